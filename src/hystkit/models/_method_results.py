"""The small records the protocol's methods return: the compiled block of the closed loop
(:class:`Block`, from ``Family.block``), a fit's given start (:class:`FitStart`, from
``Family.start_options``) and a model one size smaller (:class:`Reduction`, from
``Family.reductions``).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np


class Block(NamedTuple):
    """A model compiled for the closed loop (see the module docstring).

    Parameters
    ----------
    step : numba dispatcher
        ``step(body, x, xn, off, u) -> out``.
    body : array
        Flat float64 parameters the step reads.
    n_state : int
        Length of the block's slice of the loop state.
    """

    step: Callable[..., float]
    body: np.ndarray
    n_state: int


class FitStart(NamedTuple):
    """How a family's fit starts from one given parameter set (:meth:`Family.start_options`).

    Parameters
    ----------
    options : dict
        Keyword options of the family's fit that make it start from exactly these parameters,
        and from them only (the reference document's single-start fmincon procedure).
    clipped : tuple of str
        One note per optimiser coordinate the fit's box moves, naming it, its given value and
        the value it starts from; empty when the start lies inside the box.
    """

    options: dict
    clipped: tuple[str, ...] = ()

    @classmethod
    def in_box(cls, options: dict, theta: np.ndarray, lower: np.ndarray, upper: np.ndarray,
               names: list[str]) -> FitStart:
        """``options`` with a note for every coordinate of ``theta`` outside ``[lower, upper]``.

        Parameters
        ----------
        options : dict
            The fit options.
        theta, lower, upper : array, shape (p,)
            The start in the fit's coordinates and the fit's box.
        names : list of str
            Names of the coordinates.

        Returns
        -------
        FitStart
        """
        start = np.clip(theta, lower, upper)
        moved = np.flatnonzero(start != theta)
        return cls(options, tuple(f"{names[i]} = {theta[i]:.6g} is outside the fit's box "
                                  f"[{lower[i]:.6g}, {upper[i]:.6g}]; the fit starts from "
                                  f"{start[i]:.6g}" for i in moved))


class Reduction(NamedTuple):
    """A model one size smaller, made from a fitted one without refitting
    (:meth:`Family.reductions`): a cell dropped, or two cells merged into one.

    Parameters
    ----------
    what : str
        What was taken out, in the fitted model's numbering: ``"cells 2 and 3 cancel (weights
        -14.6, +12.8)"``.
    size : int
        The family's size knob of the smaller model (``fit --cells``).
    label : str
        The smaller model's size for people: ``"2 cells"``.
    structure, params
        The smaller model.
    """

    what: str
    size: int
    label: str
    structure: Any
    params: Any
