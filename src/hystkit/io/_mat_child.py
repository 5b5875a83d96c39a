"""The child side of reading a MATLAB file: run as a script, never imported by hystkit.

``python -I _mat_child.py FILE OUTDIR MAX_BYTES NAME...`` loads FILE with scipy's `loadmat` and writes

- ``OUTDIR/<name>.npy`` for each requested NAME that holds real numbers (plain ``.npy``, read
  back with ``allow_pickle=False``, so the parent never unpickles anything from the file),
- one JSON line on stdout: ``{"variables": {name: [dtype, shape]}}`` for every variable, or
  ``{"error": kind, "detail": text}`` when scipy refused the file.

A malformed file can make scipy's compiled reader crash or loop; it does so in this process,
and the parent (`hystkit.io._isolated`) turns that into one error line. Only numpy and scipy are
imported (no hystkit, no pandas) to keep the start-up short.
"""

from __future__ import annotations

import json
import os
import sys


def _limit_memory(limit: int) -> None:
    # A flipped size field can ask for terabytes; fail with MemoryError instead of swapping.
    try:
        import resource
    except ImportError:  # not POSIX: no limit
        return
    if limit > 0:
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))


def _describe(value: object) -> list:
    import numpy as np
    from scipy import sparse

    if sparse.issparse(value):
        return ["sparse", list(value.shape)]
    array = np.asarray(value)
    return [str(array.dtype), list(array.shape)]


def main(path: str, outdir: str, names: list[str]) -> dict:
    """Load `path`; save the requested real-valued variables to `outdir`; return the report."""
    import numpy as np
    from scipy.io import loadmat
    from scipy.io.matlab import MatReadError

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
    variables = {}
    for name, value in contents.items():
        if name.startswith("__"):
            continue
        variables[name] = _describe(value)
        if name in names and np.asarray(value).dtype.kind in "iuf":
            np.save(os.path.join(outdir, f"{names.index(name)}.npy"), np.asarray(value),
                    allow_pickle=False)
    return {"variables": variables}


if __name__ == "__main__":
    _limit_memory(int(sys.argv[3]))
    try:
        report = main(sys.argv[1], sys.argv[2], sys.argv[4:])
    except MemoryError:
        report = {"error": "memory", "detail": ""}
    sys.stdout.write(json.dumps(report) + "\n")
