"""A family's compiled block written as C99 and MATLAB code (:class:`Translation`), what
:mod:`hystkit.export` asks a family for; each family builds its own in ``<family>/export.py``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

import numpy as np


def _no_extra(comp: Any) -> dict:
    return {}


def _block_state(plan: Any) -> int:
    return plan.n_block_state


@dataclasses.dataclass(frozen=True)
class Translation:
    """A family's compiled block (:meth:`Family.block`) written as C99 and as MATLAB code, for
    :mod:`hystkit.export`; each family builds its own in ``<family>/export.py``.

    The generated code reads the block's ``body`` at the same indices as the numba kernel:
    ``BODY[i]`` in C (``real``), ``B(i + 1)`` in MATLAB (a column). ``plan`` is the
    :class:`hystkit.export.ExportPlan`; ``lit`` formats a number as a literal of the export's
    precision.

    Parameters
    ----------
    c_model : callable
        ``c_model(plan, lit) -> str``: C defining ``static void model_rest(real *x, real
        value)`` and ``static real model_step(real *x, real u)`` (the block's step, the state
        updated in place).
    m_model : callable
        ``m_model(plan, lit) -> str``: MATLAB subfunctions ``x = model_rest(B, value)`` and
        ``[out, x] = model_step(B, x, u)``.
    m_functions : tuple of str
        The other MATLAB subfunctions ``m_model`` (and ``m_load``) define; an export named like
        one of them gets a ``_model`` suffix, as it would shadow it.
    extra : callable
        ``extra(comp) -> dict``: numbers beyond the body (rest-state constants), as
        ``plan.extra``; default none.
    state_size : callable
        ``state_size(plan) -> int``: length of the translated state; default the block's.
    inverse : bool
        Whether ``block_inverse`` is translated (an inverse-mode compensator is refused
        otherwise).
    m_load : str or None
        MATLAB ``x = model_load(B, x_block)`` turning a block state into the translated one,
        for a translation that keeps more state than the block; None: the block's as is.
    """

    c_model: Callable[[Any, Callable[[float], str]], str]
    m_model: Callable[[Any, Callable[[float], str]], str]
    m_functions: tuple[str, ...] = ()
    extra: Callable[[Any], dict] = _no_extra
    state_size: Callable[[Any], int] = _block_state
    inverse: bool = True
    m_load: str | None = None


# The linear readout y = w_0 u + sum w_k x_k - V_b (mPL eq. 5.2, the ladder's output) with w at
# BODY[IW] (C) / B(iw + 1) (MATLAB) and V_b at BODY[1]: the forward block's output, or solved
# for the input (eq. 5.13) by the inverse block. The code sets ``drive``, what drives the cells.

def linear_readout_rest(comp: Any) -> dict:
    """``W_SUM``: ``sum(w)``, the divisor of the inverse's rest input ``(y + V_b) / sum(w)``."""
    return {"W_SUM": float(np.sum(comp.params.w))}


def c_linear_readout(inverse: bool) -> str:
    """C declaring ``acc`` and setting ``drive``: ``acc`` the output (forward), ``drive`` the
    input ``(y + V_b - sum w_k x_k) / w_0`` (inverse); needs ``k``, ``drive``, ``N_CELLS``, ``IW``."""
    if inverse:
        return """    real acc = u + BODY[1];
    for (k = 0; k < N_CELLS; k++) acc -= BODY[IW + 1 + k] * x[k];
    drive = acc / BODY[IW];"""
    return """    real acc = BODY[IW] * u - BODY[1];
    for (k = 0; k < N_CELLS; k++) acc += BODY[IW + 1 + k] * x[k];
    drive = u;"""


def m_linear_readout(inverse: bool) -> str:
    """MATLAB setting ``drive`` and the block's output ``out``, as :func:`c_linear_readout`;
    needs ``n`` and ``iw``."""
    if inverse:
        return """acc = u + B(2);
for k = 1:n
    acc = acc - B(iw + k) * x(k);
end
drive = acc / B(iw);
out = drive;"""
    return """acc = B(iw) * u - B(2);
for k = 1:n
    acc = acc + B(iw + k) * x(k);
end
drive = u;
out = acc;"""
