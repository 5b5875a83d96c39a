"""Everything numeric an exported compensator needs, gathered once for every target language.

A :class:`ExportPlan` holds the model's compiled-block ``body`` (the flat float64 parameters
``Family.block`` gives the closed loop, so a translation reads the same numbers at the same
indices as the family's numba kernel), the centring, polarity and scaling constants of
:meth:`Compensator.estimate`, the use-time guard ranges, the prediction band's constants (the
same for every family: :mod:`hystkit.compensation._band`), the optional synchronised start
state and the provenance written into the generated files' comments. The C and MATLAB writers
only format it.
"""

from __future__ import annotations

import json
import keyword
import math
import re
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

from .. import __version__
from ..compensation import MAX_NORMALISED, POSITION_MARGIN, SENSOR_MARGIN, Compensator
from ..errors import InputError
from ..models import Translation, get_family
from ..signals import exponential_chirp

__all__ = ["C_KEYWORDS", "FLOAT_SENSITIVITY_LIMIT", "ExportPlan", "band_constants",
           "float_sensitivity", "identifier", "make_plan"]

# Largest change of the model's output, relative to its range, when its input is rounded to
# float (1e-7 relative) for which a float export is offered without a warning: a tenth of the
# issue's 1e-4 float tolerance, the rest being left for the float arithmetic itself.
FLOAT_SENSITIVITY_LIMIT = 1e-5

C_KEYWORDS = frozenset(
    ["auto", "break", "case", "char", "const", "continue", "default", "do", "double", "else", "enum", "extern", "float", "for", "goto", "if", "inline", "int", "long", "register", "restrict", "return", "short", "signed", "sizeof", "static", "struct", "switch", "typedef", "union", "unsigned", "void", "volatile", "while", "main"])
# Names the MATLAB/Octave side would shadow: functions a generated file calls and the
# subfunctions every export defines (a family's own are its Translation.m_functions).
_MATLAB_TAKEN = frozenset([
    "abs", "sinh", "cosh", "exp", "log", "tanh", "asinh", "max", "min", "fix", "round", "sum",
    "zeros", "ones", "numel", "isempty", "isfinite", "struct", "end", "any", "cumsum", "reshape",
    "body", "normalised", "model_step", "model_rest", "model_load", "band_half",
    # NAME_step of the C side would clash with its static model_step
    "model"])
# Fit-date keys a model file's ``fit`` section may carry (none is written by hystkit yet).
_DATE_KEYS = ("fit_date", "fitted_at", "date", "created")


@dataclass(frozen=True, eq=False)
class ExportPlan:
    """The numbers of one compensator, ready to be written as code.

    Parameters
    ----------
    name : str
        Identifier the generated functions are named after (C and MATLAB safe).
    model, mode, center : str
        Family name, ``direct`` / ``inverse``, centring mode (``fit``, ``tare``, ``track``,
        ``none``).
    body : array
        The family block's flat float64 parameters (``Family.block(..., inverse)``).
    n_block_state : int
        Length of the family block's state; the translation may keep more (``n_state``).
    constants : dict
        Centring, polarity, scaling and guard constants (see :func:`make_plan`).
    extra : dict
        Family-specific arrays and numbers the translation needs beyond ``body``.
    sync_state : array or None
        Model state after the synchronisation excitation, when it is known.
    provenance : dict
        Strings for the generated comments: family title, structure, source, fit date, version.
    float_sensitivity : float
        Change of the model's output, relative to its range, when run in float32 (see
        :func:`float_sensitivity`).
    sync_note : str
        What the sync start-up is, or why there is none.
    band : dict or None
        The prediction band's constants at the exported level (see :func:`band_constants`);
        None: the compensator has no band, and the export has no band outputs.
    """

    name: str
    model: str
    mode: str
    center: str
    body: np.ndarray
    n_block_state: int
    constants: dict
    extra: dict = field(default_factory=dict)
    sync_state: np.ndarray | None = None
    provenance: dict = field(default_factory=dict)
    float_sensitivity: float = 0.0
    sync_note: str = ""
    band: dict | None = None

    @property
    def float_is_enough(self) -> bool:
        """Whether single precision can follow the model (see :func:`float_sensitivity`); also
        True when the probe could not run (NaN), which the generated README says."""
        return not self.float_sensitivity > FLOAT_SENSITIVITY_LIMIT

    @property
    def inverse(self) -> bool:
        return self.mode == "inverse"

    @property
    def translation(self) -> Translation:
        """The family's C and MATLAB translation (``Family.export``)."""
        return get_family(self.model).export

    @property
    def n_state(self) -> int:
        """Length of the translated model state (the block's, or more where a translation
        keeps derived values such as running sums)."""
        return self.translation.state_size(self)


