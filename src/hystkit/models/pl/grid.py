"""The default grid of the PL structural search, apart from the search itself so that
``hystkit pl-search --help`` can show it without loading the model's numba kernels."""

__all__ = ["DEFAULT_GRID"]

#: Default grid of :func:`search.structural_search` (16 structures, < ~30 s on 8000 samples).
DEFAULT_GRID: dict[str, tuple] = {"n": (1, 2, 5, 10), "p": (5.0, 21.0), "m": (1, 5),
                                  "s": (0.001,)}
