"""Write an export folder atomically (all files or none; an existing folder only with force)."""

from __future__ import annotations

import errno
import os
import shutil
import tempfile
from pathlib import Path

import numpy as np

from ..compensation import Compensator
from ..errors import InputError, OutputError, OutputExistsError
from ..io import atomic_folder, check_output_folder
from ..live import sync_excitation
from ._c import c_files
from ._matlab import matlab_files
from ._plan import ExportPlan, make_plan

__all__ = ["LANGUAGES", "export_compensator", "sync_state_of"]

LANGUAGES = ("c", "matlab")


def sync_state_of(comp: Compensator) -> tuple[np.ndarray | None, str]:
    """The model state after the synchronisation excitation (eq. 2.21-2.22) and a note; the
    state is None, and the note says why, when the model does not forget its history."""
    try:
        sync = sync_excitation(comp)
    except InputError as exc:
        return None, f"no sync start-up: {exc}"
    n_hold = round(sync.hold_seconds / sync.dt)
    levels = ", ".join(f"{sync.signal[i * n_hold]:.6g}" for i in range(len(sync.levels)))
    return sync.state_after, (f"sync start-up: after e_sync, the {sync.quantity} held at "
                              f"{levels} {sync.unit} for {sync.hold_seconds:g} s each "
                              f"({sync.rule})")


def export_compensator(comp: Compensator, out: str | Path, lang: str = "c", *,
                       double: bool = False, name: str | None = None,
                       force: bool = False,
                       level: float | None = None) -> tuple[ExportPlan, dict[str, str]]:
    """Write ``comp`` as code into the folder ``out``; returns the plan and file name -> text.

    Parameters
    ----------
    comp : Compensator
        The fitted compensator.
    out : str or Path
        Output folder, written atomically.
    lang : {"c", "matlab"}
        Target language.
    double : bool
        C only: compute in double instead of float (the MATLAB code is always double, and
        asking for it there is refused rather than ignored).
    name : str, optional
        Identifier of the generated functions (see :func:`make_plan`).
    force : bool
        Write into an existing folder, replacing same-named files. Without it the folder is
        created complete (built beside it, then renamed): of two exports to the same new
        folder exactly one succeeds.
    level : float, optional
        Nominal coverage of the exported prediction band (its lower/upper outputs); default
        the band's own. A compensator without a band exports without band outputs, and
        refuses a `level`.

    Returns
    -------
    plan : ExportPlan
        The numbers written.
    files : dict of str to str
        File name -> text of each file written.

    Raises
    ------
    InputError
        Unknown language, `double` with MATLAB, a `level` without a band, or a compensator
        that cannot be exported (the reason).
    OutputExistsError
        ``out`` exists (or was created while the files were built) and ``force`` is not
        given.
    """
    if lang not in LANGUAGES:
        raise InputError(f"--lang {lang!r}: choose one of {', '.join(LANGUAGES)}")
    if double and lang != "c":
        raise InputError("--double applies to --lang c only (the MATLAB code always computes "
                         "in double)")
    out = Path(out)
    if out.exists() and not force:
        raise OutputExistsError(f"{out} exists; use --force to write into it")
    sync_state, sync_note = sync_state_of(comp)
    plan = make_plan(comp, name, sync_state=sync_state, sync_note=sync_note, level=level)
    files = c_files(plan, double) if lang == "c" else matlab_files(plan)
    _make_parent(out)
    if force:  # into the folder, existing or not: same-named files replaced, others kept
        with atomic_folder(out, force=True, names=files) as tmp:
            _write_files(tmp, files)
    else:
        _create_folder(out, files)
    return plan, files


def _make_parent(out: Path) -> None:
    """Create the folders above `out`, as ``hystkit fit --out dir/model.json`` does (the golden
    run of issue 28 found ``--out new/dir`` ending in an internal error)."""
    try:
        Path(os.path.abspath(out)).parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"{out}: cannot create the folder above it ({exc.strerror})") from None


def _write_files(folder: Path, files: dict[str, str]) -> None:
    for file_name, text in files.items():
        (folder / file_name).write_text(text, encoding="utf-8")


def _create_folder(out: Path, files: dict[str, str]) -> None:
    """Build `files` in a hidden sibling of `out` and rename it to `out`, which must not
    exist: a folder that appeared meanwhile (another export, C beside MATLAB) is refused, not
    merged into (`atomic_folder` merges into a folder that exists when it publishes)."""
    check_output_folder(out, files)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out.name or 'export'}.tmp-",
                                dir=Path(os.path.abspath(out)).parent))
    try:
        _write_files(tmp, files)
        try:
            # rename(2) refuses a non-empty target (and replaces an empty one, losing nothing)
            os.rename(tmp, out)
        except OSError as exc:
            if exc.errno in (errno.ENOTEMPTY, errno.EEXIST, errno.ENOTDIR, errno.EISDIR):
                raise OutputExistsError(f"{out} already exists (created while hystkit was "
                                        f"writing it: another export?); nothing written, use "
                                        f"another --out or --force") from None
            raise OutputError(f"{out}: cannot create the folder ({exc.strerror})") from None
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
