"""Output paths: the checks every command runs before any work.

A refused output costs nothing and writes nothing: it exists (without ``force``), is a folder,
is an input, has the wrong extension, a name too long once the temporary's marks are added, or
lies where files cannot be created. Publication itself is :mod:`._atomic`.
"""

from __future__ import annotations

import os
import secrets
from collections.abc import Iterable
from pathlib import Path

from hystkit.errors import OutputError, OutputExistsError

from .._docfill import fill_output_doc
from ._unfinished import forget, register

__all__ = ["TEMP_MARK", "check_folder_writable", "check_output_folder", "check_output_format",
           "check_output_path"]

TEMP_MARK = ".tmp-"  # every temporary's name holds this; tests look for strays by it


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


@fill_output_doc
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

    %(written_path)s
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
    probe = register(existing / f".hystkit-probe{TEMP_MARK}{secrets.token_hex(4)}")
    try:
        os.close(os.open(probe, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o600))
    except OSError as exc:
        forget(probe)
        raise OutputError(f"{what}: cannot write into {existing} "
                          f"({exc.strerror or exc})") from None
    probe.unlink(missing_ok=True)
    forget(probe)


def _same_file(a: Path, b: Path) -> bool:
    try:
        return a.exists() and b.exists() and os.path.samefile(a, b)
    except OSError:
        return False
