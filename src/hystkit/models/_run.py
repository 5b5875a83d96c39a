"""``simulate``, ``simulate_reference`` and ``invert`` written once for every family.

Every family runs the same way: check that the parameters fit the structure, check the signal,
start from the given state or at rest, run the compiled kernel, refuse a non-finite result.
Only the kernel call differs. A family's model module declares that call (and its state size,
rest state and readable ``step``) in a :class:`Runs` record and takes its three functions from
:func:`family_runs`::

    RUNS = Runs(label="mpl", step=step, n_state=..., rest_state=..., forward=..., inverse=...)
    simulate, simulate_reference, invert = family_runs(RUNS, __name__, "the mPL model")
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ._docs import filled
from ._validation import broadcast_state, check_finite_run, check_signal, run_steps

__all__ = ["Runs", "family_runs"]

Run = tuple[np.ndarray, np.ndarray]


def _no_check(structure: Any, params: Any, inverse: bool) -> None:
    return None


@dataclass(frozen=True)
class Runs:
    """What a family gives the generic runs.

    Parameters
    ----------
    label : str
        The model's name in error messages (``"mpl"``, ``"Chua-Stromsmoe"``).
    step : callable
        The readable ``step(structure, params, x, u) -> (y, x_next)``.
    forward : callable
        ``forward(structure, params, u, x) -> (y, x_end)``: the compiled run from the checked
        input and start. It raises its own divergence errors; non-finite outputs are refused
        here.
    n_state : callable
        ``n_state(structure, params) -> int``: length of a given ``x0`` (default start).
    rest_state : callable
        ``rest_state(structure, params, value, inverse) -> x``: the start of a run with
        ``x0=None`` at the first input (``inverse``: first output) (default start).
    inverse : callable or None
        ``inverse(structure, params, y, x) -> (u_hat, x_end)``, likewise; None: no inverse.
    check : callable
        ``check(structure, params, inverse)``: raise unless the parameters fit the structure
        (and, for ``inverse``, have an inverse); called before the signal is looked at.
    start : callable or None
        ``start(structure, params, x0, value, inverse) -> x`` replacing the default start (rest
        state for ``x0=None``, else ``x0`` broadcast to ``n_state`` floats): for a state that
        is not a vector of floats (a Preisach staircase).
    layout : str or None
        What the state's values are, for the message on a ``x0`` of the wrong size.
    """

    label: str
    step: Callable[..., tuple[float, np.ndarray]]
    forward: Callable[[Any, Any, np.ndarray, np.ndarray], Run]
    n_state: Callable[[Any, Any], int] | None = None
    rest_state: Callable[..., np.ndarray] | None = None
    inverse: Callable[[Any, Any, np.ndarray, np.ndarray], Run] | None = None
    check: Callable[[Any, Any, bool], None] = _no_check
    start: Callable[..., np.ndarray] | None = None
    layout: str | None = None

    def initial(self, structure: Any, params: Any, x0: Any, value: float,
                inverse: bool) -> np.ndarray:
        """The state a run starts from: ``x0`` as given, or at rest at ``value``."""
        if self.start is not None:
            return self.start(structure, params, x0, value, inverse)
        if x0 is None:
            return self.rest_state(structure, params, value, inverse)
        return broadcast_state(x0, self.n_state(structure, params), self.layout)


_SIMULATE = """Run {title} over an input sequence (compiled kernel).

    Parameters
    ----------
    %(structure)s
    u : array, shape (n,)
        Model input, one value per sample (every ``structure.dt``).
    x0 : array, float or None
        Initial state (a float: every value of it). ``None`` starts at rest at the first
        input, the state ``rest_state(structure, params, u[0])`` of the family.

    Returns
    -------
    y : array, shape (n,)
        Model output.
    x_end : array
        State after the last sample; feeding it back as ``x0`` continues the run exactly.

    Raises
    ------
    ValueError
        If `params` do not fit `structure`, `u` is empty, not 1-D or not finite, or `x0` does
        not fit the state.
    FitDivergedError
        If the output leaves the finite range (parameters or inputs outside the domain).
