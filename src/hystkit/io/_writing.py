"""Writing recordings and JSON result files; the output-path checks every command runs first.

Every output is published atomically (see :func:`atomic_output` and :func:`atomic_folder`):
it is built under a hidden temporary name beside its target and renamed into place only when
complete, so a crash, Ctrl-C, SIGTERM or a full disk leaves the old file (or nothing), never a
partial one, and without ``force`` two concurrent writers of one path cannot both win.
"""

from __future__ import annotations

import errno
import json
import math
import os
import secrets
import shutil
from collections.abc import Callable, Iterable, Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from hystkit.errors import NonFiniteError, OutputError, OutputExistsError

from .._read_options import TIME_UNITS
from ._recording import _COLUMNS, Recording

if TYPE_CHECKING:  # pandas loads when a recording is written, not for a model file
    import pandas as pd

TEMP_MARK = ".tmp-"  # every temporary's name holds this; tests look for strays by it


RECORDING_SUFFIXES = (".csv", ".parquet", ".mat")


def write_recording(
    recording: Recording,
    path: str | os.PathLike[str],
    *,
    extra: dict[str, np.ndarray] | None = None,
    force: bool = False,
    kept: dict[str, np.ndarray] | None = None,
    units: dict[str, str] | None = None,
    units_sidecar: bool = False,
    names: Mapping[str, str] | None = None,
    time_unit: str = "s",
) -> Path:
    """Write a recording as CSV, Parquet or MATLAB (chosen by the suffix of `path`), atomically.

    Parameters
    ----------
    recording : Recording
        Written as columns ``time``, ``position`` (if present), ``sensor`` (or as `names`
        says).
    path : str or path-like
        ``.csv``, ``.parquet`` or ``.mat``; parent directories are created.
    extra : dict of str to ndarray, shape (n,), optional
        Further columns appended in the given order (e.g. a compensated position [mm]);
        boolean ones (flags) are written as 0/1 (logical in ``.mat``).
    force : bool
        Overwrite an existing file.
    kept : dict of str to ndarray, shape (n,), optional
        Columns of the input copied as they were (numbers, or text), written between the
        recording's columns and `extra`; empty input cells (NaN, "") stay empty.
    units : dict of str to str, optional
        Units of columns beyond ``recording.units`` (e.g. ``position_estimate``). Written to
        Parquet's schema metadata (``hystkit.units``) and as the ``units`` struct of a
        ``.mat`` file; CSV keeps its header plain (a units line would need ``--units-row`` to
        read back).
    units_sidecar : bool
        CSV with units, or with `names` or a `time_unit` of its own: also write the settings
        file beside it (``out.toml``, `sidecar_path`: the units in a ``[units]`` table, the
        names in ``[columns]``, the ``time_unit``), which reading ``out.csv`` picks up; both
        files appear together or not at all.
    names : mapping of str to str, optional
        The names to write the recording's ``time``, ``position``, ``sensor`` under (those of
        the file it was read from, e.g. ``{"time": "t_ms"}``); `units` and `kept` use the
        written names.
    time_unit : {"s", "ms", "us", "ns", "min"}
        Unit of the written time column (the input's, `hystkit.io.ReadOptions.time_unit`);
        written in it and labelled so in the units (``ms``). A value is written in its
        shortest form when that reads back (times the unit's seconds) to the same time.

    Returns
    -------
    Path
        The written file. Floats are written in shortest round-trip form, so reading it
        back gives bit-identical values. In a ``.mat`` file every column is a variable
        (column vector; flags as logical, text as a cell array), names made MATLAB
        identifiers (`matlab_name`), with ``column_names`` (the written names in order) and
        ``units`` (a struct).

    Raises
    ------
    OutputExistsError
        `path` exists and `force` is False (message says to pass ``--force``), also when
        another process created it while this one was writing.
    NonFiniteError
        A column holds NaN or infinity (the message names column and row); nothing is written.
    ValueError
        An extra column has the wrong length or clashes with a recording column.
    OutputError
        A suffix other than ``.csv``/``.parquet``/``.mat`` (`check_output_format`).

    Notes
    -----
    The file appears complete or not at all (:func:`atomic_output`).
    """
    path = Path(path)
    suffix = check_output_format(path, RECORDING_SUFFIXES, "a recording")
    written = {name: (names or {}).get(name, name) for name in _COLUMNS}
    columns = {written[name]: getattr(recording, name) for name in _COLUMNS
               if getattr(recording, name) is not None}
    columns[written["time"]] = time_in_unit(recording.time, time_unit)
    for group in (kept or {}), (extra or {}):
        for name, values in group.items():
            values = np.asarray(values)
            if name in columns:
                raise ValueError(f"extra column {name!r} clashes with a recording column")
            if values.shape != (recording.n_samples,):
                raise ValueError(f"extra column {name!r} has shape {values.shape}; the "
                                 f"recording has {recording.n_samples} samples")
            columns[name] = values
    for name, values in columns.items():
        if name not in (kept or {}):
            _refuse_non_finite(path, name, np.asarray(values))
    all_units = {**{written.get(name, name): unit for name, unit in recording.units},
                 **(units or {})}
    all_units = {name: unit for name, unit in all_units.items() if name in columns}
    # the time's unit labels it in .mat and Parquet; a settings file says time_unit instead
    labels = {written["time"]: time_unit, **all_units} if time_unit != "s" else all_units
    if suffix == ".mat":
        from ._mat_writer import recording_variables, write_mat

        return write_mat(path, {}, force=force,
                         verbatim=recording_variables(columns, labels))
    import pandas as pd

    # flags (bool) as 0/1 in text and Parquet files, as the files hystkit always wrote
    frame = pd.DataFrame({name: values.astype(int) if np.asarray(values).dtype.kind == "b"
                          else values for name, values in columns.items()})
    renamed = {name: other for name, other in written.items() if other != name}
    if suffix == ".csv" and units_sidecar and (all_units or renamed or time_unit != "s"):
        ours = {other: name for name, other in renamed.items()}  # [units] keys its three so
        text = units_settings_text({ours.get(name, name): unit for name, unit in
                                    all_units.items()}, path.name, columns=renamed,
                                   time_unit=time_unit)
        with atomic_outputs([path, sidecar_path(path)], force) as (tmp, toml_tmp):
            frame.to_csv(tmp, index=False)
            toml_tmp.write_text(text, encoding="utf-8")
        return path
    with atomic_output(path, force) as tmp:
        if suffix == ".csv":  # pandas writes floats as repr(): the shortest exact round trip
            frame.to_csv(tmp, index=False)
        else:
            _write_parquet(frame, tmp, labels)
    return path