def identifier(text: str, taken: tuple[str, ...] = ()) -> str:
    """A C and MATLAB identifier from a file name.

    Parameters
    ----------
    text : str
        A file name or any text.
    taken : tuple of str
        More names to avoid, in any case: the family's MATLAB subfunctions
        (``Translation.m_functions``).

    Returns
    -------
    str
        The letters (in their case: MATLAB finds ``bestA.m`` only as ``bestA`` on a
        case-sensitive file system), digits and ``_`` of `text` (at most 40 of them),
        starting with a letter (``m_`` is put in front otherwise); C and Python keywords,
        names the generated code calls and `taken` get a ``_model`` suffix.
    """
    name = re.sub(r"[^0-9A-Za-z_]+", "_", text).strip("_")[:40].strip("_")
    if not name or not name[0].isalpha():
        name = f"m_{name}".rstrip("_")
    if (name in C_KEYWORDS or name in _MATLAB_TAKEN or keyword.iskeyword(name)
            or name.lower() in {t.lower() for t in taken}):
        name = f"{name}_model"
    return name


def make_plan(comp: Compensator, name: str | None = None, *,
              sync_state: np.ndarray | None = None, sync_note: str = "",
              level: float | None = None) -> ExportPlan:
    """Gather what an exported ``comp`` needs; refuse (InputError) what cannot be exported.

    Parameters
    ----------
    comp : Compensator
        The fitted compensator.
    name : str, optional
        Identifier of the generated functions; by default from the model file's name (or the
        family's name when there is no file).
    sync_state : numpy.ndarray, optional
        Model state after the synchronisation excitation.
    sync_note : str
        What the sync start-up is, or why there is none.
    level : float, optional
        Nominal coverage of the exported band; default the band's own (``Band.level``).

    Returns
    -------
    ExportPlan
        The numbers to write.

    Raises
    ------
    InputError
        When the family or mode has no translation, the centring is the oracle, ``name``
        is not an identifier, or `level` is given for a compensator without a band (or is
        not a probability); the message gives the reason on one line.
    """
    source = comp.source or "<memory>"
    if comp.center == "recording":
        raise InputError(f"{source}: centring 'recording' is an oracle (it removes the whole "
                         f"recording's mean, unknown while the sensor is in use) and cannot run "
                         f"sample by sample; refit with --center fit, tare or track")
    refusal = comp.family.export_refusal(comp.mode == "inverse")
    if refusal:
        raise InputError(f"{source}: cannot export the {comp.model} {comp.mode} compensator: "
                         f"{refusal}")
    trans = comp.family.export
    if name is None:
        name = identifier(Path(source).stem if comp.source else comp.model, trans.m_functions)
    elif identifier(name, trans.m_functions) != name:
        raise InputError(f"--name {name!r}: not usable as a C/MATLAB identifier (letters, "
                         f"digits and _, starting with a letter, not a keyword); e.g. "
                         f"{identifier(name, trans.m_functions)!r}")
    band = band_constants(comp, level)
    block = comp.family.block(comp.structure, comp.params, comp.mode == "inverse")
    return ExportPlan(
        name=name, model=comp.model, mode=comp.mode, center=comp.center,
        body=np.array(block.body, dtype=np.float64), n_block_state=int(block.n_state),
        constants=_constants(comp),
        extra=trans.extra(comp),
        sync_state=None if sync_state is None else np.asarray(sync_state, dtype=float),
        provenance=_provenance(comp, band), float_sensitivity=float_sensitivity(comp),
        sync_note=sync_note, band=band)


