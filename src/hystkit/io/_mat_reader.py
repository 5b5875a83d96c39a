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
from dataclasses import dataclass, field, replace
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
    """What the child found: every variable's kind (a numpy dtype or ``struct``, ``char``,
    ``cell``, ``sparse``, ``object``) and shape, the fields of 1x1 structs, the requested
    real arrays (by requested name: ``v`` or ``v.field``) and texts.

    Parameters
    ----------
    variables : dict of str to (str, tuple of int)
        Kind and shape of every variable in the file.
    arrays : dict of str to numpy.ndarray
        The requested real arrays, by requested name.
    fields : dict, optional
        Kind and shape of the fields of each 1x1 struct, by struct name.
    texts : dict of str to str, optional
        The requested character variables.
    dtypes : dict of str to str, optional
        numpy dtype name of each variable and struct field (``v`` or ``v.field``).
    """

    variables: dict[str, tuple[str, tuple[int, ...]]]
    arrays: dict[str, np.ndarray]
    fields: dict[str, dict[str, tuple[str, tuple[int, ...]]]] = field(default_factory=dict)
    texts: dict[str, str] = field(default_factory=dict)
    dtypes: dict[str, str] = field(default_factory=dict)  # numpy's, by ``v`` or ``v.field``

    def describe(self, name: str) -> str:
        """``'s' (struct with fields time, x)``, ``'M' (double 800x3)``: for messages."""
        kind, shape = self.variables[name]
        if name in self.fields:
            return f"{name!r} (struct with fields {', '.join(self.fields[name]) or 'none'})"
        kind = {"float64": "double", "float32": "single", "struct": "struct array"}.get(kind,
                                                                                       kind)
        return f"{name!r} ({kind} {'x'.join(map(str, shape))})"


def load_mat(path: Path, names: list[str], source: str, *,
             texts: tuple[str, ...] = ()) -> MatContents:
    """Read `path` in a child process; real-valued variables among `names` come back as arrays.

    Parameters
    ----------
    path : Path
        A MATLAB v4/v5/v7 file.
    names : list of str
        Arrays wanted (if they hold real numbers): a variable ``v``, a field ``v.f`` of a 1x1
        struct, ``*.f`` (field f of every 1x1 struct) or ``*`` (every matrix with at least 2
        columns and more rows than columns). All variables are described regardless.
    source : str
        File name used in error messages.
    texts : tuple of str
        Character variables (or struct fields) wanted as text.

    Returns
    -------
    MatContents
        Every variable's description plus the requested arrays and texts.

    Raises
    ------
    InputError
        ``"<source>: cannot read MATLAB file ..."`` when scipy refuses the file, the child
        crashes, runs out of memory or time; v7.3 (HDF5) files get their own message.
    """
    size = path.stat().st_size
    timeout = TIMEOUT_BASE_S + size / TIMEOUT_RATE
    limit = max(MEMORY_BASE, MEMORY_FACTOR * size)
    request = json.dumps({"arrays": list(names), "texts": list(texts)})
    with tempfile.TemporaryDirectory(prefix="hystkit-mat-") as tmp:
        argv = [sys.executable, "-I", str(_CHILD), str(path), tmp, str(limit), request]
        try:
            proc = subprocess.run(argv, capture_output=True, timeout=timeout,
                                  stdin=subprocess.DEVNULL, check=False)
        except subprocess.TimeoutExpired as exc:
            raise _fail(source, f"the reader did not finish within {timeout:.0f} s") from exc
        except OSError as exc:
            raise _fail(source, f"the reader could not be started ({exc})") from exc
        report = _report(proc, source)
        try:
            variables = {name: _kind_shape(value)
                         for name, value in report["variables"].items()}
            fields = {name: {f: _kind_shape(v) for f, v in inner.items()}
                      for name, inner in report.get("fields", {}).items()}
            dtypes = {name: str(value[2]) for name, value in report["variables"].items()}
            dtypes.update({f"{name}.{f}": str(v[2])
                           for name, inner in report.get("fields", {}).items()
                           for f, v in inner.items()})
            arrays = {name: np.load(Path(tmp) / Path(file).name, allow_pickle=False)
                      for name, file in report.get("saved", {}).items()}
            found_texts = {str(k): str(v) for k, v in report.get("texts", {}).items()}
        except (KeyError, TypeError, ValueError, OSError) as exc:
            raise _fail(source, f"the reader's report is incomplete ({exc})") from exc
    return MatContents(variables, arrays, fields, found_texts, dtypes)