def sidecar_path(path: str | os.PathLike[str]) -> Path:
    """The settings file beside a recording (``out.csv`` -> ``out.toml``).

    Parameters
    ----------
    path : str or os.PathLike
        The recording.

    Returns
    -------
    pathlib.Path
        The same path with the suffix ``.toml``.
    """
    return Path(path).with_suffix(".toml")


def units_settings_text(units: dict[str, str], file: str | None = None, *,
                        columns: Mapping[str, str] | None = None, time_unit: str = "s") -> str:
    """A recording's settings file (``out.toml``) that holds the units of its columns (and
    how to read a file written in its input's names and time unit).

    Parameters
    ----------
    units : dict of str to str
        Unit of each column, by column name (hystkit's ``time``, ``position``, ``sensor``
        for the columns `columns` renames).
    file : str, optional
        The name of the recording it is for (``out.csv``): then it applies to that file
        only, even when an ``out.mat`` appears beside it.
    columns : mapping of str to str, optional
        hystkit name -> the file's column name, written as a ``[columns]`` table.
    time_unit : str
        Unit of the time column; written when not ``s``.

    Returns
    -------
    str
        The TOML text: ``file``, ``time_unit``, a ``[columns]`` and a ``[units]`` table.
    """
    lines = ["# written by hystkit: how to read the file beside this one", ""]
    lines += [] if file is None else [f"file = {json.dumps(file)}"]
    lines += [] if time_unit == "s" else [f"time_unit = {json.dumps(time_unit)}"]
    lines += [""] if len(lines) > 2 else []
    for table, values in (("columns", columns or {}), ("units", units)):
        if values:
            lines += [f"[{table}]"]
            lines += [f"{json.dumps(name)} = {json.dumps(text)}" for name, text in values.items()]
            lines += [""]
    return "\n".join(lines).rstrip("\n") + "\n"