def band_constants(comp: Compensator, level: float | None = None) -> dict[str, float] | None:
    """The prediction band of ``comp`` as numbers (names as in the C code), or None.

    The generated per-sample recursion is ``_band._features_kernel`` and the half-width
    ``_band.half_width``, in the same order of operations; the constants the Python side
    derives from the model file (``exp(-dt / tau)``, ``1 - decay``, ``1 - share``, the range
    widths) are computed here on the same doubles.

    Parameters
    ----------
    comp : Compensator
        The compensator.
    level : float, optional
        Nominal coverage; default the band's own.

    Returns
    -------
    dict or None
        ``LEVEL``, ``Q`` (the score quantile at the level [mm]), ``DT``, ``DECAY``, ``GAIN``,
        ``LOW``, ``HIGH``, ``WIDTH`` (the normalised training range), ``BASE``, ``SHARE``,
        ``RATE_REFERENCE``, ``RATE_HIGH`` and ``POSITION_WIDTH`` [mm]; None without a band.

    Raises
    ------
    InputError
        `level` given for a compensator without a band, `level` not strictly between 0 and
        1, or a band without the training ranges it is measured against.
    """
    source = comp.source or "<memory>"
    band = comp.band
    if band is None:
        if level is not None:
            raise InputError(f"--level: {source} has no prediction band (fitted without one "
                             f"or by a hystkit before bands); fit it again for a band")
        return None
    if comp.training_range is None or comp.position_range is None:
        raise InputError(f"{source}: the prediction band needs the training ranges, which the "
                         f"model file does not give; fit it again")
    try:
        q = band.quantile(level)
    except ValueError as exc:
        raise InputError(f"--level: {exc}") from None
    dt = float(comp.structure.dt)
    decay = math.exp(-dt / band.tau)
    low, high = comp.training_range
    high = high if high > low else low + 1.0  # as band_features: a range of one value
    p_lo, p_hi = comp.position_range
    return {"LEVEL": float(band.level if level is None else level), "Q": float(q), "DT": dt,
            "DECAY": decay, "GAIN": 1.0 - decay, "LOW": float(low), "HIGH": float(high),
            "WIDTH": float(high - low), "BASE": 1.0 - band.rate_share,
            "SHARE": float(band.rate_share), "RATE_REFERENCE": float(band.rate_reference),
            "RATE_HIGH": float(band.rate_high), "POSITION_WIDTH": float(p_hi - p_lo)}


def float_sensitivity(comp: Compensator) -> float:
    """How far single precision takes the model from its double run, relative to its range.

    The model's compiled block runs on the document's probe chirp (0.1 -> 3 Hz over 100 s,
    unit amplitude in normalised units, as ``hystkit stability``) twice: in double, and with
    its parameters, input, state and output rounded to float32 at every sample (what a float
    export stores). A well-conditioned model moves by ~1e-7 of its range; one whose weights
    nearly cancel amplifies rounding by orders of magnitude, and then no float implementation
    can follow the double reference. ``inf`` when only the float run leaves the finite
    range; NaN when the double run does too (the model is unstable on the probe itself, so the
    probe says nothing).
    """
    t = np.arange(round(100.0 / comp.structure.dt)) * comp.structure.dt
    probe = exponential_chirp(t, amplitude=1.0)
    inverse = comp.mode == "inverse"
    block = comp.family.block(comp.structure, comp.params, inverse)
    rest = comp.family.rest_state(comp.structure, comp.params, float(probe[0]), inverse)
    runs = []
    for dtype in (np.float64, np.float32):
        body = block.body.astype(dtype).astype(np.float64)
        x = rest.astype(dtype).astype(np.float64)
        out = np.empty(probe.size)
        with np.errstate(all="ignore"):
            for k, u in enumerate(probe.astype(dtype).astype(np.float64)):
                xn = np.empty_like(x)
                out[k] = dtype(block.step(body, x, xn, 0, u))
                x = xn.astype(dtype).astype(np.float64)
        runs.append(out)
    if not np.all(np.isfinite(runs[0])):
        return float("nan")
    with np.errstate(all="ignore"):
        change = float(np.max(np.abs(runs[1] - runs[0])) / max(float(np.ptp(runs[0])), 1e-300))
    return change if np.isfinite(change) else float("inf")


