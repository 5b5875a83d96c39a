"""The child side of reading a MATLAB file: run as a script, never imported by hystkit.

``python -I _mat_child.py FILE OUTDIR MAX_BYTES REQUEST`` loads FILE with scipy's `loadmat`;
REQUEST is JSON ``{"arrays": [name, ...], "texts": [name, ...]}`` where a name is a variable
(``time``) or a field of a scalar struct (``s.time``). It writes

- ``OUTDIR/<i>.npy`` for each requested array that holds real numbers (plain ``.npy``, read
  back with ``allow_pickle=False``, so the parent never unpickles anything from the file);
  ``*.f`` asks for field f of every 1x1 struct, ``*`` for every matrix (see `_requested`),
- one JSON line on stdout: ``{"variables": {name: [kind, shape, dtype]}, "fields": {name: {field:
  [kind, shape, dtype]}}, "texts": {name: text}, "saved": {name: file}}``, where kind is a numpy dtype or ``struct``,
  ``char``, ``cell``, ``sparse``, ``object``; or ``{"error": kind, "detail": text}`` when scipy
  refused the file.

A malformed file can make scipy's compiled reader crash or loop; it does so in this process,
and the parent (`hystkit.io._mat_reader`) turns that into one error line. Only numpy and scipy
are imported (no hystkit, no pandas) to keep the start-up short.
"""

from __future__ import annotations

import json
import os
import sys

import numpy as np
from scipy import sparse
from scipy.io import loadmat
from scipy.io.matlab import MatlabOpaque, MatReadError

try:
    import resource
except ImportError:  # not POSIX: no memory limit
    resource = None

_MAX_TEXT = 16 << 20  # characters of a requested text (a model file is at most 16 MB)
_DESCRIBED_ONLY = ("sparse", "object", "struct", "char", "cell")


def _limit_memory(limit: int) -> None:
    # A flipped size field can ask for terabytes; fail with MemoryError instead of swapping.
    # RLIMIT_AS caps the whole address space, the modules imported above included.
    if resource is not None and limit > 0:
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))


def _kind(value: object) -> str:
    if sparse.issparse(value):
        return "sparse"
    if isinstance(value, MatlabOpaque):
        return "object"  # a MATLAB class instance (table, timetable, string, ...)
    array = np.asarray(value)
    if array.dtype.names:
        return "struct"
    if array.dtype.kind == "U":
        return "char"
    if array.dtype.kind == "O":
        return "cell"
    return str(array.dtype)


def _describe(value: object) -> list:
    dtype = "sparse" if _kind(value) == "sparse" else str(np.asarray(value).dtype)
    return [_kind(value), list(np.shape(value)), dtype]


def _scalar_struct_fields(value: object) -> dict | None:
    """Field name -> value of a 1x1 struct, None for anything else."""
    array = np.asarray(value)
    if not array.dtype.names or array.size != 1:
        return None
    element = array.reshape(-1)[0]
    return {name: element[name] for name in array.dtype.names}


def _lookup(contents: dict, name: str) -> object | None:
    variable, dot, field = name.partition(".")
    value = contents.get(variable)
    if value is None or not dot:
        return value
    fields = _scalar_struct_fields(value)
    return None if fields is None else fields.get(field)


def _requested(contents: dict, names: list[str]):
    """(name, value) of each requested array: ``v``, ``v.f``, ``v.*`` (every field of v),
    ``*.f`` (field f of every 1x1 struct) and ``*`` (every 2-D variable with more rows than columns, at least 2 columns)."""
    for name in names:
        if name == "*":
            for variable, value in contents.items():
                shape = np.shape(value)
                if len(shape) == 2 and 2 <= shape[1] < shape[0]:
                    yield variable, value
        elif name.endswith(".*"):
            for field, value in (_scalar_struct_fields(contents.get(name[:-2])) or {}).items():
                yield f"{name[:-2]}.{field}", value
        elif name.startswith("*."):
            for variable in contents:
                value = _lookup(contents, f"{variable}.{name[2:]}")
                if value is not None:
                    yield f"{variable}.{name[2:]}", value
        else:
            value = _lookup(contents, name)
            if value is not None:
                yield name, value


def main(path: str, outdir: str, request: dict) -> dict:
    """Load `path`; save the requested real-valued arrays to `outdir`; return the report."""
    try:
        contents = loadmat(path)
    except NotImplementedError as exc:  # scipy's answer to HDF5-based (v7.3) files
        return {"error": "v73", "detail": str(exc)}
    except MemoryError:
        return {"error": "memory", "detail": ""}
    except (ValueError, OSError, MatReadError) as exc:
        return {"error": "refused", "detail": str(exc)}
    except Exception as exc:  # noqa: BLE001 - scipy's other failures on damaged files
        return {"error": "damaged", "detail": f"{type(exc).__name__}: {exc}"}
    contents = {k: v for k, v in contents.items() if not k.startswith("__")}
    variables, fields = {}, {}
    for name, value in contents.items():
        variables[name] = _describe(value)
        inner = _scalar_struct_fields(value)
        if inner is not None:
            fields[name] = {field: _describe(v) for field, v in inner.items()}
    saved = {}
    for name, value in _requested(contents, request.get("arrays", ())):
        if name not in saved and _kind(value) not in _DESCRIBED_ONLY and np.asarray(value).dtype.kind in "iuf":
            file = f"{len(saved)}.npy"
            np.save(os.path.join(outdir, file), np.asarray(value), allow_pickle=False)
            saved[name] = file
    texts = {}
    for name in request.get("texts", ()):
        value = _lookup(contents, name)
        if value is not None and _kind(value) == "char" and np.asarray(value).size <= 1:
            text = str(np.asarray(value).reshape(-1)[0]) if np.asarray(value).size else ""
            if len(text) <= _MAX_TEXT:
                texts[name] = text
    return {"variables": variables, "fields": fields, "texts": texts, "saved": saved}


if __name__ == "__main__":
    _limit_memory(int(sys.argv[3]))
    try:
        report = main(sys.argv[1], sys.argv[2], json.loads(sys.argv[4]))
    except MemoryError:
        report = {"error": "memory", "detail": ""}
    sys.stdout.write(json.dumps(report) + "\n")