def time_in_unit(seconds: np.ndarray, unit: str) -> np.ndarray:
    """Times [s] in `unit` (``ms``, ...), each in its shortest form (15 significant digits)
    where that gives back exactly `seconds` when read in `unit`: 20 ms read as 0.02 s is
    written 20, not 20.000000000000004.

    Parameters
    ----------
    seconds : numpy.ndarray
        Times [s].
    unit : str
        A key of `hystkit.io.ReadOptions`' time units.

    Returns
    -------
    numpy.ndarray
        The times in `unit` (`seconds` itself for ``s``).
    """
    scale = TIME_UNITS[unit]
    if scale == 1.0:
        return seconds
    values = np.asarray(seconds, dtype=np.float64) / scale
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):  # checked below
        digits = 14 - np.floor(np.log10(np.abs(values)))
        factor = 10.0 ** np.where(np.isfinite(digits), digits, 0.0)
        short = np.round(values * factor) / factor
        return np.where(short * scale == seconds, short, values)


def _write_parquet(frame: pd.DataFrame, path: Path, units: dict[str, str]) -> None:
    import pyarrow as pa
    import pyarrow.parquet as pq

    table = pa.Table.from_pandas(frame, preserve_index=False)
    if units:
        metadata = {**(table.schema.metadata or {}),
                    b"hystkit.units": json.dumps(units).encode()}
        table = table.replace_schema_metadata(metadata)
    pq.write_table(table, path)


def _refuse_non_finite(path: Path, name: str, values: np.ndarray) -> None:
    if values.dtype.kind not in "fc":
        return
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        raise NonFiniteError(f"{path}: column {name!r} row {bad[0] + 1} is {values[bad[0]]} "
                             f"({bad.size} non-finite value(s)); refusing to write it")


def write_json(obj: Any, path: str | os.PathLike[str], *, force: bool = False) -> Path:
    """Write `obj` as indented JSON (metrics, model parameters), atomically.

    NumPy scalars and arrays are converted to plain numbers and lists. NaN and infinity are
    refused because standard JSON cannot represent them.

    Parameters
    ----------
    obj : object
        JSON-serialisable data; numpy scalars and arrays allowed.
    path : str or os.PathLike
        Output ``.json`` file.
    force : bool, default False
        Replace an existing file.

    Returns
    -------
    pathlib.Path
        `path`.

    Raises
    ------
    OutputExistsError
        `path` exists and `force` is False.
    OutputError
        `path` does not end in ``.json`` (`check_output_format`).
    NonFiniteError
        `obj` holds NaN or infinity (the message names the key path, e.g.
        ``metrics.sine.r2`` or ``params.a[3]``); nothing is written.
    """
    path = Path(path)
    check_output_path(path, force, formats=(".json",), what="a JSON file")
    # Serialise before touching the disk so a bad object leaves no file at all.
    try:
        text = json.dumps(obj, indent=2, allow_nan=False, default=_json_default) + "\n"
    except ValueError:
        where = _first_non_finite(json.loads(json.dumps(obj, default=_json_default)))
        raise NonFiniteError(f"{path}: {where}; refusing to write NaN or infinity to "
                             f"JSON") from None
    with atomic_output(path, force) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return path


def _first_non_finite(obj: Any, where: str = "") -> str:
    """Key path and value of the first NaN/inf in a plain JSON object."""
    if isinstance(obj, float) and not math.isfinite(obj):
        return f"value {where or '(top level)'} is {obj}"
    items = (obj.items() if isinstance(obj, dict) else enumerate(obj)
             if isinstance(obj, list) else ())
    for key, value in items:
        sub = f"{where}[{key}]" if isinstance(key, int) else f"{where}.{key}" if where else key
        found = _first_non_finite(value, sub)
        if found:
            return found
    return ""


def _json_default(value: Any) -> Any:
    if isinstance(value, np.ndarray | np.generic):
        return value.tolist()
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    raise TypeError(f"cannot write {type(value).__name__} as JSON")


