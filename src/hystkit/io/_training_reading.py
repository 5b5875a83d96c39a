"""What a model file remembers of how its training recordings were read (its ``reading``): one
rule for ``hystkit fit`` and ``select``, `hystkit.fit` given paths and `run_batch`.

A model fitted on files read with one column mapping and time unit remembers them, with a units
line when every CSV among them had one and the units of position and sensor; ``evaluate``,
``compensate``, ``report`` and ``stream --in`` then read a file of that layout without options.
Files read differently leave nothing remembered, and a note says so.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path

from .._read_options import FIELDS, ReadOptions
from ..errors import InputError

__all__ = ["remember_reading", "training_reading", "training_units"]


def training_units(recordings: Sequence, sources: Sequence[str | Path] | None = None,
                   ) -> dict[str, str]:
    """Units of the training recordings' columns (``fit_info["units"]``, which ``compensate``
    labels its estimate with); the recordings must agree.

    Parameters
    ----------
    recordings : sequence of Recording
        The training recordings (pieces of one file count as recordings).
    sources : sequence of path, optional
        Their names for the message; default each recording's ``source``.

    Returns
    -------
    dict
        Column name -> unit, for the columns whose unit a file gave.

    Raises
    ------
    InputError
        Two recordings give one column different units (fitting them jointly mixes scales);
        the message names the later recording (from `sources`, else its ``source``).
    """
    units: dict[str, str] = {}
    names = [rec.source for rec in recordings] if sources is None else list(sources)
    for rec, source in zip(recordings, names, strict=True):
        for name, unit in rec.units:
            if units.setdefault(name, unit) != unit:
                raise InputError(f"{source}: {name} is in {unit!r}, an earlier recording's in "
                                 f"{units[name]!r}; fit recordings in one unit")
    return units


def training_reading(options: Sequence[ReadOptions], paths: Sequence[str | Path],
                     units: dict[str, str]) -> tuple[ReadOptions | None, str]:
    """What a model file remembers of how its training files were read.

    Parameters
    ----------
    options : sequence of ReadOptions
        How each training file was read.
    paths : sequence of path
        The files, in the same order.
    units : dict
        Units of position and sensor of the training recordings (`training_units`).

    Returns
    -------
    reading : ReadOptions or None
        Their columns and time unit, a units line when every CSV among them had one, and
        `units`; None when the files were read with different columns or time units.
    note : str
        Why nothing is remembered, else "".
    """
    paths = [Path(p) for p in paths]
    if len({(o.columns, o.time_unit) for o in options}) > 1:
        shown = "; ".join(f"{p}: {_describe(o)}" for p, o in zip(paths, options, strict=True))
        return None, (f"the training files were read differently ({shown}): the model file "
                      f"does not remember how; later commands read each file as their "
                      f"options and settings files say")
    csvs = [o for o, p in zip(options, paths, strict=True) if p.suffix.lower() == ".csv"]
    first = options[0]
    return ReadOptions(columns=first.columns, time_unit=first.time_unit,
                       units_row=bool(csvs) and all(o.units_row for o in csvs),
                       units=tuple(units.items())), ""


def remember_reading(comp, units: dict[str, str], options: Sequence[ReadOptions] | None,
                     paths: Sequence[str | Path] | None = None):
    """`comp` with its training data's `units` (`training_units`) in ``fit_info["units"]``
    and, when it was fitted on files only (`options` and `paths`, one per file), how they
    were read (``reading``).

    Parameters
    ----------
    comp : Compensator
        The fitted compensator.
    units : dict
        Units of its training recordings (`training_units`).
    options : sequence of ReadOptions or None
        How each training file was read; None when not all the data came from files.
    paths : sequence of path, optional
        The training files, in the order of `options`.

    Returns
    -------
    comp : Compensator
        A copy (its ``fit_info`` too); ``reading`` None when the data were not all files or
        the files were read differently.
    note : str
        Why files were not remembered, else "".
    """
    info = {**comp.fit_info, **({"units": units} if units else {})}
    reading, note = (None, "") if options is None else training_reading(options, paths, units)
    return replace(comp, fit_info=info, reading=reading), note


def _describe(options: ReadOptions) -> str:
    columns = ",".join(options.name(field) for field in FIELDS)
    return f"columns {columns}, time in {options.time_unit}"
