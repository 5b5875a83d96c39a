"""Docstring entries that mean the same in every family, written once (MNE-Python's
``docdict`` / ``fill_doc``, scipy's ``doccer``).

A line of a docstring that holds only ``%(name)s`` is replaced by the entry ``name``, indented as
that line. In an entry, ``{Structure}`` and ``{Params}`` become the family's record types and
``{state}`` the module's description of its state vector ``x`` (``state=``, an entry's name or
the text). The rest of each docstring (its summary, equations, units, the entries particular to
it) stays in the source::

    fill_doc = docfiller("PlStructure", "PlParams", state="x_capacitors")

    @fill_doc
    def rest_state(structure, params, value, inverse=False):
        '''Cells at rest, each equal to the source (``d_k(0) = 0``), shape (N,).

        %(rest_state)s
        '''
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TypeVar

from .._docfill import fill

__all__ = ["ENTRIES", "RECORDS", "docfiller", "filled"]

F = TypeVar("F", bound=Callable)

# The records every model function takes first; modules start their own entries with it.
RECORDS = """structure : {Structure}
    The model's structure.
params : {Params}
    Its parameters."""

ENTRIES = {
    # the records every model function takes first
    "structure": RECORDS,
    # the whole Parameters section of a function of the structure alone
    "structure_parameters": """Parameters
----------
structure : {Structure}
    The model's structure.""",
    # the whole Parameters section of a function of the records alone
    "records_parameters": """Parameters
----------
""" + RECORDS,
    "params": """params : {Params}
    The model's parameters.""",
    # rest_state(structure, params, value, inverse)
    "rest_value": """value : float
    Constant input (with `inverse`: output) the model rests at.
inverse : bool, default False
    Rest state of the inverse: `value` is an output.""",
    "rest_returns": """numpy.ndarray
    The state at rest.""",
    # the state before a sample, by what the family's state is
    "x_cells": """x : numpy.ndarray, shape (N,)
    Cell voltages before the sample.""",
    "x_capacitors": """x : numpy.ndarray, shape (N,)
    Capacitor voltages before the sample.""",
    "x_staircase": """x : numpy.ndarray, shape (k,)
    Staircase before the sample.""",
    # a run of the cells alone (``states``) of the capacitor-cell families
    "u_source": """u : numpy.ndarray, shape (n,)
    Source voltage sampled every ``structure.dt``.""",
    "x0_capacitors": """x0 : numpy.ndarray, float or None, optional
    Initial capacitor voltages, as for :func:`simulate`.""",
    "x_end_capacitors": """x_end : numpy.ndarray, shape (N,)
    Capacitor voltages after the last sample.""",
    # the output branch of the cubic-output families
    "branch": """lo, hi : float
    The branch's bounds (``+-inf`` where unbounded).
sign : float
    Sign of ``g'`` on it.""",
    # the Raises section of the functions that find the branch around the rest point
    "no_branch": """Raises
------
FitDivergedError
    If ``g'(z_rest) = 0`` (no monotone branch through the operating point).""",
    "u_max": """u_max : float
    Largest input magnitude.""",
    "rng": """rng : numpy.random.Generator
    Source of the draws.""",
    # invert_step(structure, params, x, y)
    "y_step": """y : float
    Output to reach at this sample.""",
    "u_step": """u : float
    Input that gives `y` from the present state.""",
    "x_next": """x_next : numpy.ndarray
    State after the sample.""",
    # the options every multistart fit passes on (hystkit.identification.fit_multistart)
    "multistart": """max_nfev, screen_nfev, n_polish : int
    As :func:`hystkit.identification.fit_multistart`.
accept : callable, optional
    A candidate counts only if ``accept(params)``; ``accept_reason`` says why others failed.
accept_reason : str, optional
    Why candidates were rejected, for the message.""",
    # the Returns section of a multistart fit
    "best_start": """Returns
-------
FitResult
    The best start's fit.""",
    # the fits that solve one linear least-squares problem (no robust loss)
    "linear_loss": """loss, f_scale : str, float
    Only ``"linear"`` (the SSE): a robust loss is refused with InputError.""",
    # ... with a smoothness penalty (preisach, gpreisach)
    "penalised_weights": """weights : array, shape (n,), optional
    Per-sample weights (finite, >= 0, not all 0): the rows of the least-squares problem
    are scaled by ``sqrt(w)`` and the smoothness penalty by ``sqrt(mean(w))`` (so weights
    all equal to any ``c`` give the unweighted fit).""",
    "state": "{state}",
    # whole sections of the protocol functions whose signature means the same everywhere
    "cell_voltages": """Parameters
----------
""" + RECORDS + """
v : numpy.ndarray, shape (..., N)
    Voltage across each cell's resistor.

Returns
-------
numpy.ndarray, shape (..., N)
    One value per cell and voltage.""",
    "params_bound": """Parameters
----------
params : {Params}
    The model's parameters.
u_max : float
    Largest input magnitude.

Returns
-------
float
    The bound on ``|y|``.""",
    "rest_state": """Parameters
----------
""" + RECORDS + """
value : float
    Constant input (with `inverse`: output) the model rests at.
inverse : bool, default False
    Rest state of the inverse: `value` is an output.

Returns
-------
numpy.ndarray
    The state at rest.""",
    "step": """Parameters
----------
""" + RECORDS + """
{state}
u : float
    Input of the sample.

Returns
-------
y : float
    Output of the sample.
x_next : numpy.ndarray
    State after the sample.""",
    "invert_step": """Parameters
----------
""" + RECORDS + """
{state}
y : float
    Output to reach at this sample.

Returns
-------
u : float
    Input that gives `y` from the present state.
x_next : numpy.ndarray
    State after the sample.""",
}

def filled(doc: str, structure: type | str = "Structure", params: type | str = "Params",
           state: str = "", entries: dict[str, str] | None = None) -> str:
    """`doc` with its ``%(name)s`` lines replaced by :data:`ENTRIES`.

    Parameters
    ----------
    doc : str
        A docstring.
    structure, params : type or str
        The family's record types (or their names).
    state : str
        The entry of the state ``x``: a key of :data:`ENTRIES` or the entry's text.
    entries : dict, optional
        The module's own entries, beside :data:`ENTRIES` (same form).

    Returns
    -------
    str
        The docstring filled in.
    """
    table = {**ENTRIES, **entries} if entries else ENTRIES
    names = {"Structure": getattr(structure, "__name__", structure),
             "Params": getattr(params, "__name__", params),
             "state": table.get(state, state)}
    return fill(doc, lambda key: table[key].format(**names))


def docfiller(structure: type | str = "Structure", params: type | str = "Params",
              state: str = "", entries: dict[str, str] | None = None) -> Callable[[F], F]:
    """A decorator that fills a function's docstring in place (:func:`filled`).

    Parameters
    ----------
    structure, params : type or str
        The family's record types (or their names).
    state : str
        The entry of the state ``x`` (:func:`filled`).
    entries : dict, optional
        The module's own entries (:func:`filled`).

    Returns
    -------
    callable
        ``fill_doc(function) -> function``.
    """

    def fill_doc(function: F) -> F:
        function.__doc__ = filled(function.__doc__, structure, params, state, entries)
        return function

    return fill_doc
