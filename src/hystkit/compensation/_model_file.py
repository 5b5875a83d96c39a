"""Compensator <-> model file (schema ``hystkit.compensator``, version 1), JSON or MATLAB.

A ``.mat`` model file holds every key of the JSON file as a MATLAB variable (structs for the
sections; ``m = load('model.mat')`` gives one struct with every field) and the JSON text itself
as ``hystkit_json``, which is what hystkit reads back: MATLAB has no integers, nulls or
one-element lists apart from scalars, so only the text round-trips exactly. Reading checks that
the ``params`` variables still equal the text's, so a model edited in MATLAB is refused rather
than silently ignored.

Keys added since the first files (``polarity``, ``tare_seconds``, ``track_seconds``,
``sensor_reference``, ``rest_position``, ``position_range``, ``band``, ``reading``) are optional
when reading, with the behaviour of the files that lacked them: polarity +1, no position-range
guard, no band, recordings read as the command line and settings files say. ``reading`` is how
the training recordings were read (``columns``, ``time_unit``, ``units_row``, ``units``;
`check_reading`), which later commands apply to a file of the same column names. A file with
``center: recording`` (the old default) still loads and runs the paper's protocol, which removes
each recording's own sensor mean: it is an oracle (not causal) and is labelled so.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np

from .. import __version__
from .._docfill import fill_output_doc
from .._read_options import ReadOptions
from ..errors import InputError
from ..io import check_output_format, load_mat, matlab_name, write_json, write_mat
from ..models import FAMILIES
from ._band import Band
from ._centring import CENTERS
from ._compensator import MODES, Compensator
from ._conventions import LinearBaseline, Scaling
from ._model_checks import (
    MAX_MODEL_BYTES,
    check_keys,
    check_like,
    check_model_dict,
    check_model_domain,
    check_reading,
    key_in_message,
)

__all__ = [
    "MAT_JSON_KEY",
    "MODEL_SUFFIXES",
    "SCHEMA",
    "SCHEMA_VERSION",
    "compensator_from_dict",
    "compensator_to_dict",
    "load_compensator",
    "save_compensator",
]

SCHEMA = "hystkit.compensator"
SCHEMA_VERSION = 1


def compensator_to_dict(comp: Compensator) -> dict:
    """Plain-JSON form: model type, structure, parameters, normalisation, dt, baseline, fit.

    Parameters
    ----------
    comp : Compensator
        The compensator.

    Returns
    -------
    dict
        Plain JSON (numbers, strings, lists, dicts).
    """
    return {
        "schema": SCHEMA,
        "schema_version": SCHEMA_VERSION,
        "hystkit_version": __version__,
        "model": comp.model,
        "mode": comp.mode,
        "center": comp.center,
        "dt": comp.structure.dt,
        "structure": asdict(comp.structure),
        "params": comp.params.to_dict(),
        "normalisation": asdict(comp.scaling),
        "baseline": asdict(comp.baseline),
        "fit_seconds": comp.fit_info.get("fit_seconds"),
        "fit": comp.fit_info.to_dict(),
        "training_range": (None if comp.training_range is None
                           else list(comp.training_range)),
        "position_range": (None if comp.position_range is None
                           else list(comp.position_range)),
        "polarity": comp.polarity,
        "tare_seconds": comp.tare_seconds,
        "track_seconds": comp.track_seconds,
        "sensor_reference": comp.sensor_reference,
        "rest_position": comp.rest_position,
        "band": None if comp.band is None else comp.band.to_dict(),
        "reading": _reading_dict(comp.reading),
    }


def _reading_dict(reading: ReadOptions | None) -> dict | None:
    """The ``reading`` section: the fields of `reading` a model file keeps (`READING_KEYS`);
    empty ``columns`` and ``units`` are left out (in MATLAB an empty struct does not survive
    a load and save)."""
    if reading is None:
        return None
    section = {"time_unit": reading.time_unit, "units_row": reading.units_row}
    for key in ("columns", "units"):
        if getattr(reading, key):
            section[key] = dict(getattr(reading, key))
    return section


def compensator_from_dict(d: dict, source: str = "<dict>") -> Compensator:
    """Inverse of :func:`compensator_to_dict`; InputError names what is wrong and where.

    Every value is checked (type, finiteness, size; :func:`check_model_dict`) before the
    family sees it, and whatever the family's own validation raises becomes an InputError
    naming the key path (``params.a``): a model file is untrusted input.

    Parameters
    ----------
    d : dict
        The plain-JSON form (:func:`compensator_to_dict`).
    source : str, default "<dict>"
        Name used in error messages (the file).

    Returns
    -------
    Compensator
        The compensator, with ``source`` set.

    Raises
    ------
    InputError
        Another schema or schema version, a missing key, or a value of the wrong type, size or
        range.
    """
    if not isinstance(d, dict) or d.get("schema") != SCHEMA:
        found = d.get("schema") if isinstance(d, dict) else type(d).__name__
        raise InputError(f"{source}: not a hystkit compensator file (schema {found!r}, "
                         f"expected {SCHEMA!r})")
    version = d.get("schema_version")
    if version != SCHEMA_VERSION:
        newer = (isinstance(version, int | float) and not isinstance(version, bool)
                 and version > SCHEMA_VERSION)
        raise InputError(f"{source}: key 'schema_version': {version!r} is not supported (this "
                         f"hystkit reads version {SCHEMA_VERSION}"
                         + ("; the file was written by a newer hystkit)" if newer else ")"))
    missing = [k for k in ("model", "mode", "center", "structure", "params", "normalisation",
                           "baseline") if k not in d]
    if missing:
        raise InputError(f"{source}: key {missing[0]!r} is missing")
    check_model_dict(d, source)
    if d["model"] not in FAMILIES:
        raise InputError(f"{source}: key 'model': {d['model']!r} is not a known model "
                         f"({', '.join(sorted(FAMILIES))})")
    for key, known in (("mode", MODES), ("center", CENTERS)):
        if d[key] not in known:
            raise InputError(f"{source}: key {key!r}: unknown value {d[key]!r} "
                             f"({', '.join(known)})")
    family = FAMILIES[d["model"]]
    check_like(source, "structure", d["structure"],
               family.make_structure(1.0, family.default_size).to_dict())
    for section, record in (("structure", family.structure_type), ("normalisation", Scaling),
                            ("baseline", LinearBaseline)):
        check_keys(source, section, d[section], record)
    check_model_domain(d, source)
    structure = _build(source, "structure", {name: "structure" for name in d["structure"]},
                       lambda: family.structure_type(**d["structure"]))
    params = _build(source, "params", {name: "params" for name in d["params"]},
                    lambda: family.params_type.from_dict(d["params"]))
    band = None if d.get("band") is None else _build(
        source, "band", {name: "band" for name in d["band"]}, lambda: Band.from_dict(d["band"]))
    # The compensator runs the model on two samples: structure and params must fit together.
    return _build(source, "", _sections(d), lambda: Compensator(
        structure=structure, params=params, mode=d["mode"], center=d["center"],
        scaling=Scaling(**d["normalisation"]), baseline=LinearBaseline(**d["baseline"]),
        fit_info=d.get("fit") or {}, training_range=_pair_or_none(d.get("training_range")),
        position_range=_pair_or_none(d.get("position_range")), model=d["model"],
        source=source, band=band, reading=check_reading(d.get("reading"), source),
        **_optional(d)), _defaulted(structure, d["structure"]))


def _defaulted(structure: Any, given: dict) -> str:
    """The structure fields a file left out (their defaults were used), to add to an error
    about the model that they may explain (``params have 3 cells, structure has 1``)."""
    missing = [f"structure.{k} (default {v!r})" for k, v in structure.to_dict().items()
               if k not in given]
    return f"; key {', '.join(missing)} missing from the file" if missing else ""


def _sections(d: dict) -> dict[str, str]:
    """Field name -> its section ("" at the top level), to name the key path of a
    compensator-level error."""
    sections = {key: "" for key in ("polarity", "tare_seconds", "track_seconds",
                                    "training_range", "position_range", "mode", "model")}
    for section in ("baseline", "normalisation", "structure", "params"):
        sections.update({name: section for name in d[section]})
    return sections


def _build(source: str, section: str, sections: dict[str, str],
           make: Callable[[], Any], note: str = "") -> Any:
    """Run a family's (or the compensator's) constructor on checked values; whatever it
    raises becomes an InputError naming the key path: ``section.field`` when the message names
    a field of `sections`, else `section` (none if that is ""); `note` is appended to it."""
    try:
        return make()
    except InputError:
        raise
    except KeyError as exc:  # Record.from_dict: "Params needs a, b"
        detail = exc.args[0] if exc.args else exc
        raise InputError(f"{source}: key {section!r}: {detail} (missing key)") from None
    # What a family's validation raises for bad values; anything else (NameError, ...) is a bug
    # in hystkit and must reach the CLI's internal-error line, not pose as a bad file.
    except (ValueError, TypeError, ArithmeticError, IndexError) as exc:
        message = str(exc) or type(exc).__name__
        name = key_in_message(message, sections)
        path = section if name is None else ".".join(filter(None, (sections[name], name)))
        where = f"key {path!r}: " if path else "invalid model contents: "
        if not path and "params" in message and "structure" in message:
            where = "keys 'structure' and 'params' do not fit together: "
        raise InputError(f"{source}: {where}{message}{note}") from None


def _pair_or_none(value: list | None) -> tuple | None:
    return None if value is None else tuple(value)


def _optional(d: dict) -> dict:
    """Keys newer than the first model files, only when present (older files keep defaults)."""
    keys = ("polarity", "tare_seconds", "track_seconds", "sensor_reference", "rest_position")
    return {k: (float(d[k]) if d[k] is not None else None) for k in keys if k in d}


MODEL_SUFFIXES = (".json", ".mat")
MAT_JSON_KEY = "hystkit_json"  # the variable of a .mat model file that hystkit reads back


@fill_output_doc
def save_compensator(comp: Compensator, path: str | Path, *, force: bool = False) -> Path:
    """Write the model file, JSON or MATLAB by the extension of `path` (``.json``/``.mat``);
    refuses another extension, and to overwrite unless ``force``.

    Parameters
    ----------
    comp : Compensator
        The compensator.
    path : str or pathlib.Path
        Output file, ``.json`` or ``.mat``.
    %(force)s

    %(written_path)s
    OutputError
        Another extension.
    """
    path = Path(path)
    d = compensator_to_dict(comp)
    if check_output_format(path, MODEL_SUFFIXES, "a model file") == ".json":
        return write_json(d, path, force=force)
    text = json.dumps(d, allow_nan=False, default=_plain)
    return write_mat(path, {**d, MAT_JSON_KEY: text}, force=force)


def _plain(value: Any) -> Any:
    if hasattr(value, "tolist"):
        return value.tolist()
    raise TypeError(f"cannot write {type(value).__name__} to a model file")


def load_compensator(path: str | Path) -> Compensator:
    """Read a model file written by :func:`save_compensator`.

    ``.mat`` files (written by :func:`save_compensator`) are parsed in a child process like
    every MATLAB input.

    Parameters
    ----------
    path : str or pathlib.Path
        A ``.json`` or ``.mat`` model file.

    Returns
    -------
    Compensator
        The compensator, with ``source`` naming `path`.

    Raises
    ------
    InputError
        For any problem with the file (missing, a folder, binary, larger than
        ``MAX_MODEL_BYTES``, not JSON, nested too deeply) or its contents (see
        :func:`compensator_from_dict`), naming the file and the key path.
    """
    path = Path(path)
    try:
        if path.is_dir():
            raise InputError(f"{path}: is a folder, not a model file")
        size = path.stat().st_size
        if size > MAX_MODEL_BYTES:
            raise InputError(f"{path}: {size} bytes, larger than any model file "
                             f"(limit {MAX_MODEL_BYTES}); is this a model file?")
        if path.suffix.lower() == ".mat":
            return _load_mat_model(path)
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise InputError(f"{path}: file not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot read model file ({exc})") from None
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(f"{path}: not JSON (line {exc.lineno}: {exc.msg})") from None
    except RecursionError:
        raise InputError(f"{path}: not a model file (JSON nested too deeply)") from None
    return compensator_from_dict(data, source=str(path))


def _load_mat_model(path: Path) -> Compensator:
    """A ``.mat`` model file: the model in its ``hystkit_json`` text, after checking that its
    ``params`` variables (what a MATLAB user would edit) still equal the text's."""
    source = str(path)
    contents = load_mat(path, ["params.*"], source, texts=(MAT_JSON_KEY,))
    if MAT_JSON_KEY not in contents.texts:
        listed = ", ".join(contents.variables) or "none"
        raise InputError(f"{source}: not a hystkit model file (no text variable "
                         f"{MAT_JSON_KEY!r}; variables: {listed})")
    try:
        data = json.loads(contents.texts[MAT_JSON_KEY])
    except json.JSONDecodeError as exc:
        raise InputError(f"{source}: variable {MAT_JSON_KEY!r} is not JSON ({exc.msg})") from None
    except RecursionError:
        raise InputError(f"{source}: not a model file (JSON nested too deeply)") from None
    comp = compensator_from_dict(data, source=source)
    for name, value in data["params"].items():
        if not _numeric(value):  # nested lists are cell arrays in MATLAB: not compared
            continue
        stored = contents.arrays.get(f"params.{matlab_name(name)}")
        if stored is None or not np.array_equal(np.ravel(stored), np.ravel(value)):
            raise InputError(f"{source}: variable params.{name} differs from the model in "
                             f"{MAT_JSON_KEY!r} (edited in MATLAB?); hystkit reads the model "
                             f"from {MAT_JSON_KEY!r}: fit again rather than edit a model file")
    return comp


def _numeric(value: Any) -> bool:
    """A number or a flat list of numbers (what a MATLAB double array holds)."""
    items = value if isinstance(value, list) else [value]
    return all(isinstance(v, int | float) and not isinstance(v, bool) for v in items)
