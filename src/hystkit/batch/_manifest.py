"""What a batch fits: one `SensorJob` per sensor, from a manifest (CSV or TOML) or a folder.

Manifest CSV: a header row and one row per sensor, columns ``sensor`` (the id: letters,
digits, ``.``, ``_``, ``-``), ``fit`` and ``validate`` (recording paths, several separated by
``;``), and optionally ``model``, ``size``, ``mode``, ``center`` (an empty cell takes the
batch's default). Manifest TOML: a ``[defaults]`` table of those options and one ``[[sensor]]``
table per sensor with ``id``, ``fit``, ``validate`` (a path or a list) and the options.
Relative paths are relative to the manifest's folder.

Folder (`jobs_from_folder`): each sub-folder is a sensor named after it; its recordings whose
names start with ``fit`` are fitted jointly and those starting with ``val`` validate. Each
recording directly in the folder is a sensor of its own, named after the file: its first half
fits, its second half validates.
"""

from __future__ import annotations

import csv
import re
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

from ..compensation import CENTERS, MODES
from ..errors import InputError
from ..models import FAMILIES

__all__ = ["RECORDING_SUFFIXES", "SensorJob", "jobs_from_folder", "read_manifest"]

RECORDING_SUFFIXES = (".csv", ".parquet", ".mat")
OPTION_KEYS = ("model", "size", "mode", "center")
_ID = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]{0,99}")


@dataclass(frozen=True)
class SensorJob:
    """One sensor: its recordings and model options.

    Parameters
    ----------
    sensor : str
        The sensor's id (letters, digits, ``.``, ``_``, ``-``); it names the model file.
    fit : tuple of Path
        Recordings fitted jointly.
    validate : tuple of Path
        Recordings the fit is scored on.
    model : str
        Model family name.
    size : int or None
        Model size; None: the family's default.
    mode : str
        ``"direct"`` or ``"inverse"`` compensation.
    center : str or None
        Centring of the compensator; None: the library's default.
    split : bool
        True: ``fit`` is one recording whose first half fits and second half validates
        (``validate`` is empty).
    where : str
        Where the job was read (manifest row or folder entry), for messages.
    """

    sensor: str
    fit: tuple[Path, ...]
    validate: tuple[Path, ...] = ()
    model: str = "mpl"
    size: int | None = None
    mode: str = "direct"
    center: str | None = None  # None: the library's default centring
    split: bool = False
    where: str = field(default="", compare=False)  # manifest row, for messages

    def describe(self) -> dict:
        """The job as plain values (stored with its result, to tell a changed job)."""
        return {"sensor": self.sensor, "fit": [str(p) for p in self.fit],
                "validate": [str(p) for p in self.validate], "model": self.model,
                "size": self.size, "mode": self.mode, "center": self.center,
                "split": self.split}


