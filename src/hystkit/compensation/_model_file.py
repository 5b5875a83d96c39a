"""Compensator <-> JSON model file (schema ``hystkit.compensator``, version 1).

Keys added since the first files (``polarity``, ``tare_seconds``, ``track_seconds``,
``sensor_reference``, ``rest_position``, ``position_range``) are optional when reading, with the
behaviour of the files that lacked them: polarity +1, no position-range guard. A file with
``center: recording`` (the old default) still loads and runs the paper's protocol, which removes
each recording's own sensor mean: it is an oracle (not causal) and is labelled so.
"""

from __future__ import annotations

import json
from dataclasses import asdict
from pathlib import Path

from .. import __version__
from ..errors import InputError
from ..io import write_json
from ..models import FAMILIES
from ._centring import CENTERS
from ._compensator import MODES, Compensator
from ._conventions import LinearBaseline, Scaling

__all__ = [
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
    """Plain-JSON form: model type, structure, parameters, normalisation, dt, baseline, fit."""
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
        "fit": comp.fit_info,
        "training_range": (None if comp.training_range is None
                           else list(comp.training_range)),
        "position_range": (None if comp.position_range is None
                           else list(comp.position_range)),
        "polarity": comp.polarity,
        "tare_seconds": comp.tare_seconds,
        "track_seconds": comp.track_seconds,
        "sensor_reference": comp.sensor_reference,
        "rest_position": comp.rest_position,
    }


def compensator_from_dict(d: dict, source: str = "<dict>") -> Compensator:
    """Inverse of :func:`compensator_to_dict`; InputError names what is wrong."""
    if not isinstance(d, dict) or d.get("schema") != SCHEMA:
        found = d.get("schema") if isinstance(d, dict) else type(d).__name__
        raise InputError(f"{source}: not a hystkit compensator file (schema {found!r}, "
                         f"expected {SCHEMA!r})")
    if d.get("schema_version") != SCHEMA_VERSION:
        raise InputError(f"{source}: schema_version {d.get('schema_version')!r} is not supported "
                         f"(this hystkit reads version {SCHEMA_VERSION})")
    try:
        if d["model"] not in FAMILIES:
            raise InputError(f"{source}: key 'model': {d['model']!r} is not a known model "
                             f"({', '.join(sorted(FAMILIES))})")
        if d["mode"] not in MODES or d["center"] not in CENTERS:
            raise InputError(f"{source}: key 'mode'/'center': unknown value "
                             f"{d['mode']!r}/{d['center']!r}")
        family = FAMILIES[d["model"]]
        return Compensator(structure=family.structure_type(**d["structure"]),
                           params=family.params_type.from_dict(d["params"]), mode=d["mode"],
                           center=d["center"], scaling=Scaling(**d["normalisation"]),
                           baseline=LinearBaseline(**d["baseline"]), fit_info=d.get("fit", {}),
                           training_range=_pair_or_none(d.get("training_range")),
                           position_range=_pair_or_none(d.get("position_range")),
                           model=d["model"], **_optional(d))
    except KeyError as exc:
        raise InputError(f"{source}: key {exc.args[0]!r} is missing") from None
    except (TypeError, ValueError) as exc:
        raise InputError(f"{source}: invalid model contents ({exc})") from None


def _pair_or_none(value) -> tuple | None:
    return None if value is None else tuple(value)


def _optional(d: dict) -> dict:
    """Keys newer than the first model files, only when present (older files keep defaults)."""
    keys = ("polarity", "tare_seconds", "track_seconds", "sensor_reference", "rest_position")
    return {k: (float(d[k]) if d[k] is not None else None) for k in keys if k in d}


def save_compensator(comp: Compensator, path: str | Path, *, force: bool = False) -> Path:
    """Write the model file; refuses to overwrite unless ``force``."""
    return write_json(compensator_to_dict(comp), path, force=force)


def load_compensator(path: str | Path) -> Compensator:
    """Read a model file written by :func:`save_compensator`."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise InputError(f"{path}: file not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot read model file ({exc})") from None
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(f"{path}: not JSON (line {exc.lineno}: {exc.msg})") from None
    return compensator_from_dict(data, source=str(path))
