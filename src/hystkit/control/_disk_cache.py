"""What every ``hystkit control`` run computes the same way, computed once and kept on disk.

Every ``hystkit control`` and ``hystkit stability --control`` run starts from the three sensor
models of ch. 7 (:func:`~hystkit.control.fit_sensor_models`): fitting them again on every
command line took about 0.4 s of a 1.9 s run. ``hystkit control`` then reads the linearised
loop's margins (:func:`~hystkit.control.loop_margins`), for which python-control alone takes
0.6 s to import. Both are deterministic, so each result is a function of its inputs and of the
code that computes it: :func:`cached_sensor_models` and :func:`cached_loop_margins` store it
under a key made of

- every input by its value: numbers by their ``repr`` (exact), arrays by their bytes,
  records (recordings, blocks, loops) field by field (a changed sample or gain changes the
  key);
- the code: hystkit's version and the path, size and modification time of every ``.py`` file of
  the installed hystkit package (an edit anywhere computes again: the virtual sensor, the
  families, the solvers), the versions of Python, numpy, scipy and numba, and the installed
  python-control's ``__init__.py`` (path, size, modification time).

A stored result is read back exactly as it was (pickle: the same float64 bits), so a command's
numbers are the same with or without the cache. The folder is ``$HYSTKIT_CACHE_DIR``, else
``$XDG_CACHE_HOME/hystkit``, else ``~/.cache/hystkit``; deleting it only costs the next run its
fit. An unreadable entry is computed again and replaced; an unwritable folder is not an error
(one line on stderr; the run computes, as before).
"""

from __future__ import annotations

import dataclasses
import hashlib
import importlib.util
import os
import pickle
import platform
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

import numba
import numpy as np
import scipy

from .. import __version__
from .. import control as package
from ._loop import ControlLoop
from ._loop_margins import LoopMargins
from ._sensor_blocks import SensorModels

__all__ = ["cache_folder", "cached_loop_margins", "cached_sensor_models", "code_stamp",
           "memo_key"]

PACKAGE = Path(__file__).resolve().parents[1]  # the hystkit package folder
T = TypeVar("T")


def cache_folder() -> Path:
    """``$HYSTKIT_CACHE_DIR``, else ``$XDG_CACHE_HOME/hystkit``, else ``~/.cache/hystkit``."""
    if os.environ.get("HYSTKIT_CACHE_DIR"):
        return Path(os.environ["HYSTKIT_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "hystkit"


def code_stamp() -> str:
    """What the fit's result depends on besides its arguments: the versions, and every source
    file of the hystkit package by path, size and modification time (about 300 ``stat``)."""
    parts = [__version__, platform.python_version(), np.__version__, scipy.__version__,
             numba.__version__]
    spec = importlib.util.find_spec("control")  # its version needs an import (0.6 s)
    if spec is not None and spec.origin is not None:
        stat = os.stat(spec.origin)
        parts.append(f"{spec.origin}:{stat.st_size}:{stat.st_mtime_ns}")
    for path in sorted(PACKAGE.rglob("*.py")):
        stat = path.stat()
        parts.append(f"{path.relative_to(PACKAGE)}:{stat.st_size}:{stat.st_mtime_ns}")
    return hashlib.sha256("\n".join(parts).encode()).hexdigest()


def _digest(value: Any, h) -> None:
    """Feed `value`'s content to the hash `h`, the same for equal values in any process (a
    pickle is not: it records which equal objects are one object)."""
    if value is None or isinstance(value, bool | int | float | complex | str | bytes | Path):
        h.update(f"{type(value).__name__}:{value!r};".encode())
    elif isinstance(value, np.ndarray | np.generic):
        array = np.ascontiguousarray(value)
        h.update(f"array:{array.dtype.str}:{array.shape};".encode())
        h.update(array.tobytes())
    elif isinstance(value, list | tuple):
        h.update(f"{type(value).__name__}:{len(value)};".encode())
        for item in value:
            _digest(item, h)
    elif isinstance(value, dict):
        h.update(f"dict:{len(value)};".encode())
        for key in sorted(value, key=repr):
            _digest(key, h)
            _digest(value[key], h)
    elif dataclasses.is_dataclass(value):
        h.update(f"{type(value).__module__}.{type(value).__qualname__};".encode())
        for f in dataclasses.fields(value):
            h.update(f"{f.name}=".encode())
            _digest(getattr(value, f.name), h)
    else:  # another object (e.g. the virtual sensor's physics as a family): its pickle
        h.update(f"{type(value).__module__}.{type(value).__qualname__};".encode())
        h.update(pickle.dumps(value, protocol=5))


def memo_key(kind: str, inputs: dict[str, Any]) -> str:
    """The cache key of `kind` computed from `inputs` with the code of today."""
    h = hashlib.sha256(f"{kind}\n{code_stamp()}\n".encode())
    _digest(inputs, h)
    return h.hexdigest()


def cached_sensor_models(folder: Path | None = None, **options: Any) -> SensorModels:
    """``fit_sensor_models(**options)``, read from the cache when this fit was stored there
    with the same inputs and code, else fitted and stored.

    Parameters
    ----------
    folder : Path, optional
        Cache folder; default :func:`cache_folder`.
    **options
        Keyword arguments of :func:`~hystkit.control.fit_sensor_models`.

    Returns
    -------
    SensorModels
        The fitted models, bit for bit those of a fresh fit.
    """
    return _memo("sensor-models", options, lambda: fit_sensor_models(**options), SensorModels,
                 folder)


def fit_sensor_models(**options: Any) -> SensorModels:
    """:func:`~hystkit.control.fit_sensor_models`, looked up in the package when a fit is due:
    the virtual sensor it fits on loads scipy.signal (0.6 s), which a stored fit never needs."""
    return package.fit_sensor_models(**options)


def cached_loop_margins(loop: ControlLoop, folder: Path | None = None) -> LoopMargins:
    """``loop_margins(loop)`` (at rest), read from the cache when stored there for an equal
    loop with the same code, else computed (python-control loaded then) and stored.

    Parameters
    ----------
    loop : ControlLoop
        The loop; every block, gain and option of it is part of the key.
    folder : Path, optional
        Cache folder; default :func:`cache_folder`.

    Returns
    -------
    LoopMargins
        The margins, bit for bit those computed afresh.
    """

    # looked up in the package when not stored: python-control loads only then
    return _memo("loop-margins", {"loop": loop}, lambda: package.loop_margins(loop),
                 LoopMargins, folder)


def _memo(kind: str, inputs: dict[str, Any], compute: Callable[[], T], expected: type,
          folder: Path | None) -> T:
    folder = cache_folder() if folder is None else Path(folder)
    path = folder / f"{kind}-{memo_key(kind, inputs)}.pickle"
    try:
        with path.open("rb") as f:
            value = pickle.load(f)
        if isinstance(value, expected):
            return value
    except (OSError, pickle.UnpicklingError, EOFError, AttributeError, ImportError,
            TypeError, ValueError):
        pass  # absent, or written by something else: compute again
    value = compute()
    _store(value, path)
    return value


def _store(value: Any, path: Path) -> None:
    """Written to a temporary file and renamed: a reader sees the whole entry or none."""
    tmp = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=path.parent, prefix=".tmp-", delete=False) as f:
            tmp = Path(f.name)
            pickle.dump(value, f, protocol=5)
        os.replace(tmp, path)
    except OSError as exc:
        if tmp is not None:
            tmp.unlink(missing_ok=True)
        print(f"hystkit: not cached ({exc.strerror}: {path.parent})", file=sys.stderr)
