"""Atomic publication of outputs (files, folders, several files at once).

Every output is published atomically (see :func:`atomic_output` and :func:`atomic_folder`):
it is built under a hidden temporary name beside its target and renamed into place only when
complete, so a crash, Ctrl-C, SIGTERM or a full disk leaves the old file (or nothing), never a
partial one, and without ``force`` two concurrent writers of one path cannot both win.
"""

from __future__ import annotations

import errno
import os
import secrets
import shutil
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path

from hystkit.errors import OutputError, OutputExistsError

from .._docfill import fill_output_doc

# check_folder_writable: re-exported for cli.cmd_report, which imports it from here.
from ._output_checks import TEMP_MARK, check_folder_writable, check_output_folder, check_output_path
from ._unfinished import forget, register

__all__ = ["atomic_folder", "atomic_output", "atomic_outputs", "check_folder_writable"]


@fill_output_doc
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
    %(force)s

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
        forget(tmp)
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
        tmp = register(path.with_name(f".{path.stem}{TEMP_MARK}{secrets.token_hex(4)}"
                                      f"{path.suffix}"))
        try:
            os.close(os.open(tmp, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o666))
            return tmp
        except FileExistsError:  # another writer's
            forget(tmp)
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
        tmp = register(out / name if out.is_dir()
                       else Path(os.path.abspath(out)).with_name(name))
        try:
            tmp.mkdir()
            return tmp
        except FileExistsError:  # another writer's
            forget(tmp)
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
