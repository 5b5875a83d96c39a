"""Writing recordings and JSON result files; the output-path checks every command runs first."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from hystkit.errors import InputError, OutputError, OutputExistsError

from ._recording import _COLUMNS, Recording


def write_recording(
    recording: Recording,
    path: str | os.PathLike[str],
    *,
    extra: dict[str, np.ndarray] | None = None,
    force: bool = False,
) -> Path:
    """Write a recording as CSV or Parquet (chosen by the suffix of `path`).

    Parameters
    ----------
    recording : Recording
        Written as columns ``time``, ``position`` (if present), ``sensor``.
    path : str or path-like
        ``.csv`` or ``.parquet``; parent directories are created.
    extra : dict of str to ndarray, shape (n,), optional
        Further columns appended in the given order (e.g. a compensated position [mm]).
    force : bool
        Overwrite an existing file.

    Returns
    -------
    Path
        The written file. Floats are written in shortest round-trip form, so reading it
        back gives bit-identical values.

    Raises
    ------
    OutputExistsError
        `path` exists and `force` is False (message says to pass ``--force``).
    ValueError
        An extra column has the wrong length or clashes with a recording column;
        `InputError` (a ValueError) for a suffix other than ``.csv``/``.parquet``.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".csv", ".parquet"):
        raise InputError(f"{path}: cannot write file type {suffix or '(no suffix)'!r}; "
                         "accepted: .csv, .parquet")
    columns = {name: getattr(recording, name) for name in _COLUMNS
               if getattr(recording, name) is not None}
    for name, values in (extra or {}).items():
        values = np.asarray(values)
        if name in columns:
            raise ValueError(f"extra column {name!r} clashes with a recording column")
        if values.shape != (recording.n_samples,):
            raise ValueError(f"extra column {name!r} has shape {values.shape}; the recording "
                             f"has {recording.n_samples} samples")
        columns[name] = values
    frame = pd.DataFrame(columns)
    check_output_path(path, force)
    if suffix == ".csv":  # pandas writes floats as repr(): the shortest exact round trip
        _write_text_safely(path, lambda: frame.to_csv(path, index=False))
    else:
        _write_text_safely(path, lambda: frame.to_parquet(path, index=False))
    return path


def write_json(obj: Any, path: str | os.PathLike[str], *, force: bool = False) -> Path:
    """Write `obj` as indented JSON (metrics, model parameters).

    NumPy scalars and arrays are converted to plain numbers and lists. NaN and infinity
    are refused (ValueError) because standard JSON cannot represent them.

    Raises
    ------
    OutputExistsError
        `path` exists and `force` is False.
    """
    path = Path(path)
    check_output_path(path, force)
    # Serialise before touching the disk so a bad object leaves no half-written file.
    text = json.dumps(obj, indent=2, allow_nan=False, default=_json_default) + "\n"
    _write_text_safely(path, lambda: path.write_text(text, encoding="utf-8"))
    return path


def _json_default(value: Any) -> Any:
    if isinstance(value, np.ndarray | np.generic):
        return value.tolist()
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    raise TypeError(f"cannot write {type(value).__name__} as JSON")


def check_output_path(path: str | os.PathLike[str], force: bool = False) -> Path:
    """Refuse an output path that exists (unless ``force``) or cannot be a file.

    Callers run this before any work, so a refused run costs nothing and writes nothing.
    """
    path = Path(path)
    if path.exists() and not force:
        raise OutputExistsError(f"{path} already exists; pass --force to overwrite it")
    if path.is_dir():
        raise OutputError(f"{path} is a folder, not a file")
    for parent in path.parents:
        if parent.exists():
            if not parent.is_dir():
                raise OutputError(f"{path}: cannot create it, {parent} is a file, not a folder")
            break
    return path


def _write_text_safely(path: Path, write: Any) -> None:
    """Create parent folders and write; OS failures become one-line OutputErrors."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        write()
    except OSError as exc:
        raise OutputError(f"{path}: cannot write ({exc.strerror or exc})") from None
