"""Checks of a model file's contents before any of it reaches a family's code.

A model file is untrusted input: every value is checked for its JSON type, finiteness and size
here, so that a bad file gives one error naming the file and the key path (``params.a``,
``structure.n_cells``), never a traceback from deep inside a family, and nothing is allocated
for sizes nobody could have fitted.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Iterator
from typing import Any

from ..errors import InputError

__all__ = ["MAX_MODEL_BYTES", "MAX_PARAM_NUMBERS", "MAX_STRUCTURE_INT", "check_like",
           "check_model_dict", "key_in_message"]

# A 10 000-cell mPL file is under 1 MB; anything far larger is not a model hystkit wrote.
MAX_MODEL_BYTES = 16 * 2**20
# Fitted numbers in ``params``: far above any fit hystkit can run (Preisach grids ~ 10^4).
MAX_PARAM_NUMBERS = 1_000_000
# Integer sizes in ``structure`` (cells, levels, substeps, capacity): above this a file is
# refused before the family allocates or loops over them (boucwen ``substeps: 1e12`` hangs).
MAX_STRUCTURE_INT = 100_000

# Sections whose leaves are numbers only (strings are allowed in ``structure``).
_NUMERIC_SECTIONS = ("params", "normalisation", "baseline")
_OPTIONAL_NUMBERS = ("polarity", "tare_seconds", "track_seconds", "sensor_reference",
                     "rest_position", "dt")


def check_model_dict(d: dict, source: str) -> None:
    """Refuse wrong JSON types, non-finite numbers and oversized sizes, naming the key path.

    Raises
    ------
    InputError
        ``"<source>: key 'params.a': ..."`` for the first problem found.
    """
    for key in ("model", "mode", "center"):
        if key in d and not isinstance(d[key], str):
            _fail(source, key, f"must be a string, got {_show(d[key])}")
    for key in ("structure", *_NUMERIC_SECTIONS):
        if key in d and not isinstance(d[key], dict):
            _fail(source, key, f"must be a JSON object, got {_show(d[key])}")
    if "fit" in d and d["fit"] is not None and not isinstance(d["fit"], dict):
        _fail(source, "fit", f"must be a JSON object, got {_show(d['fit'])}")
    for key in _NUMERIC_SECTIONS:
        for path, value in _leaves(d.get(key, {}), key):
            _check_number(source, path, value)
    n_params = sum(1 for _ in _leaves(d.get("params", {}), "params"))
    if n_params > MAX_PARAM_NUMBERS:
        _fail(source, "params", f"{n_params} numbers, more than the limit {MAX_PARAM_NUMBERS}")
    for path, value in _leaves(d.get("structure", {}), "structure"):
        if isinstance(value, str):
            continue
        _check_number(source, path, value, bool_ok=True)
        if not isinstance(value, bool) and (isinstance(value, int) or value.is_integer()) \
                and abs(value) > MAX_STRUCTURE_INT:
            _fail(source, path, f"{value:g} is beyond the size limit {MAX_STRUCTURE_INT} of a "
                                f"model file")
    for key in ("training_range", "position_range"):
        value = d.get(key)
        if value is not None and not (isinstance(value, list) and len(value) == 2):
            _fail(source, key, f"must be null or a list [low, high], got {_show(value)}")
        for path, item in _leaves(value or [], key):
            _check_number(source, path, item)
    for key in _OPTIONAL_NUMBERS:
        if d.get(key) is not None:
            _check_number(source, key, d[key])


def check_like(source: str, section: str, values: dict, reference: dict) -> None:
    """Each value of `values` has the JSON kind (number, string, list) of the same key in
    `reference` (a family's default structure), so that ``n_cells: "abc"`` is named as such."""
    for key, value in values.items():
        if key not in reference:
            continue  # unknown keys: the family's constructor names them
        want = _kind(reference[key])
        if want != "any" and _kind(value) not in (want, "any"):
            _fail(source, f"{section}.{key}", f"must be a {want}, got {_show(value)}")


def _kind(value: Any) -> str:
    if isinstance(value, str):
        return "string"
    if isinstance(value, list | tuple):
        return "list"
    if isinstance(value, int | float) or value is None:
        return "number" if not isinstance(value, bool) and value is not None else "any"
    return "any"


def key_in_message(message: str, names: Iterable[str]) -> str | None:
    """The first of `names` that `message` mentions as a word (the field an error is about)."""
    for name in names:
        if re.search(rf"(?<![\w.]){re.escape(name)}(?!\w)", message):
            return name
    return None


def _leaves(value: Any, path: str) -> Iterator[tuple[str, Any]]:
    """(key path, value) of every leaf below `value`; list items as ``path[i]``."""
    if isinstance(value, dict):
        for key, item in value.items():
            yield from _leaves(item, f"{path}.{key}")
    elif isinstance(value, list):
        for i, item in enumerate(value):
            yield from _leaves(item, f"{path}[{i}]")
    else:
        yield path, value


def _check_number(source: str, path: str, value: Any, *, bool_ok: bool = False) -> None:
    if isinstance(value, bool):
        if bool_ok:
            return
        _fail(source, path, f"must be a number, got {_show(value)}")
    if not isinstance(value, int | float):
        _fail(source, path, f"must be a number, got {_show(value)}")
    if isinstance(value, float) and not math.isfinite(value):
        _fail(source, path, f"must be a finite number, got {value}")
    if isinstance(value, int) and abs(value) > 1e300:  # float() of it would overflow
        _fail(source, path, "must be a finite number, got an integer beyond float range")


def _show(value: Any) -> str:
    text = repr(value) if not isinstance(value, dict | list) else type(value).__name__
    return text if len(text) <= 40 else text[:37] + "..."


def _fail(source: str, path: str, message: str) -> None:
    raise InputError(f"{source}: key {path!r}: {message}")
