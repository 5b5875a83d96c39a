"""MATLAB files read in a child process, so that a damaged file cannot take hystkit down.

scipy's `loadmat` parses the binary format in compiled code; a file with one byte changed can
crash it (segmentation fault), make it loop, or make it ask for terabytes. The child
(`_mat_child.py`, run by path with ``python -I``) does the parsing and hands the variables back
as plain ``.npy`` files in a private temporary folder; here every way the child can fail becomes
one `InputError`.

Cost: one interpreter start with numpy and scipy, about 0.3 s (see ``benchmarks/README.md``).
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hystkit.errors import InputError

from .._read_options import DEFAULT_OPTIONS, ReadOptions
from ._cells import COLUMNS, Where, as_vector, pick

_CHILD = Path(__file__).with_name("_mat_child.py")
TIMEOUT_BASE_S = 30.0  # interpreter start plus a generous margin on a busy machine
TIMEOUT_RATE = 20e6  # bytes per second at least; loadmat reads about 1 GB/s uncompressed
MEMORY_BASE = 4 << 30  # address-space limit of the child: 4 GiB or 32 x the file
MEMORY_FACTOR = 32
_DETAIL_CHARS = 200


@dataclass(frozen=True)
class MatContents:
    """What the child found: every variable's dtype and shape, the requested real arrays."""

    variables: dict[str, tuple[str, tuple[int, ...]]]
    arrays: dict[str, np.ndarray]


def load_mat(path: Path, names: list[str], source: str) -> MatContents:
    """Read `path` in a child process; real-valued variables among `names` come back as arrays.

    Parameters
    ----------
    path : Path
        A MATLAB v4/v5/v7 file.
    names : list of str
        Variables wanted as arrays (if they hold real numbers); all are listed regardless.
    source : str
        File name used in error messages.

    Raises
    ------
    InputError
        ``"<source>: cannot read MATLAB file ..."`` when scipy refuses the file, the child
        crashes, runs out of memory or time; v7.3 (HDF5) files get their own message.
    """
    size = path.stat().st_size
    timeout = TIMEOUT_BASE_S + size / TIMEOUT_RATE
    limit = max(MEMORY_BASE, MEMORY_FACTOR * size)
    with tempfile.TemporaryDirectory(prefix="hystkit-mat-") as tmp:
        argv = [sys.executable, "-I", str(_CHILD), str(path), tmp, str(limit), *names]
        try:
            proc = subprocess.run(argv, capture_output=True, timeout=timeout,
                                  stdin=subprocess.DEVNULL, check=False)
        except subprocess.TimeoutExpired as exc:
            raise _fail(source, f"the reader did not finish within {timeout:.0f} s") from exc
        except OSError as exc:
            raise _fail(source, f"the reader could not be started ({exc})") from exc
        report = _report(proc, source)
        variables = {name: (str(dtype), tuple(int(n) for n in shape))
                     for name, (dtype, shape) in report["variables"].items()}
        arrays = {}
        for i, name in enumerate(names):
            file = Path(tmp) / f"{i}.npy"
            if file.exists():
                arrays[name] = np.load(file, allow_pickle=False)
    return MatContents(variables, arrays)


def _report(proc: subprocess.CompletedProcess, source: str) -> dict:
    """The child's JSON report, or the InputError saying how it died."""
    if proc.returncode < 0:
        number = -proc.returncode
        try:
            name = f", {signal.Signals(number).name}"
        except ValueError:
            name = ""
        raise _fail(source, f"the reader crashed (signal {number}{name}); the file is damaged")
    lines = proc.stdout.decode("utf-8", "replace").strip().splitlines()
    try:
        report = json.loads(lines[-1])
        if not isinstance(report, dict):
            raise TypeError(type(report).__name__)
    except (IndexError, ValueError, TypeError) as exc:
        last = proc.stderr.decode("utf-8", "replace").strip().splitlines()[-1:] or ["no output"]
        raise _fail(source, f"the reader failed (exit code {proc.returncode}: "
                            f"{_one_line(last[0])})") from exc
    error = report.get("error")
    if error == "v73":
        raise InputError(f"{source}: MATLAB v7.3 (HDF5) files are not supported; save with '-v7'")
    if error == "memory":
        raise _fail(source, "the file asks for more memory than the reader may use; it is "
                            "damaged or far larger than a recording")
    if error == "refused":
        raise InputError(f"{source}: cannot read MATLAB file ({_one_line(report['detail'])})")
    if error is not None:
        raise _fail(source, f"the file is damaged ({_one_line(report['detail'])})")
    return report


def _fail(source: str, message: str) -> InputError:
    return InputError(f"{source}: cannot read MATLAB file: {message}")


def _one_line(text: str) -> str:
    text = " ".join(str(text).split())
    return text if len(text) <= _DETAIL_CHARS else text[:_DETAIL_CHARS] + "..."


def read_mat(path: Path, source: str, need_position: bool,
             options: ReadOptions = DEFAULT_OPTIONS) -> tuple[dict[str, np.ndarray], Where]:
    """Read the recording variables of a MATLAB file as float64 arrays (not yet validated);
    of `options` only the column (variable) names apply here."""
    where = Where(source, noun="variable", item="sample", names=options.columns)
    contents = load_mat(path, [where.name(name) for name in COLUMNS], source)
    names = pick(list(contents.variables), need_position, where)
    arrays = {}
    for name in names:
        variable = where.name(name)
        if variable not in contents.arrays:  # not real numbers: only described by the child
            dtype, shape = contents.variables[variable]
            if dtype == "sparse":
                raise where.fail(f"a sparse matrix of shape {shape}; save it as a full vector",
                                 name)
            raise where.fail(f"not real numbers (dtype {dtype})", name)
        arrays[name] = as_vector(contents.arrays[variable], name, where)
    return arrays, where
