"""Checks of a model file's contents before any of it reaches a family's code.

A model file is untrusted input: every value is checked for its JSON type, finiteness and size
here, so that a bad file gives one error naming the file and the key path (``params.a``,
``structure.n_cells``), never a traceback from deep inside a family, and nothing is allocated
for sizes nobody could have fitted.

Then every number outside ``params`` is checked against the domain a fit writes it from
(:func:`check_model_domain`): a recording holds magnitudes up to ``MAX_MAGNITUDE`` (1e100), so
offsets lie within it and scales (max |.| of centred data) within ``[MIN_SCALE, MAX_SCALE]``;
normalised quantities (training sensor range, straight line) within their normalised bounds;
the sample time within the families' ``DT_RANGE``. A tampered
``normalisation.position_scale = 1e308`` is refused here rather than turned into estimates of
1e308 mm; a scale within the limits that does not fit the training positions is caught by the
compensator's runaway guard, after de-normalisation. ``params`` are checked by each family
against its own documented domain.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Iterable, Iterator
from typing import Any

from .._read_options import FIELDS, TIME_UNITS, ReadOptions
from ..errors import InputError
from ..io import MAX_MAGNITUDE
from ..models import DT_RANGE
from ._runaway import MAX_NORMALISED

__all__ = ["MAX_MODEL_BYTES", "MAX_PARAM_NUMBERS", "MAX_SCALE", "MAX_STRUCTURE_INT",
           "MAX_WINDOW_SAMPLES", "MIN_SCALE", "READING_KEYS", "check_keys", "check_like",
           "check_model_dict", "check_model_domain", "check_reading", "key_in_message"]

# A 10 000-cell mPL file is under 1 MB; anything far larger is not a model hystkit wrote.
MAX_MODEL_BYTES = 16 * 2**20
# Fitted numbers in ``params``: far above any fit hystkit can run (Preisach grids ~ 10^4).
MAX_PARAM_NUMBERS = 1_000_000
# Integer sizes in ``structure`` (cells, levels, substeps, capacity): above this a file is
# refused before the family allocates or loops over them (boucwen ``substeps: 1e12`` hangs).
MAX_STRUCTURE_INT = 100_000

# Scales are max |x - offset| of data with |x| <= MAX_MAGNITUDE: at most twice it. The lower
# limit mirrors it: normalising a recording's sensor (|s| <= 1e100) by a scale of at least
# 1e-100 stays finite (<= 2e200), where a subnormal scale gave inf and an internal error.
MAX_SCALE = 2.0 * MAX_MAGNITUDE
MIN_SCALE = 1.0 / MAX_MAGNITUDE
# Tare window and tracker time constant, in samples of dt: beyond it the tracker's gain
# 1 - exp(-dt / track_seconds) rounds to 0 (a 0/0 sensor level) and the window's sample count
# stops being an integer a stream can hold.
MAX_WINDOW_SAMPLES = 1e12
# Relative slack of the normalised training range's bound 1 and of dt's two copies.
_SLACK = 1e-9
# Sections whose leaves are numbers only (strings are allowed in ``structure``).
_NUMERIC_SECTIONS = ("params", "normalisation", "baseline")
_OPTIONAL_NUMBERS = ("polarity", "tare_seconds", "track_seconds", "sensor_reference",
                     "rest_position", "dt")
# The ``reading`` section: how the training recordings were read (`ReadOptions` fields)
READING_KEYS = ("columns", "time_unit", "units_row", "units")
MAX_READING_NAME = 1000  # characters of a column name or unit: far beyond any file's


def check_model_dict(d: dict, source: str) -> None:
    """Refuse wrong JSON types, non-finite numbers and oversized sizes, naming the key path.

    Raises
    ------
    InputError
        ``"<source>: key 'params.a': ..."`` for the first problem found.
    """
    for key in ("model", "mode", "center"):
        if key in d and not isinstance(d[key], str):
            _fail(source, key, f"must be a string, got {_show(d[key])}")
    for key in ("structure", *_NUMERIC_SECTIONS):
        if key in d and not isinstance(d[key], dict):
            _fail(source, key, f"must be a JSON object, got {_show(d[key])}")
    if "fit" in d and d["fit"] is not None and not isinstance(d["fit"], dict):
        _fail(source, "fit", f"must be a JSON object, got {_show(d['fit'])}")
    for key in _NUMERIC_SECTIONS:
        for path, value in _leaves(d.get(key, {}), key):
            _check_number(source, path, value)
    n_params = sum(1 for _ in _leaves(d.get("params", {}), "params"))
    if n_params > MAX_PARAM_NUMBERS:
        _fail(source, "params", f"{n_params} numbers, more than the limit {MAX_PARAM_NUMBERS}")
    for path, value in _leaves(d.get("structure", {}), "structure"):
        if isinstance(value, str):
            continue
        _check_number(source, path, value, bool_ok=True)
        if not isinstance(value, bool) and (isinstance(value, int) or value.is_integer()) \
                and abs(value) > MAX_STRUCTURE_INT:
            _fail(source, path, f"{value:g} is beyond the size limit {MAX_STRUCTURE_INT} of a "
                                f"model file")
    for key in ("training_range", "position_range"):
        value = d.get(key)
        if value is not None and not (isinstance(value, list) and len(value) == 2):
            _fail(source, key, f"must be null or a list [low, high], got {_show(value)}")
        for path, item in _leaves(value or [], key):
            _check_number(source, path, item)
    for key in _OPTIONAL_NUMBERS:
        if d.get(key) is not None:
            _check_number(source, key, d[key])
    band = d.get("band")
    if band is not None:
        if not isinstance(band, dict):
            _fail(source, "band", f"must be null or a JSON object, got {_show(band)}")
        _check_band_types(band, source)
    check_reading(d.get("reading"), source)


def check_reading(reading: Any, source: str) -> ReadOptions | None:
    """The ``reading`` section (how the training data were read), checked and built.

    Parameters
    ----------
    reading : object
        The section's contents: null, or an object with ``columns`` (hystkit name -> the
        file's column name), ``time_unit``, ``units_row`` and ``units`` (name -> unit), each
        optional.
    source : str
        The file, for messages.

    Returns
    -------
    ReadOptions or None
        Those fields as reading options (the others at their defaults); None for null or a
        file without the key (written before it was kept).

    Raises
    ------
    InputError
        ``"<source>: key 'reading.time_unit': ..."``: not an object, an unknown key, a value
        of the wrong type, or one `ReadOptions` refuses (an unknown unit, two names read
        from one column).
    """
    if reading is None:
        return None
    if not isinstance(reading, dict):
        _fail(source, "reading", f"must be null or a JSON object, got {_show(reading)}")
    for key, value in reading.items():
        if key not in READING_KEYS:
            _fail(source, f"reading.{key}", f"unknown key (expected {', '.join(READING_KEYS)})")
        if key in ("columns", "units"):
            _check_names(source, f"reading.{key}", value, FIELDS if key == "columns" else None)
    if not isinstance(reading.get("time_unit", "s"), str) \
            or reading.get("time_unit", "s") not in TIME_UNITS:
        _fail(source, "reading.time_unit", f"must be one of {', '.join(TIME_UNITS)}, got "
                                           f"{_show(reading['time_unit'])}")
    if not isinstance(reading.get("units_row", False), bool):
        _fail(source, "reading.units_row", f"must be true or false, got "
                                           f"{_show(reading['units_row'])}")
    try:
        return ReadOptions(columns=tuple(reading.get("columns", {}).items()),
                           time_unit=reading.get("time_unit", "s"),
                           units_row=reading.get("units_row", False),
                           units=tuple(reading.get("units", {}).items()))
    except ValueError as exc:  # two names from one column, crossed columns
        path = "reading.units" if str(exc).startswith("units") else "reading.columns"
        raise InputError(f"{source}: key {path!r}: {exc}") from None


def _check_names(source: str, path: str, value: Any, keys: tuple[str, ...] | None) -> None:
    """An object of text values (column names or units), keyed by `keys` when given."""
    if not isinstance(value, dict):
        _fail(source, path, f"must be a JSON object, got {_show(value)}")
    for key, item in value.items():
        if keys is not None and key not in keys:
            _fail(source, f"{path}.{key}", f"unknown key (expected {', '.join(keys)})")
        if not isinstance(item, str) or not item.strip() or len(item) > MAX_READING_NAME:
            _fail(source, f"{path}.{key}", f"must be a non-empty text of at most "
                                           f"{MAX_READING_NAME} characters, got {_show(item)}")


def check_model_domain(d: dict, source: str) -> None:
    """Refuse numbers outside the domain a fit writes them from, naming the key path.

    Runs after :func:`check_model_dict` (types and finiteness are known good). The limits are
    in the module docstring; ``params`` are left to the family.

    Parameters
    ----------
    d : dict
        The model file's contents.
    source : str
        The file, for messages.

    Raises
    ------
    InputError
        ``"<source>: key 'normalisation.position_scale': ..."`` for the first value outside
        its domain.
    """
    dt = d.get("structure", {}).get("dt")
    for path, value in (("dt", d.get("dt")), ("structure.dt", dt)):
        if value is not None:
            _within(source, path, value, *DT_RANGE, "s: the sample times a model runs at")
    if d.get("dt") is not None and dt is not None \
            and abs(d["dt"] - dt) > _SLACK * abs(dt):
        _fail(source, "dt", f"{d['dt']!r} s differs from structure.dt {dt!r} s (a fit writes "
                            f"the same step to both)")
    scaling = d.get("normalisation", {})
    for name, value in scaling.items():
        if name.endswith("_scale"):
            _within(source, f"normalisation.{name}", value, MIN_SCALE, MAX_SCALE,
                    "(a positive normal number: the max |.| of centred training data)")
        else:
            _within(source, f"normalisation.{name}", value, -MAX_MAGNITUDE, MAX_MAGNITUDE,
                    "(the largest magnitude a recording may hold)")
    for name, value in d.get("baseline", {}).items():
        _within(source, f"baseline.{name}", value, -MAX_NORMALISED, MAX_NORMALISED,
                "(normalised units)")
    for i, value in enumerate(d.get("training_range") or []):
        _within(source, f"training_range[{i}]", value, -1.0 - _SLACK, 1.0 + _SLACK,
                "(the normalised training sensor, max |.| = 1 by eq. 5.10)")
    for i, value in enumerate(d.get("position_range") or []):
        _within(source, f"position_range[{i}]", value, -MAX_MAGNITUDE, MAX_MAGNITUDE,
                "mm (the largest magnitude a recording may hold)")
    for name in ("sensor_reference", "rest_position"):
        if d.get(name) is not None:
            _within(source, name, d[name], -MAX_MAGNITUDE, MAX_MAGNITUDE,
                    "(the largest magnitude a recording may hold)")
    step = dt if dt is not None else d.get("dt")
    for name in ("tare_seconds", "track_seconds"):
        if d.get(name) is not None:
            high = MAX_WINDOW_SAMPLES * step if step is not None else math.inf
            _within(source, name, d[name], _TINY, high,
                    f"s (positive, at most {MAX_WINDOW_SAMPLES:g} samples of dt)")
    _check_band_domain(d.get("band"), step, source)


def _check_band_types(band: dict, source: str) -> None:
    """The band's JSON types: ``quantiles`` a list of numbers, ``protocol`` a string, every
    other key a number (its domain is checked by :func:`_check_band_domain`)."""
    for key, value in band.items():
        path = f"band.{key}"
        if key == "protocol":
            if not isinstance(value, str):
                _fail(source, path, f"must be a string, got {_show(value)}")
        elif key == "quantiles":
            if not isinstance(value, list):
                _fail(source, path, f"must be a list of numbers, got {_show(value)}")
            for i, item in enumerate(value):
                _check_number(source, f"{path}[{i}]", item)
        else:
            _check_number(source, path, value)


def _check_band_domain(band: dict | None, step: float | None, source: str) -> None:
    """The band's numbers within what a calibration writes: score quantiles are position
    errors (at most twice the largest magnitude), rates of a normalised sensor at most
    2 / dt, the memory a window of dt."""
    if band is None:
        return
    for i, value in enumerate(band.get("quantiles") or []):
        _within(source, f"band.quantiles[{i}]", value, 0.0, 2.0 * MAX_MAGNITUDE,
                "(a position error: at most twice the largest magnitude of a recording)")
    high = math.inf if step is None else MAX_WINDOW_SAMPLES * step
    for name in ("tau",):
        if name in band:
            _within(source, f"band.{name}", band[name], _TINY, high,
                    f"s (positive, at most {MAX_WINDOW_SAMPLES:g} samples of dt)")
    fastest = math.inf if step is None else 2.0 * (1.0 + _SLACK) / step
    for name in ("rate_reference", "rate_high"):
        if name in band:
            _within(source, f"band.{name}", band[name], _TINY, fastest,
                    "/s (a rate of the normalised training sensor: at most 2 / dt)")
    if "n_calibration" in band:
        _within(source, "band.n_calibration", band["n_calibration"], 1.0, MAX_MAGNITUDE,
                "(held-out samples)")


_TINY = float.fromhex("0x1p-1022")  # the smallest normal float


def _within(source: str, path: str, value: float, low: float, high: float, why: str) -> None:
    if not low <= value <= high:
        _fail(source, path, f"{value!r} is outside [{low:g}, {high:g}] {why}")


def check_keys(source: str, section: str, values: dict, record: type) -> None:
    """The keys of `values` against the fields of the dataclass `record` it is built into:
    a missing required field or an unknown key is named, never a constructor's TypeError.

    Parameters
    ----------
    source : str
        The file, for messages.
    section : str
        The key path of `values` (``"normalisation"``).
    values : dict
        The section's contents.
    record : type
        The dataclass built from them.

    Raises
    ------
    InputError
        ``"<source>: key 'normalisation.position_scale' is missing"`` or ``"... key
        'normalisation.bogus': unknown key (expected ...)"``.
    """
    fields = [f for f in dataclasses.fields(record) if f.init]
    names = [f.name for f in fields]
    for f in fields:
        required = (f.default is dataclasses.MISSING
                    and f.default_factory is dataclasses.MISSING)
        if required and f.name not in values:
            raise InputError(f"{source}: key '{section}.{f.name}' is missing")
    for key in values:
        if key not in names:
            _fail(source, f"{section}.{key}", f"unknown key (expected {', '.join(names)})")


def check_like(source: str, section: str, values: dict, reference: dict) -> None:
    """Each value of `values` has the JSON kind (number, string, list) of the same key in
    `reference` (a family's default structure), so that ``n_cells: "abc"`` is named as such."""
    for key, value in values.items():
        if key not in reference:
            continue  # unknown keys: the family's constructor names them
        want = _kind(reference[key])
        if want != "any" and _kind(value) not in (want, "any"):
            _fail(source, f"{section}.{key}", f"must be a {want}, got {_show(value)}")


def _kind(value: Any) -> str:
    if isinstance(value, str):
        return "string"
    if isinstance(value, list | tuple):
        return "list"
    if isinstance(value, int | float) or value is None:
        return "number" if not isinstance(value, bool) and value is not None else "any"
    return "any"


def key_in_message(message: str, names: Iterable[str]) -> str | None:
    """The one of `names` that `message` mentions first as a word (the field an error is
    about: ``v_g must be positive (f and g ...)`` is about ``v_g``, not ``g``)."""
    found = []
    for name in names:
        match = re.search(rf"(?<![\w.]){re.escape(name)}(?!\w)", message)
        if match:
            found.append((match.start(), -len(name), name))
    return min(found)[2] if found else None


def _leaves(value: Any, path: str) -> Iterator[tuple[str, Any]]:
    """(key path, value) of every leaf below `value`; list items as ``path[i]``."""
    if isinstance(value, dict):
        for key, item in value.items():
            yield from _leaves(item, f"{path}.{key}")
    elif isinstance(value, list):
        for i, item in enumerate(value):
            yield from _leaves(item, f"{path}[{i}]")
    else:
        yield path, value


def _check_number(source: str, path: str, value: Any, *, bool_ok: bool = False) -> None:
    if isinstance(value, bool):
        if bool_ok:
            return
        _fail(source, path, f"must be a number, got {_show(value)}")
    if not isinstance(value, int | float):
        _fail(source, path, f"must be a number, got {_show(value)}")
    if isinstance(value, float) and not math.isfinite(value):
        _fail(source, path, f"must be a finite number, got {value}")
    if isinstance(value, int) and abs(value) > 1e300:  # float() of it would overflow
        _fail(source, path, "must be a finite number, got an integer beyond float range")


def _show(value: Any) -> str:
    text = repr(value) if not isinstance(value, dict | list) else type(value).__name__
    return text if len(text) <= 40 else text[:37] + "..."


def _fail(source: str, path: str, message: str) -> None:
    raise InputError(f"{source}: key {path!r}: {message}")
