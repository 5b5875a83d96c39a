"""Finding the shared data and reading its files, with errors that name the file.

The public data sets live outside the package (``shared/data`` beside the repository, see
its README.md). Where they are is decided, in this order, by an explicit ``root``, the
environment variable ``HYSTKIT_SHARED_DATA``, or the first folder ``shared/data`` found in
the current directory, the hystkit source tree or any folder above either.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.io import loadmat
from scipy.io.matlab import MatReadError

from ..errors import InputError

__all__ = ["ENV_VAR", "DataNotFoundError", "data_folder", "find_root", "read_mat_matrix",
           "read_table"]

ENV_VAR = "HYSTKIT_SHARED_DATA"


class DataNotFoundError(InputError):
    """The shared data, a data set's folder or one of its files is not where it is looked
    for; the registry adds where the files come from and where to put them.
    """


def find_root(root: str | os.PathLike[str] | None = None) -> tuple[Path, str]:
    """The shared data root and how it was chosen.

    Parameters
    ----------
    root : path-like, optional
        Use this folder; no search.

    Returns
    -------
    (Path, str)
        The folder (not checked for contents) and a phrase saying where it came from.

    Raises
    ------
    InputError
        No root given, ``HYSTKIT_SHARED_DATA`` unset and no ``shared/data`` folder found.
    """
    if root is not None:
        return Path(root), "root argument"
    env = os.environ.get(ENV_VAR)
    if env:  # set but wrong is reported by data_folder, never silently replaced by a search
        return Path(env), f"${ENV_VAR}"
    starts = (Path.cwd(), Path(__file__).resolve().parent)
    for start in starts:
        for folder in (start, *start.parents):
            candidate = folder / "shared" / "data"
            if candidate.is_dir():
                return candidate, f"found above {start}"
    raise DataNotFoundError(f"shared data not found: no folder shared/data in {starts[0]}, in "
                            f"the hystkit source tree or above them; set {ENV_VAR}=/path/to/"
                            "shared/data or pass root=")


def data_folder(folder: str, root: str | os.PathLike[str] | None = None) -> Path:
    """The folder of one data set below the shared data root; absent -> `InputError`."""
    base, how = find_root(root)
    path = base / folder
    if not path.is_dir():
        raise DataNotFoundError(f"{path}: data folder not found (shared data root {base}, from "
                                f"{how})")
    return path


def _existing(path: Path) -> Path:
    if not path.is_file():
        raise DataNotFoundError(f"{path}: file not found")
    return path


def read_table(path: Path, n_columns: int, *, sep: str = r"\s+",
               usecols: list[int] | None = None) -> np.ndarray:
    """Numeric text table without header -> array (rows, len(usecols) or n_columns).

    Raises
    ------
    InputError
        Missing file, wrong column count, a non-numeric or empty cell (names file, line and
        column, 1-based).
    """
    _existing(path)
    try:
        frame = pd.read_csv(path, sep=sep, header=None, dtype=str, keep_default_na=False)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot parse as a {n_columns}-column table ({exc})") from None
    if frame.shape[1] != n_columns:
        raise InputError(f"{path}: expected {n_columns} columns, found {frame.shape[1]}")
    columns = list(range(n_columns)) if usecols is None else usecols
    out = np.empty((len(frame), len(columns)))
    for j, col in enumerate(columns):
        text = frame[col].str.strip()
        values = pd.to_numeric(text, errors="coerce").to_numpy(dtype=float, na_value=np.nan)
        bad = np.flatnonzero(np.isnan(values) & ~text.str.lower().eq("nan").to_numpy())
        if bad.size:
            i = int(bad[0])
            raise InputError(f"{path}: line {i + 1}, column {col + 1}: not a number "
                             f"({text.iloc[i]!r})")
        out[:, j] = values
    return out


def read_mat_matrix(path: Path, variable: str) -> np.ndarray:
    """One numeric variable of a MATLAB v5 file as a 2-D float array."""
    _existing(path)
    try:
        contents = loadmat(path, variable_names=[variable])
    except (ValueError, OSError, MatReadError, NotImplementedError) as exc:
        raise InputError(f"{path}: cannot read MATLAB file ({exc})") from None
    if variable not in contents:
        raise InputError(f"{path}: variable {variable!r} not found")
    array = np.asarray(contents[variable])
    if array.dtype.kind not in "iuf" or array.ndim != 2:
        raise InputError(f"{path}: variable {variable!r} is not a numeric matrix "
                         f"(dtype {array.dtype}, shape {array.shape})")
    return array.astype(float)
