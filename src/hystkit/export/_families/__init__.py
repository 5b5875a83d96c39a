"""Per-family translations of the compiled blocks (``<family>/kernels.py``) into C and MATLAB.

Each module here translates one family's ``block_forward`` / ``block_inverse`` and its
``rest_state`` and exposes:

- ``HAS_INVERSE``: whether ``block_inverse`` is translated;
- ``extra(comp) -> dict``: numbers beyond the block's ``body`` (rest-state constants);
- ``state_size(plan) -> int``: length of the translated state;
- ``c_model(plan, lit) -> str``: C defining ``static void model_rest(real *x, real value)`` and
  ``static real model_step(real *x, real u)`` (the block's step, state updated in place), reading
  ``BODY``; ``lit`` formats a number as a literal of the export's precision;
- ``m_model(plan, lit) -> str``: MATLAB subfunctions ``x = model_rest(B, value)`` and
  ``[out, x] = model_step(B, x, u)``, ``B`` the body as a column.

A family absent here is refused with the reason in :data:`REFUSALS`.
"""

from __future__ import annotations

import importlib
from types import ModuleType

__all__ = ["REFUSALS", "TRANSLATED", "refusal", "translator"]

TRANSLATED = {"mpl": "mpl", "mpl-poly": "mpl_poly", "mpl-g": "mpl_g", "pi": "pi",
              "preisach": "preisach", "gpreisach": "preisach", "ladder": "ladder",
              "boucwen": "boucwen", "bobbio": "bobbio", "chua": "chua", "pl": "pl"}

REFUSALS: dict[str, str] = {}  # every registered family is translated


def translator(model: str) -> ModuleType | None:
    """The translation module of family ``model``, or None."""
    module = TRANSLATED.get(model)
    return None if module is None else importlib.import_module(f".{module}", __name__)


def refusal(model: str, mode: str) -> str:
    """Why ``model`` in ``mode`` cannot be exported (one line)."""
    if model in REFUSALS:
        return REFUSALS[model]
    if model in TRANSLATED and mode == "inverse":
        return f"the {model} family has no inverse to translate"
    return f"no translation of family {model!r}"