def _kind_shape(value: list) -> tuple[str, tuple[int, ...]]:
    kind, shape = value[:2]
    return str(kind), tuple(int(n) for n in shape)


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
    """Read the recording of a MATLAB file as float64 arrays (not yet validated).

    Where the recording is, in this order: the variable `options.mat_var` (a 1x1 struct or a
    matrix); variables named ``time``, ``position``, ``sensor`` (or as `options.columns` says);
    the file's only 1x1 struct holding those fields, or its only matrix with samples as rows
    (2 columns: time, sensor; 3: time, position, sensor; others need 1-based
    `options.columns`). Anything else is one line listing the variables with their shapes.
    """
    where = Where(source, noun="variable", item="sample", names=options.columns)
    wanted = [where.name(name) for name in COLUMNS]
    var = options.mat_var
    request = [f"{var}.{w}" for w in wanted] + [var] if var else \
        wanted + [f"*.{w}" for w in wanted] + ["*"]
    contents = load_mat(path, request, source, texts=tuple(f"units.{n}" for n in COLUMNS))
    # a `units` struct of text, as hystkit writes it, labels the columns
    units = tuple((n, contents.texts[f"units.{n}"]) for n in COLUMNS
                  if contents.texts.get(f"units.{n}", "").strip())
    if var is not None:
        arrays, where = _read_variable(contents, var, source, need_position, options)
    elif any(w in contents.variables for w in wanted) or not contents.variables:
        arrays = _read_vectors(contents, list(contents.variables), where, need_position)
    else:
        candidates = [name for name in contents.variables if name not in _LABELS
                      and (name in contents.fields or name in contents.arrays)]
        if len(candidates) != 1:
            listed = ", ".join(contents.describe(name) for name in contents.variables)
            raise where.fail(f"missing required variables "
                             f"{', '.join(map(where.label, COLUMNS))}; variables found: "
                             f"{listed}; name the one holding the recording with --mat-var "
                             f"(a struct, or a matrix with one sample per row)")
        arrays, where = _read_variable(contents, candidates[0], source, need_position, options)
    return arrays, replace(where, units=units)


def _read_vectors(contents: MatContents, found: list[str], where: Where, need_position: bool,
                  prefix: str = "") -> dict[str, np.ndarray]:
    """The recording from vectors: top-level variables, or the fields of struct `prefix`."""
    kinds = contents.fields[prefix] if prefix else contents.variables
    arrays = {}
    for name in pick(found, need_position, where):
        variable = where.name(name)
        key = f"{prefix}.{variable}" if prefix else variable
        if key not in contents.arrays:  # not real numbers: only described by the child
            kind, shape = kinds[variable]
            if kind == "sparse":
                raise where.fail(f"a sparse matrix of shape {shape}; save it as a full vector",
                                 name)
            dtype = contents.dtypes.get(key, kind)
            what = f": {_KIND_NAMES[kind]}" if kind in _KIND_NAMES else ""
            raise where.fail(f"not real numbers (dtype {dtype}){what}", name)
        arrays[name] = as_vector(contents.arrays[key], name, where)
    return arrays


_LABELS = ("units", "column_names")  # what hystkit writes beside a recording's columns
_KIND_NAMES = {"struct": "a struct", "char": "text", "cell": "a cell array",
               "object": "a MATLAB object", "sparse": "a sparse matrix"}