"""

_REFERENCE = """Same as ``simulate``, as a plain loop over ``step`` (the readable reference of
    {title}).

    Parameters
    ----------
    %(structure)s
    u : array, shape (n,)
        Model input, one value per sample.
    x0 : array, float or None
        Initial state, as for ``simulate``.

    Returns
    -------
    y : array, shape (n,)
        Model output.
    x_end : array
        State after the last sample.

    Raises
    ------
    ValueError
        As ``simulate``.
"""

_INVERT = """Run the inverse of {title} (the compensator) over an output sequence.

    Parameters
    ----------
    %(structure)s
    y : array, shape (n,)
        Measured model output (e.g. the sensor signal), one value per sample.
    x0 : array, float or None
        Initial state of the model (a float: every value of it). ``None`` starts at rest at the
        first output, the state ``rest_state(structure, params, y[0], inverse=True)``.

    Returns
    -------
    u_hat : array, shape (n,)
        Estimated input.
    x_end : array
        State after the last sample; continues ``simulate`` or ``invert``.

    Raises
    ------
    ValueError
        If `params` do not fit `structure`, `y` is empty, not 1-D or not finite, or `x0` does
        not fit the state.
    FitDivergedError
        If the model has no inverse or the inverse leaves the finite range (the inverse's
        stability depends on the parameters, so it is checked rather than guaranteed).
"""


def _named(function: Callable, name: str, module: str, doc: str, notes: str) -> Callable:
    function.__name__ = function.__qualname__ = name
    function.__module__ = module
    function.__doc__ = filled(doc) + (f"\n    Notes\n    -----\n    {notes}\n" if notes else "")
    return function


def family_runs(runs: Runs, module: str, title: str, notes: str = "",
                inverse_notes: str = "") -> tuple[Callable[..., Run], Callable[..., Run],
                                                  Callable[..., Run] | None]:
    """The family's ``simulate``, ``simulate_reference`` and ``invert`` (None without an
    inverse), as functions of ``module`` documented for ``title``.

    Parameters
    ----------
    runs : Runs
        What the family runs.
    module : str
        The model module's ``__name__`` (where the functions are documented).
    title : str
        The model in the docstrings: ``"the modified Power-Law model"``.
    notes, inverse_notes : str
        Family-specific notes added to the docstrings of the forward runs and of ``invert``.

    Returns
    -------
    tuple
        ``(simulate, simulate_reference, invert)``.
    """

    def checked(structure: Any, params: Any, signal: np.ndarray, x0: Any,
                inverse: bool) -> tuple[np.ndarray, np.ndarray]:
        """The checked signal (``u``, or ``y`` for the inverse) and the start state."""
        runs.check(structure, params, inverse)
        signal = check_signal(signal, "y" if inverse else "u")
        return signal, runs.initial(structure, params, x0, signal[0], inverse)

    def simulate(structure: Any, params: Any, u: np.ndarray,
                 x0: np.ndarray | float | None = None) -> Run:
        u, x = checked(structure, params, u, x0, False)
        y, x_end = runs.forward(structure, params, u, x)
        return check_finite_run(y, runs.label), x_end

    def simulate_reference(structure: Any, params: Any, u: np.ndarray,
                           x0: np.ndarray | float | None = None) -> Run:
        u, x = checked(structure, params, u, x0, False)
        return run_steps(runs.step, structure, params, u, x)

    def invert(structure: Any, params: Any, y: np.ndarray,
               x0: np.ndarray | float | None = None) -> Run:
        y, x = checked(structure, params, y, x0, True)
        u_hat, x_end = runs.inverse(structure, params, y, x)
        return check_finite_run(u_hat, runs.label, "inverse"), x_end

    return (_named(simulate, "simulate", module, _SIMULATE.format(title=title), notes),
            _named(simulate_reference, "simulate_reference", module,
                   _REFERENCE.format(title=title), notes),
            None if runs.inverse is None else
            _named(invert, "invert", module, _INVERT.format(title=title), inverse_notes))
