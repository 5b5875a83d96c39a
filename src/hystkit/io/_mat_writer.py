"""MATLAB (``.mat``, version 5/7) output: results a MATLAB user loads with ``load``.

Values become MATLAB's own types: numbers and numeric lists -> double (1-D arrays as column
vectors), booleans -> logical, text -> char, lists of text or of mixed values -> cell arrays,
dicts -> structs, None -> ``[]`` (MATLAB's "nothing"). Names must be MATLAB identifiers;
`matlab_name` makes one from any column name. Written by `scipy.io.savemat` into a temporary
beside the target, published atomically like every hystkit output.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable, Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from hystkit.errors import NonFiniteError

from ._atomic import atomic_output
from ._output_checks import check_output_format

__all__ = ["matlab_name", "to_matlab", "write_mat"]

MAX_NAME = 63  # MATLAB's namelengthmax
_INVALID = re.compile(r"[^A-Za-z0-9_]")


def matlab_name(name: str) -> str:
    """A valid MATLAB identifier for `name`, as ``matlab.lang.makeValidName`` makes it:
    invalid characters become ``_``, a name not starting with a letter gets an ``x`` in
    front, at most 63 characters (``'temp C'`` -> ``temp_C``, ``'1st'`` -> ``x1st``).

    Parameters
    ----------
    name : str
        Any column or variable name.

    Returns
    -------
    str
        A valid MATLAB identifier.
    """
    valid = _INVALID.sub("_", str(name).strip()) or "x"
    if not valid[0].isalpha():
        valid = "x" + valid
    return valid[:MAX_NAME]


def to_matlab(value: Any, where: str = "") -> Any:
    """`value` as something `scipy.io.savemat` writes as the MATLAB type listed above.

    Raises
    ------
    NonFiniteError
        A NaN or infinity, naming its key path (``params.w[2]``): hystkit's outputs hold no
        NaN, in MATLAB as in JSON.
    TypeError
        A value with no MATLAB form (naming its key path).
    """
    if value is None:
        return np.zeros((0, 0))
    if isinstance(value, bool | np.bool_):
        return np.bool_(value)
    if isinstance(value, str):
        return value
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if isinstance(value, int | float | np.integer | np.floating):
        _check_finite(np.float64(value), where)
        return np.float64(value)
    if isinstance(value, Mapping):
        return _struct(value, where)
    if isinstance(value, np.ndarray) and value.dtype.kind in "biuf":
        if value.dtype.kind == "f":
            _check_finite(value, where)
        return value
    if isinstance(value, list | tuple | np.ndarray):
        items = list(value)
        if items and all(isinstance(v, bool | np.bool_) for v in items):
            return np.array(items, dtype=bool)
        if all(_is_number(v) for v in items):
            array = np.array(items, dtype=np.float64).reshape(1, -1)  # a row, as [1 2 3]
            _check_finite(array, where)
            return array
        if (items and all(isinstance(v, list) and len(v) == len(items[0]) and v for v in items)
                and all(_is_number(x) for v in items for x in v)):
            array = np.array(items, dtype=np.float64)  # equal rows: a matrix
            _check_finite(array, where)
            return array
        cell = np.empty((1, len(items)), dtype=object)
        for i, item in enumerate(items):
            cell[0, i] = to_matlab(item, f"{where}[{i}]")
        return cell
    raise TypeError(f"{where or 'value'}: cannot write {type(value).__name__} to a .mat file")


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float | np.integer | np.floating) \
        and not isinstance(value, bool | np.bool_)


def _struct(mapping: Mapping, where: str) -> dict[str, Any]:
    fields: dict[str, Any] = {}
    for key, name in _matlab_keys(mapping, f"{where or 'value'}: keys", "field"):
        fields[name] = to_matlab(mapping[key], f"{where}.{key}" if where else str(key))
    return fields


def _matlab_keys(keys: Iterable[str], what: str, kind: str) -> Iterator[tuple[str, str]]:
    """Each key with its `matlab_name`, in order; a ValueError (``<what> 'a-b' and another both
    become MATLAB <kind> 'a_b'``) at the first key whose name an earlier key took."""
    taken: set[str] = set()
    for key in keys:
        name = matlab_name(key)
        if name in taken:
            raise ValueError(f"{what} {key!r} and another both become MATLAB {kind} {name!r}")
        taken.add(name)
        yield key, name


def _check_finite(values: Any, where: str) -> None:
    array = np.asarray(values, dtype=np.float64)
    bad = np.flatnonzero(~np.isfinite(array.reshape(-1)))
    if bad.size:
        at = f"{where}[{bad[0]}]" if array.ndim else where
        raise NonFiniteError(f"value {at or '(top level)'} is {array.reshape(-1)[bad[0]]}")


def recording_variables(columns: Mapping[str, np.ndarray],
                        units: Mapping[str, str]) -> dict[str, Any]:
    """The variables of a recording written to ``.mat``: one column vector per column
    (boolean flags as logical, text as a cell array), ``column_names`` and ``units``."""
    variables: dict[str, Any] = {}
    for name, key in _matlab_keys(columns, "columns", "variable"):
        values = np.asarray(columns[name])
        if values.dtype.kind not in "biuf":
            import pandas as pd  # here: a model file written as .mat needs no pandas

            cell = np.empty((values.size, 1), dtype=object)
            cell[:, 0] = ["" if v is None or pd.isna(v) else str(v) for v in values]
            values = cell
        variables[key] = values
    variables["column_names"] = to_matlab([matlab_name(n) for n in columns])
    variables["units"] = {matlab_name(n): str(u) for n, u in units.items()}
    return variables


def write_mat(path: str | os.PathLike[str], mapping: Mapping[str, Any], *,
              force: bool = False, verbatim: Mapping[str, Any] | None = None) -> Path:
    """Write `mapping` as the variables of a MATLAB file, atomically.

    Parameters
    ----------
    path : str or path-like
        Must end in ``.mat``.
    mapping : mapping of str to value
        Variable name (made a MATLAB identifier by `matlab_name`) -> value (converted by
        `to_matlab`: arrays, numbers, text, lists, dicts as structs, None as ``[]``). 1-D
        arrays are written as column vectors, as MATLAB stores a recording's columns.
    force : bool
        Overwrite an existing file.
    verbatim : mapping of str to value, optional
        Variables already in MATLAB form, written as they are (no conversion, no NaN check):
        a recording's columns copied from its input (`recording_variables`).

    Returns
    -------
    Path
        The written file (MATLAB 5 format, compressed; ``load`` reads it in MATLAB and Octave).

    Raises
    ------
    OutputExistsError, OutputError
        As every output: exists without `force`, wrong extension, cannot be written.
    NonFiniteError
        A NaN or infinity anywhere (the message names the variable and index); nothing is
        written.
    ValueError
        Two names that become the same MATLAB name.
    """
    from scipy.io import savemat  # here: scipy.io loads only for .mat outputs

    path = Path(path)
    check_output_format(path, (".mat",), "a MATLAB file")
    variables: dict[str, Any] = {}
    for name, key in _matlab_keys(mapping, f"{path}: names", "variable"):
        try:
            variables[key] = to_matlab(mapping[name], key)
        except NonFiniteError as exc:
            raise NonFiniteError(f"{path}: {exc}; refusing to write NaN or infinity") from None
    for name, value in (verbatim or {}).items():
        if name in variables:
            raise ValueError(f"{path}: variable {name!r} is given twice")
        variables[name] = value
    with atomic_output(path, force) as tmp:
        savemat(tmp, variables, format="5", oned_as="column", do_compression=True,
                long_field_names=True)
    return path