def check_output_format(path: str | os.PathLike[str], suffixes: Iterable[str],
                        what: str = "this output") -> str:
    """Refuse a file name whose extension does not match the format written to it.

    Parameters
    ----------
    path : str or path-like
        The output file.
    suffixes : iterable of str
        Accepted extensions with the dot (``".json"``), compared without case; the first
        is the format written when there is one.
    what : str
        What is written, for the message (``"a model file"``).

    Returns
    -------
    str
        The extension of `path` in lower case (one of `suffixes`): writers pick the format by it.

    Raises
    ------
    OutputError
        One line: ``out.xlsx: a model file is written as .json or .mat, not '.xlsx'``. A file
        named ``s.mat`` holding JSON, or ``x.xlsx`` holding JSON, would mislead every program
        that opens it.
    """
    suffixes = tuple(s.lower() for s in suffixes)
    suffix = Path(path).suffix.lower()
    if suffix not in suffixes:
        found = f"{suffix!r}" if suffix else "no extension"
        accepted = (", ".join(suffixes[:-1]) + " or " if len(suffixes) > 1 else "") \
            + suffixes[-1]
        raise OutputError(f"{path}: {what} is written as {accepted}, not {found}; name the "
                          f"file accordingly")
    return suffix


def check_output_path(path: str | os.PathLike[str], force: bool = False, *,
                      inputs: Iterable[str | os.PathLike[str]] = (),
                      formats: Iterable[str] | None = None, what: str = "this output") -> Path:
    """Refuse an output path that exists (unless ``force``) or cannot be created.

    Callers run this before any work, so a refused run costs nothing and writes nothing.
    Checked: the path exists (without `force`), is a folder, is one of `inputs`, has a file
    where a parent folder should be, or its nearest existing parent folder is not writable
    (permission, read-only or virtual file system: probed by creating and removing a hidden
    file there); with `formats` (accepted extensions, e.g. ``(".json", ".mat")``), an
    extension that does not match (`check_output_format`, `what` names the content).

    Parameters
    ----------
    path : str or os.PathLike
        The output file.
    force : bool, default False
        Allow replacing an existing file.
    inputs : iterable of str or os.PathLike, optional
        Input files of the command, which must not be overwritten.
    formats : iterable of str, optional
        Accepted extensions; any if None.
    what : str, default "this output"
        What the file holds, for the message about a wrong extension.

    Returns
    -------
    pathlib.Path
        `path`.

    Raises
    ------
    OutputExistsError
        `path` exists and `force` is False.
    OutputError
        Any other reason listed above.
    """
    path = Path(path)
    _check_name_length(path)  # first: the system refuses even to look at a too-long name
    if path.is_dir():
        raise OutputError(f"{path} is a folder, not a file")
    for given in inputs:
        if _same_file(path, Path(given)):
            raise OutputError(f"{path} is also an input of this command; write elsewhere")
    if path.exists() and not force:
        raise OutputExistsError(f"{path} already exists; pass --force to overwrite it")
    if path.exists() and not path.is_file():  # a device, pipe or socket: never replace it
        raise OutputError(f"{path} is not a regular file; write to a file")
    check_folder_writable(path.parent, what=path)
    if formats is not None:
        check_output_format(path, formats, what)
    return path


def _check_name_length(path: Path) -> None:
    """Refuse a name too long for the folder's file system once the temporary's marks are
    added (``.`` + ``.tmp-XXXXXXXX``: 14 bytes), rather than after the work."""
    existing = path.parent
    while not _exists(existing) and existing.parent != existing:
        existing = existing.parent
    try:
        limit = os.pathconf(existing, "PC_NAME_MAX")
    except (OSError, ValueError):
        limit = 255
    for part in (*path.parent.relative_to(existing).parts, path.name):
        if len(part.encode()) + 14 + 4 > limit:  # + 4: the "old-" mark of a replaced file
            raise OutputError(f"{path}: file name too long ({len(part.encode())} bytes; "
                              f"at most {limit - 18} here)")


def _exists(path: Path) -> bool:
    """`Path.exists`, False for a name the system refuses to look up (too long)."""
    try:
        return path.exists()
    except OSError:
        return False


