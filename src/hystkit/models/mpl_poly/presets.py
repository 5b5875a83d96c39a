"""Paper 9.2's published polynomial-mPL parameter sets (tables I and II), as printed.

The paper prints ``f2``, ``f3`` (and ``g2``, ``g3``) that enter eq. 10 (eq. 5.16) squared and
cubed; :func:`paper_9_2_params` applies that. Why these are not typos: docs/models/mpl_poly.md.
"""

from __future__ import annotations

from collections.abc import Mapping

from . import model as mpl_poly

__all__ = ["PAPER_9_2_TABLE_I", "PAPER_9_2_TABLE_II", "paper_9_2_params"]

#: Paper 9.2, table I (left): initial conditions, as printed (``f2``, ``f3`` enter squared and
#: cubed, eq. 10); ``w0, w1, V_b`` from the text below table II.
PAPER_9_2_TABLE_I: dict[str, float] = {
    "f0": -1.0, "f1": 0.1, "f2": 0.1, "f3": 1.0, "g0": 0.1, "g1": 1.0, "g2": 0.1, "g3": 1.0,
    "w0": 1.0, "w1": -1.0, "V_b": 0.01}

#: Paper 9.2, table II: fitted weights of the four direct compensators (N = 1, 40 Hz,
#: normalised sensor -> position), as printed; convert with :func:`paper_9_2_params`.
PAPER_9_2_TABLE_II: dict[str, dict[str, float]] = {
    "sine": {"f0": -2.516, "f1": -2.666, "f2": 1.975, "f3": 1.953, "g0": 0.100, "g1": 1.195,
             "g2": 0.006, "g3": 0.475, "w0": 1.000, "w1": -0.492, "V_b": 0.135},
    "chirp": {"f0": -0.469, "f1": -1.712, "f2": -2.228, "f3": 3.125, "g0": -0.369, "g1": 1.094,
              "g2": 0.006, "g3": -0.384, "w0": 1.516, "w1": -0.531, "V_b": -0.537},
    "decay": {"f0": -0.258, "f1": 0.663, "f2": -0.002, "f3": 0.008, "g0": -0.779, "g1": 1.320,
              "g2": -0.002, "g3": -0.240, "w0": 0.984, "w1": -0.875, "V_b": -0.302},
    "noise": {"f0": -4.719, "f1": 3.412, "f2": -1.244, "f3": 1.469, "g0": -0.119, "g1": 1.125,
              "g2": 0.006, "g3": -0.259, "w0": 1.156, "w1": -0.406, "V_b": 0.010},
}


def paper_9_2_params(printed: Mapping[str, float]) -> mpl_poly.MplPolyParams:
    """One-cell parameters from paper 9.2's printed values (a column of table I or II).

    eq. 10 of the paper (eq. 5.16) applies ``f(x) = f0 + f1 x + f2^2 x^2 + f3^3 x^3`` to the
    printed values, and the same form to ``g``: the squares and cubes are not typos (with them
    every column is a working compensator, without them the chirp column is anti-correlated
    with its input; docs/models/mpl_poly.md).

    Parameters
    ----------
    printed : mapping of str to float
        ``f0 .. f3``, ``g0 .. g3``, ``w0``, ``w1`` and ``V_b`` as printed.

    Returns
    -------
    mpl_poly.MplPolyParams
        One-cell parameters.
    """
    def cubic(p: str) -> list[float]:
        return [printed[f"{p}0"], printed[f"{p}1"], printed[f"{p}2"] ** 2, printed[f"{p}3"] ** 3]

    return mpl_poly.MplPolyParams(f=[cubic("f")], g=cubic("g"),
                                  w=[printed["w0"], printed["w1"]], v_b=printed["V_b"])