def _read_variable(contents: MatContents, var: str, source: str, need_position: bool,
                   options: ReadOptions) -> tuple[dict[str, np.ndarray], Where]:
    """The recording held by variable `var`: a 1x1 struct of vectors or a matrix."""
    if var not in contents.variables:
        listed = ", ".join(contents.describe(name) for name in contents.variables) or "none"
        raise InputError(f"{source}: no variable {var!r} (--mat-var); variables found: "
                         f"{listed}")
    kind, shape = contents.variables[var]
    if var in contents.fields:
        where = Where(f"{source}: struct {var!r}", noun="field", item="sample",
                      names=options.columns)
        return _read_vectors(contents, list(contents.fields[var]), where, need_position,
                             prefix=var), where
    if var in contents.arrays and len(shape) == 2:
        return _read_matrix(contents.arrays[var], var, source, need_position, options)
    if kind == "struct":
        raise InputError(f"{source}: variable {var!r} is a {'x'.join(map(str, shape))} struct "
                         f"array; save one struct of column vectors (for a table: "
                         f"table2struct(T, 'ToScalar', true))")
    if kind == "object":
        raise InputError(f"{source}: variable {var!r} is a MATLAB object (a table or "
                         f"timetable?) that hystkit cannot read; save table2struct(T, "
                         f"'ToScalar', true) instead")
    if var in contents.arrays:
        raise InputError(f"{source}: variable {var!r} has shape {'x'.join(map(str, shape))}; "
                         f"a recording matrix has one sample per row and 2 or more columns")
    raise InputError(f"{source}: variable {var!r} holds "
                     f"{_KIND_NAMES.get(kind, f'dtype {kind}')}, not a recording; use a "
                     f"struct of vectors or a numeric matrix")


def _read_matrix(matrix: np.ndarray, var: str, source: str, need_position: bool,
                 options: ReadOptions) -> tuple[dict[str, np.ndarray], Where]:
    """Columns of a matrix with one sample per row; `options.columns` gives 1-based column
    numbers (default: 2 columns time, sensor; 3 columns time, position, sensor)."""
    n_rows, n_cols = matrix.shape
    label = f"{source}: matrix {var!r} ({n_rows}x{n_cols})"
    if n_cols > n_rows:
        raise InputError(f"{label}: one sample per row is expected; transpose it (M.') "
                         f"before saving")
    given = dict(options.columns)
    bad = [f"{k}={v}" for k, v in given.items() if not v.isdigit()]
    if bad:
        raise InputError(f"{label}: --columns gives column numbers for a matrix (1-based, e.g. "
                         f"time=1,position=2,sensor=3), got {', '.join(bad)}")
    defaults = {2: {"time": "1", "sensor": "2"}, 3: {"time": "1", "position": "2",
                                                      "sensor": "3"}}
    numbers = given or defaults.get(n_cols)
    if numbers is None:
        raise InputError(f"{label}: with {n_cols} columns, say which are which with "
                         f"--columns time=1,position=2,sensor=3 (1-based)")
    if "time" not in numbers or "sensor" not in numbers or (need_position
                                                             and "position" not in numbers):
        missing = [n for n in COLUMNS if n not in numbers and (need_position or n != "position")]
        raise InputError(f"{label}: no column given for {', '.join(missing)}; use --columns "
                         f"time=1,position=2,sensor=3 (1-based)")
    where = Where(label, item="sample", names=tuple(numbers.items()))
    arrays = {}
    for name in COLUMNS:
        if name not in numbers:
            continue
        index = int(numbers[name])
        if not 1 <= index <= n_cols:
            raise InputError(f"{label}: column {index} ({name}) does not exist; columns are "
                             f"numbered 1 to {n_cols}")
        arrays[name] = np.asarray(matrix[:, index - 1], dtype=np.float64).copy()
    return arrays, where