def read_manifest(path: Path, defaults: Mapping[str, object]) -> list[SensorJob]:
    """Jobs of a ``.csv`` or ``.toml`` manifest; options missing there come from `defaults`.

    Parameters
    ----------
    path : Path
        The manifest (see the module docstring for its columns or tables).
    defaults : mapping
        The batch's options (keys of ``OPTION_KEYS``) for sensors that do not set them.

    Returns
    -------
    list of SensorJob
        One job per sensor, in the manifest's order; paths resolved against its folder.

    Raises
    ------
    InputError
        Unreadable manifest, a missing column or key, a bad id or option, a repeated id; the
        message names the file and the row (CSV line or ``[[sensor]]`` number).
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".csv", ".toml"):
        raise InputError(f"{path}: a manifest is a .csv or .toml file")
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot read the manifest ({exc})") from None
    entries = _csv_entries(path, text) if suffix == ".csv" else _toml_entries(path, text)
    jobs = [_job(path, where, entry, defaults) for where, entry in entries]
    if not jobs:
        raise InputError(f"{path}: the manifest lists no sensor")
    _check_unique(jobs)
    return jobs


def _csv_entries(path: Path, text: str) -> list[tuple[str, dict]]:
    rows = list(csv.reader(text.splitlines()))
    if not rows:
        raise InputError(f"{path}: empty manifest; expected a header row sensor,fit,validate")
    header = [h.strip() for h in rows[0]]
    missing = [c for c in ("sensor", "fit", "validate") if c not in header]
    unknown = [c for c in header if c not in ("sensor", "fit", "validate", *OPTION_KEYS)]
    if missing or unknown:
        raise InputError(f"{path}: line 1: {'missing column(s) ' + ', '.join(missing) if missing else ''}"
                         f"{'; ' if missing and unknown else ''}"
                         f"{'unknown column(s) ' + ', '.join(unknown) if unknown else ''}; "
                         f"columns: sensor, fit, validate, and optionally "
                         f"{', '.join(OPTION_KEYS)}")
    entries = []
    for line, row in enumerate(rows[1:], start=2):
        if not any(cell.strip() for cell in row):
            continue
        if len(row) != len(header):
            raise InputError(f"{path}: line {line}: {len(row)} fields, the header has "
                             f"{len(header)}")
        cells = {k: v.strip() for k, v in zip(header, row)}
        entry = {k: v for k, v in cells.items() if v != ""}
        for key in ("fit", "validate"):
            entry[key] = [p.strip() for p in cells[key].split(";") if p.strip()]
        entries.append((f"line {line}", entry))
    return entries


def _toml_entries(path: Path, text: str) -> list[tuple[str, dict]]:
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{path}: not valid TOML ({exc})") from None
    sensors = doc.get("sensor", [])
    defaults = doc.get("defaults", {})
    if not isinstance(sensors, list) or not isinstance(defaults, dict):
        raise InputError(f"{path}: expected [defaults] and [[sensor]] tables")
    unknown = [k for k in defaults if k not in OPTION_KEYS]
    if unknown:
        raise InputError(f"{path}: [defaults]: unknown key(s) {', '.join(unknown)}; known: "
                         f"{', '.join(OPTION_KEYS)}")
    entries = []
    for k, table in enumerate(sensors, start=1):
        where = f"[[sensor]] {k}"
        unknown = [key for key in table if key not in ("id", "fit", "validate", *OPTION_KEYS)]
        if unknown:
            raise InputError(f"{path}: {where}: unknown key(s) {', '.join(unknown)}")
        entry = {**defaults, **{key: v for key, v in table.items() if key != "id"}}
        if "id" in table:
            entry["sensor"] = table["id"]
        for key in ("fit", "validate"):
            value = entry.get(key, [])
            entry[key] = [value] if isinstance(value, str) else value
        entries.append((where, entry))
    return entries


def _job(path: Path, where: str, entry: dict, defaults: Mapping[str, object]) -> SensorJob:
    sensor = entry.get("sensor")
    if not isinstance(sensor, str) or not _ID.fullmatch(sensor):
        raise InputError(f"{path}: {where}: sensor id {sensor!r}: use 1-100 letters, digits, "
                         f"'.', '_', '-' (it names the model file), starting with a letter "
                         f"or digit")
    paths = {}
    for key in ("fit", "validate"):
        names = entry[key]
        if not names or not all(isinstance(n, str) and n for n in names):
            raise InputError(f"{path}: {where}: sensor {sensor!r}: column {key!r}: give at "
                             f"least one recording path")
        paths[key] = tuple(path.parent / n for n in names)
    options = {**defaults, **{k: entry[k] for k in OPTION_KEYS if k in entry}}
    job = SensorJob(sensor=sensor, fit=paths["fit"], validate=paths["validate"], where=where)
    return _with_options(job, options, f"{path}: {where}: sensor {sensor!r}")


def _with_options(job: SensorJob, options: Mapping[str, object], where: str) -> SensorJob:
    """`job` with the model options, each checked against the registry (one-line errors)."""
    model = str(options.get("model") or "mpl")
    if model not in FAMILIES:
        raise InputError(f"{where}: unknown model {model!r}; known: "
                         f"{', '.join(sorted(FAMILIES))}")
    family = FAMILIES[model]
    size = options.get("size")
    if size is not None:
        try:
            size = int(str(size))
        except ValueError:
            raise InputError(f"{where}: size {size!r} is not a whole number") from None
        if not 1 <= size <= family.max_size:
            raise InputError(f"{where}: size {size}: {model} accepts 1 to {family.max_size} "
                             f"({family.size_help})")
    mode = str(options.get("mode") or "direct")
    if mode not in MODES or (mode == "inverse" and family.invert is None):
        raise InputError(f"{where}: mode {mode!r}: {model} accepts "
                         f"{'direct' if family.invert is None else ', '.join(MODES)}")
    center = options.get("center")
    if center is not None and center not in CENTERS:
        raise InputError(f"{where}: centring {center!r}; known: {', '.join(CENTERS)}")
    return replace(job, model=model, size=size, mode=mode, center=center)


def _check_unique(jobs: Sequence[SensorJob]) -> None:
    seen: dict[str, str] = {}
    for job in jobs:
        if job.sensor in seen:
            raise InputError(f"sensor id {job.sensor!r} appears twice ({seen[job.sensor]} and "
                             f"{job.where}); ids name the model files")
        seen[job.sensor] = job.where


def jobs_from_folder(folder: Path, defaults: Mapping[str, object]) -> list[SensorJob]:
    """Jobs of a folder of recordings (see the module docstring for the convention).

    Parameters
    ----------
    folder : Path
        Folder of sensor sub-folders and/or recordings; names starting with ``.`` are skipped.
    defaults : mapping
        The batch's options (keys of ``OPTION_KEYS``) for every sensor.

    Returns
    -------
    list of SensorJob
        One job per sensor, in the order of the sorted entry names.

    Raises
    ------
    InputError
        No sensor found, a sub-folder without ``fit*`` or ``val*`` recordings, an id that
        cannot name a file, two sensors with one id.
    """
    folder = Path(folder)
    jobs = []
    for entry in sorted(folder.iterdir()):
        if entry.name.startswith("."):
            continue
        where = f"{folder}: {entry.name}"
        if entry.is_dir():
            recs = sorted(p for p in entry.iterdir() if p.suffix.lower() in RECORDING_SUFFIXES)
            fit = tuple(p for p in recs if p.name.lower().startswith("fit"))
            val = tuple(p for p in recs if p.name.lower().startswith("val"))
            if not fit or not val:
                raise InputError(f"{where}: a sensor folder needs recordings named fit* and "
                                 f"val* (.csv, .parquet, .mat); found "
                                 f"{', '.join(p.name for p in recs) or 'none'}")
            job = SensorJob(sensor=entry.name, fit=fit, validate=val, where=where)
        elif entry.suffix.lower() in RECORDING_SUFFIXES:
            job = SensorJob(sensor=entry.stem, fit=(entry,), split=True, where=where)
        else:
            continue
        if not _ID.fullmatch(job.sensor):
            raise InputError(f"{where}: {job.sensor!r} cannot be a sensor id (it names the "
                             f"model file): use letters, digits, '.', '_', '-'")
        jobs.append(_with_options(job, defaults, where))
    if not jobs:
        raise InputError(f"{folder}: no sensor found: expected sub-folders with fit*/val* "
                         f"recordings or recordings ({', '.join(RECORDING_SUFFIXES)})")
    _check_unique(jobs)
    return jobs
