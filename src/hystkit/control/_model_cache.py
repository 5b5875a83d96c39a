"""The sensor models of ``hystkit control``, fitted once and kept on disk.

Every ``hystkit control`` and ``hystkit stability --control`` run starts from the three sensor
models of ch. 7 (:func:`~hystkit.control.fit_sensor_models`); fitting them again on every command
line took about 0.4 s of a 1.9 s run (more under load). The fit is deterministic, so its result
is a function of its inputs and of the code that computes it: :func:`cached_sensor_models`
stores it under a key made of

- every argument of the fit, recordings and ready blocks by the SHA-256 of their pickle (their
  values: a changed sample changes the key);
- the code: hystkit's version and the path, size and modification time of every ``.py`` file of
  the installed hystkit package (an edit anywhere refits: the virtual sensor, the families, the
  solvers), and the versions of Python, numpy, scipy and numba.

A stored fit is read back exactly as it was (pickle: the same float64 bits), so a command's
numbers are the same with or without the cache. The folder is ``$HYSTKIT_CACHE_DIR``, else
``$XDG_CACHE_HOME/hystkit``, else ``~/.cache/hystkit``; deleting it only costs the next run its
fit. An unreadable entry is fitted again and replaced; an unwritable folder is not an error
(the run just fits, as before).
"""

from __future__ import annotations

import hashlib
import os
import pickle
import platform
import sys
import tempfile
from pathlib import Path
from typing import Any

import numba
import numpy as np
import scipy

from .. import __version__
from ._sensors import SensorModels, fit_sensor_models

__all__ = ["cache_folder", "cached_sensor_models", "code_stamp", "models_key"]

PACKAGE = Path(__file__).resolve().parents[1]  # the hystkit package folder
PREFIX = "sensor-models-"


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
    for path in sorted(PACKAGE.rglob("*.py")):
        stat = path.stat()
        parts.append(f"{path.relative_to(PACKAGE)}:{stat.st_size}:{stat.st_mtime_ns}")
    return hashlib.sha256("\n".join(parts).encode()).hexdigest()


def _value_key(value: Any) -> str:
    if value is None or isinstance(value, str | int | float | bool):
        return repr(value)
    return "sha256:" + hashlib.sha256(pickle.dumps(value, protocol=5)).hexdigest()


def models_key(options: dict[str, Any]) -> str:
    """The cache key of ``fit_sensor_models(**options)`` with the code of today."""
    text = "\n".join(f"{name}={_value_key(options[name])}" for name in sorted(options))
    return hashlib.sha256(f"{code_stamp()}\n{text}".encode()).hexdigest()


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
    folder = cache_folder() if folder is None else Path(folder)
    path = folder / f"{PREFIX}{models_key(options)}.pickle"
    try:
        with path.open("rb") as f:
            models = pickle.load(f)
        if isinstance(models, SensorModels):
            return models
    except (OSError, pickle.UnpicklingError, EOFError, AttributeError, ImportError,
            TypeError, ValueError):
        pass  # absent, or written by something else: fit again
    models = fit_sensor_models(**options)
    _store(models, path)
    return models


def _store(models: SensorModels, path: Path) -> None:
    """Written to a temporary file and renamed: a reader sees the whole entry or none."""
    tmp = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=path.parent, prefix=".tmp-", delete=False) as f:
            tmp = Path(f.name)
            pickle.dump(models, f, protocol=5)
        os.replace(tmp, path)
    except OSError as exc:
        if tmp is not None:
            tmp.unlink(missing_ok=True)
        print(f"hystkit: sensor models not cached ({exc.strerror}: {path.parent})",
              file=sys.stderr)