def check_output_folder(folder: str | os.PathLike[str], names: Iterable[str],
                        force: bool = False, *,
                        inputs: Iterable[str | os.PathLike[str]] = ()) -> Path:
    """`check_output_path` for a folder output: the folder itself and each file `names`.

    Parameters
    ----------
    folder : str or os.PathLike
        The output folder.
    names : iterable of str
        Files that will be written into it.
    force : bool, default False
        Allow replacing existing files.
    inputs : iterable of str or os.PathLike, optional
        Input files of the command, which must not be overwritten.

    Returns
    -------
    pathlib.Path
        `folder`.

    Raises
    ------
    OutputError
        `folder` is a file, or a file in it is refused by :func:`check_output_path`.
    """
    folder = Path(folder)
    _check_name_length(folder)
    if folder.exists() and not folder.is_dir():
        raise OutputError(f"{folder} is a file, not a folder")
    inputs = list(inputs)
    for name in names:
        check_output_path(folder / name, force, inputs=inputs)
    return folder


def check_folder_writable(folder: Path, *, what: str | os.PathLike[str] | None = None) -> None:
    """Refuse when files cannot be created in `folder` or in its nearest existing ancestor."""
    what = folder if what is None else what
    existing = Path(folder)
    while not existing.exists():
        if existing.parent == existing:
            break
        existing = existing.parent
    if existing.exists() and not existing.is_dir():
        raise OutputError(f"{what}: cannot create it, {existing} is a file, not a folder")
    if not os.access(existing, os.W_OK | os.X_OK):
        raise OutputError(f"{what}: cannot write into {existing} (permission denied)")
    # os.access says yes to root and knows nothing of read-only mounts or /proc: try it.
    probe = existing / f".hystkit-probe{TEMP_MARK}{secrets.token_hex(4)}"
    try:
        os.close(os.open(probe, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o600))
    except OSError as exc:
        raise OutputError(f"{what}: cannot write into {existing} "
                          f"({exc.strerror or exc})") from None
    probe.unlink(missing_ok=True)


def _same_file(a: Path, b: Path) -> bool:
    try:
        return a.exists() and b.exists() and os.path.samefile(a, b)
    except OSError:
        return False


@contextmanager
def atomic_output(path: str | os.PathLike[str], force: bool = False) -> Iterator[Path]:
    """Yield a temporary path to write `path`'s content to; publish it only on success.

    The temporary is a hidden file in the target's folder (``.STEM.tmp-XXXXXXXX.SUFFIX``: the
    suffix is kept for writers that pick the format by it, e.g. ``savefig``). On leaving the
    block normally it is renamed into place: with `force` by ``os.replace`` (atomic; readers
    see the old or the new file), without by exclusive creation (a hard link, which fails if
    the target appeared meanwhile: of two concurrent writers exactly one wins, the other gets
    `OutputExistsError`). Where hard links are unsupported, an exclusively created placeholder
    is replaced instead (still exclusive; the target is briefly empty). On any exception,
    including KeyboardInterrupt and SystemExit, the temporary is removed and the target left
    as it was. OS errors while writing become one-line `OutputError`s naming `path`.

    Parameters
    ----------
    path : str or os.PathLike
        The output file.
    force : bool, default False
        Replace an existing file.

    Yields
    ------
    pathlib.Path
        The temporary file to write to.

    Raises
    ------
    OutputExistsError
        `path` exists (before or on publishing) and `force` is False.
    OutputError
        `path` cannot be written.

    Examples
    --------
    >>> with atomic_output("out.csv", force=False) as tmp:  # doctest: +SKIP
    ...     frame.to_csv(tmp)
    """
    path = Path(path)
    check_output_path(path, force)

    def publish(tmp: Path) -> None:
        _fsync(tmp)
        _publish(tmp, path, force)

    # after a link, the target keeps the content: the temporary name always goes
    with _staged(path, _create_temporary, publish, lambda tmp: tmp.unlink(missing_ok=True)) \
            as tmp:
        yield tmp


