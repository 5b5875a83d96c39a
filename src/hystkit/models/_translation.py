"""A family's compiled block written as C99 and MATLAB code (:class:`Translation`), what
:mod:`hystkit.export` asks a family for; each family builds its own in ``<family>/export.py``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any


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