def _constants(comp: Compensator) -> dict[str, float]:
    """The data path of :meth:`Compensator.estimate` as numbers (names as in the C code).

    ``TRACK_A`` / ``TRACK_A1`` are the coefficients of ``_centring.sensor_level``'s
    ``lfilter`` (``a`` and ``a - 1``), computed here so that the generated code repeats the
    same operations on the same doubles.
    """
    sc = comp.scaling
    dt = comp.structure.dt
    a = 1.0 - np.exp(-dt / comp.track_seconds)
    lo, hi = comp.training_range if comp.training_range is not None else (-np.inf, np.inf)
    pad = SENSOR_MARGIN * (hi - lo) if np.isfinite(hi - lo) else 0.0
    p_lo, p_hi = (comp.position_range if comp.position_range is not None
                  else (-np.inf, np.inf))
    p_pad = POSITION_MARGIN * (p_hi - p_lo) if np.isfinite(p_hi - p_lo) else 0.0
    none = comp.center == "none"
    return {
        "POLARITY": float(comp.polarity),
        "SENSOR_OFFSET": 0.0 if none else float(sc.sensor_offset),
        "SENSOR_SCALE": float(sc.sensor_scale),
        "SENSOR_REFERENCE": float(comp.sensor_reference),
        "POSITION_SCALE": float(sc.position_scale),
        "POSITION_OFFSET": 0.0 if none else float(sc.position_offset),
        "N_TARE": float(max(1, round(comp.tare_seconds / dt))),
        "TRACK_A": float(a),
        "TRACK_A1": float(a - 1.0),
        "SENSOR_LOW": float(lo - pad),
        "SENSOR_HIGH": float(hi + pad),
        "ESTIMATE_LOW": float(p_lo - p_pad),
        "ESTIMATE_HIGH": float(p_hi + p_pad),
        "MAX_NORMALISED": float(MAX_NORMALISED),
        "DT": float(dt),
    }


def _band_text(comp: Compensator, band: dict | None) -> str:
    if band is None:
        return ("none: the model file has no prediction band (fitted with --no-band, or by a "
                "hystkit before bands); no lower/upper outputs")
    return (f"prediction band at level {band['LEVEL']:g}, outputs lower/upper [mm] per sample "
            f"(calibrated at {comp.band.level:g} on {comp.band.protocol}, "
            f"{comp.band.n_calibration} held-out samples)")


def _provenance(comp: Compensator, band: dict | None = None) -> dict[str, str]:
    info = comp.fit_info or {}
    date = next((str(info[k]) for k in _DATE_KEYS if info.get(k)), None)
    if date is None:
        date = "not recorded in the model file"
        if comp.source and Path(comp.source).is_file():
            mtime = datetime.fromtimestamp(Path(comp.source).stat().st_mtime, UTC)
            date += f" (file last modified {mtime:%Y-%m-%d %H:%M} UTC)"
    return {
        "family": f"{comp.model}: {comp.family.title}",
        "mode": comp.mode,
        "center": comp.center,
        "structure": json.dumps(_plain(comp.structure.to_dict()), separators=(", ", ": ")),
        "source": comp.source or "<in memory, no model file>",
        "fit_date": date,
        "hystkit": __version__,
        "exported": f"{datetime.now(UTC):%Y-%m-%d %H:%M} UTC",
        "band": _band_text(comp, band),
    }


def _plain(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    return value