@contextmanager
def _staged(target: Path, make: Callable[[Path], Path], publish: Callable[[Path], None],
            discard: Callable[[Path], None]) -> Iterator[Path]:
    """The mechanism of every atomic output: create the missing parent folders, `make` a
    temporary for `target`, yield it, `publish` it when the block ends normally, `discard` it
    in any case; on failure the parent folders it created are removed again. OS errors become
    one-line `OutputError`s naming `target`."""
    created: list[Path] = []
    try:
        created = _make_parents(target.parent)
        tmp = make(target)
    except OSError as exc:
        _remove_folders(created)
        raise OutputError(f"{target}: cannot write ({exc.strerror or exc})") from None
    done = False
    try:
        try:
            yield tmp
            publish(tmp)
            done = True
        except (OutputError, OutputExistsError):
            raise
        except OSError as exc:
            raise OutputError(f"{target}: cannot write ({exc.strerror or exc})") from None
    finally:
        discard(tmp)
        if not done:
            _remove_folders(created)


def _make_parents(folder: Path) -> list[Path]:
    """Create `folder` and its missing parents; return those created, innermost first."""
    missing = []
    while not folder.exists() and folder.parent != folder:
        missing.append(folder)
        folder = folder.parent
    for made in reversed(missing):
        made.mkdir(exist_ok=True)
    return missing


def _remove_folders(folders: list[Path]) -> None:
    """Remove folders a failed write created (innermost first; only while still empty)."""
    for folder in folders:
        try:
            folder.rmdir()
        except OSError:
            break


def _create_temporary(path: Path) -> Path:
    """Exclusively create an empty hidden file beside `path` (mode from the umask, unlike
    mkstemp's 0600, so the published file gets the usual permissions)."""
    while True:
        tmp = path.with_name(f".{path.stem}{TEMP_MARK}{secrets.token_hex(4)}{path.suffix}")
        try:
            os.close(os.open(tmp, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o666))
            return tmp
        except FileExistsError:
            continue


def _fsync(path: Path) -> None:
    """Flush to disk before the rename, so a power cut cannot publish an empty file."""
    if path.is_file():
        fd = os.open(path, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def _publish(tmp: Path, path: Path, force: bool) -> None:
    if force:
        os.replace(tmp, path)
        return
    try:
        os.link(tmp, path)
    except FileExistsError:
        raise OutputExistsError(f"{path} already exists (created while hystkit was writing "
                                f"it); pass --force to overwrite it") from None
    except OSError as exc:
        if exc.errno not in (errno.EPERM, errno.ENOTSUP, errno.EOPNOTSUPP, errno.EMLINK,
                             errno.EXDEV, errno.ENOSYS):
            raise
        try:  # no hard links here (FAT, some network shares): claim the name, then replace
            os.close(os.open(path, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o666))
        except FileExistsError:
            raise OutputExistsError(f"{path} already exists (created while hystkit was "
                                    f"writing it); pass --force to overwrite it") from None
        os.replace(tmp, path)


@contextmanager
def atomic_folder(out: str | os.PathLike[str], force: bool = False,
                  names: Iterable[str] = ()) -> Iterator[Path]:
    """Yield a temporary folder to build the folder output `out` in; publish it on success.

    The temporary is a hidden sibling of `out` (``.NAME.tmp-XXXXXXXX``; inside `out` if that
    exists already). When the block ends normally: if `out` does not exist, the temporary is
    renamed to it, so the folder appears complete or not at all; if it exists, the built
    files are moved into it one by one only after all were built (with `force` replacing same-named files; without, by
    exclusive creation, and a clash removes the files already moved, so nothing changes).
    On any exception the temporary folder is removed. `names` (files the caller will write)
    are checked first like :func:`check_output_folder`.

    Parameters
    ----------
    out : str or os.PathLike
        The output folder.
    force : bool, default False
        Replace same-named files in an existing `out`.
    names : iterable of str, optional
        Files the caller will write, checked before the block runs.

    Yields
    ------
    pathlib.Path
        The temporary folder to write into.
    """
    out = Path(out)
    check_output_folder(out, names, force)
    with _staged(out, _create_temporary_folder, lambda tmp: _publish_folder(tmp, out, force),
                 lambda tmp: shutil.rmtree(tmp, ignore_errors=True)) as tmp:
        yield tmp


def _create_temporary_folder(out: Path) -> Path:
    """A hidden sibling of `out`; inside `out` when it exists (``.``, ``..``, ``/`` have no
    usable sibling, and the files are merged one by one anyway)."""
    while True:
        name = f".{os.path.basename(os.path.abspath(out)) or 'out'}{TEMP_MARK}" \
               f"{secrets.token_hex(4)}"
        tmp = out / name if out.is_dir() else Path(os.path.abspath(out)).with_name(name)
        try:
            tmp.mkdir()
            return tmp
        except FileExistsError:
            continue


def _publish_folder(tmp: Path, out: Path, force: bool) -> None:
    if not out.exists():
        try:
            # rename(2) refuses a non-empty target (and replaces an empty one, losing nothing)
            os.rename(tmp, out)
            return
        except OSError as exc:
            if exc.errno not in (errno.ENOTEMPTY, errno.EEXIST, errno.ENOTDIR):
                raise
    if not out.is_dir():
        raise OutputError(f"{out} is a file, not a folder")
    files = sorted(p for p in tmp.rglob("*") if p.is_file())  # tmp may lie inside out
    for built in files:
        (out / built.relative_to(tmp)).parent.mkdir(parents=True, exist_ok=True)
    _publish_all([(built, out / built.relative_to(tmp)) for built in files], force)


def _publish_all(pairs: list[tuple[Path, Path]], force: bool) -> None:
    """Publish each (temporary, target); if one fails, undo the ones already published.

    Undo removes a file this run created and, with `force`, puts the replaced file back (kept
    as a hidden hard link until every target is in place).
    """
    done: list[tuple[Path, Path | None]] = []  # target, backup of what it replaced
    try:
        for tmp, target in pairs:
            backup = _backup(target) if force else None
            try:
                _publish(tmp, target, force)
            except (OutputError, OutputExistsError):
                raise
            except OSError as exc:
                if backup is not None:
                    backup.unlink(missing_ok=True)
                raise OutputError(f"{target}: cannot write ({exc.strerror or exc})") from None
            done.append((target, backup))
    except BaseException:
        for target, backup in reversed(done):
            if backup is not None:
                os.replace(backup, target)
            else:
                target.unlink(missing_ok=True)
        raise
    finally:
        for _, backup in done:
            if backup is not None:
                backup.unlink(missing_ok=True)


def _backup(target: Path) -> Path | None:
    """A hidden hard link to `target`'s current file (None: no file, or no hard links)."""
    if not target.is_file():
        return None
    backup = target.with_name(f".{target.name}{TEMP_MARK}old-{secrets.token_hex(4)}")
    try:
        os.link(target, backup)
    except OSError:
        return None
    return backup


@contextmanager
def atomic_outputs(paths: Iterable[str | os.PathLike[str]],
                   force: bool = False) -> Iterator[list[Path]]:
    """:func:`atomic_output` for several files that belong together (data and its report).

    Yields one temporary per path, in order. When the block ends normally they are published
    in order; if one cannot be (it appeared meanwhile), those already published are undone,
    so all appear or none does. On any exception every temporary is removed.

    Parameters
    ----------
    paths : iterable of str or os.PathLike
        The output files.
    force : bool, default False
        Replace existing files.

    Yields
    ------
    list of pathlib.Path
        One temporary per path, in order.
    """
    paths = [Path(p) for p in paths]
    for path in paths:
        check_output_path(path, force)
    created: list[Path] = []
    temps: list[Path] = []
    done = False
    try:
        try:
            for path in paths:
                created += _make_parents(path.parent)
                temps.append(_create_temporary(path))
            yield temps
            for tmp in temps:
                _fsync(tmp)
            _publish_all(list(zip(temps, paths, strict=True)), force)
            done = True
        except (OutputError, OutputExistsError):
            raise
        except OSError as exc:
            raise OutputError(f"{exc.filename or paths[0]}: cannot write "
                              f"({exc.strerror or exc})") from None
    finally:
        for tmp in temps:
            tmp.unlink(missing_ok=True)
        if not done:
            _remove_folders(sorted(set(created), key=lambda p: -len(p.parts)))
