"""The records of online adaptation (:mod:`._adaptive`): how a stream adapts
(:class:`Adaptation`), what it remembers (:class:`AdaptiveState`) and which references it
believes (:class:`Plausible`), with the limits that bound them."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..compensation import Compensator
from ..errors import InputError
from ._rls import RlsState
from ._stream_state import StreamState

__all__ = ["ADAPT_PARAMETERS", "BAND_STEP", "MAX_BAND_FACTOR", "MAX_INNOVATION",
           "MAX_MULTIPLIER", "REFERENCE_MARGIN", "Adaptation", "AdaptiveState", "Plausible"]

ADAPT_PARAMETERS = ("gain", "weights")
# Relative error allowed between a model's output and its weighted cell outputs on the probe
# run: rounding of a sum of a few hundred terms, far below any non-linearity in the weights.
LINEARITY_TOLERANCE = 1e-9
# Plausible references, in extents of the training positions (their span; module docstring):
# a reference beyond the training positions widened by REFERENCE_MARGIN extents on each side, or
# further than MAX_INNOVATION extents from the estimate, is no drift but a wrong reference.
REFERENCE_MARGIN = 0.5
MAX_INNOVATION = 1.0
# The output parameters' domain: a gain moved by more than this factor (or a cell's weight
# multiplier beyond it in magnitude) is no drift but another sensor; fit again.
MAX_MULTIPLIER = 10.0
# Quantile tracking of the band: log m moves by BAND_STEP (1 - alpha) at a miss, by
# -BAND_STEP alpha at a hit (a miss widens the 90 % band by 20 %, nine hits narrow it back).
BAND_STEP = 0.2
MAX_BAND_FACTOR = 100.0


@dataclass(frozen=True)
class Adaptation:
    """How a stream adapts.

    Parameters
    ----------
    parameters : {"gain", "weights"}
        Which output parameters RLS re-fits (module docstring).
    forgetting : float
        Forgetting factor ``lambda`` in (0, 1], per reference sample: the estimate remembers
        about ``1 / (1 - lambda)`` references (1: never forgets).
    prior_gain : float
        Prior standard deviation of each multiplier (``a``, ``a_k``), relative (0.1: 10 %).
    prior_offset : float or None
        Prior standard deviation of the offset ``b`` [mm]; None: 10 % of the training
        positions' span (1 mm if the model file does not know it).
    reference_margin : float, default REFERENCE_MARGIN
        A reference [mm] beyond the training positions widened by this many extents of them
        on each side is rejected (:class:`Plausible`; ``inf``: no such check).
    max_innovation : float, default MAX_INNOVATION
        A reference further than this many extents of the training positions from the
        sample's estimate is rejected (``inf``: no such check).
    """

    parameters: str = "gain"
    forgetting: float = 0.9
    prior_gain: float = 0.1
    prior_offset: float | None = None
    reference_margin: float = REFERENCE_MARGIN
    max_innovation: float = MAX_INNOVATION

    def __post_init__(self) -> None:
        if self.parameters not in ADAPT_PARAMETERS:
            raise InputError(f"adaptation parameters {self.parameters!r}: use one of "
                             f"{', '.join(ADAPT_PARAMETERS)}")
        if not 0.0 < self.forgetting <= 1.0:
            raise InputError(f"forgetting factor {self.forgetting!r}: must be in (0, 1]")
        for name in ("prior_gain", "prior_offset"):
            value = getattr(self, name)
            if value is not None and not (0.0 < value < float("inf")):
                raise InputError(f"{name} {value!r}: must be a finite positive number")
        for name in ("reference_margin", "max_innovation"):
            if not getattr(self, name) > 0.0:  # inf allowed: no such check
                raise InputError(f"{name} {getattr(self, name)!r}: must be a positive number")


@dataclass(frozen=True, eq=False)
class AdaptiveState:
    """The plain stream's state and the RLS state of the output parameters.

    Parameters
    ----------
    stream : StreamState
        The plain (un-adapted) stream's state.
    rls : RlsState
        Estimate and covariance of the output parameters (multipliers, then the offset [mm]).
    n_rejected : int, default 0
        References rejected as implausible (:class:`Plausible`); they moved nothing.
    n_refused : int, default 0
        Plausible references whose update would have left the output parameters' domain;
        refused, they moved nothing either.
    band_log_factor : float, default 0.0
        ``log m`` of the band's multiplier (module docstring).
    n_band_misses : int, default 0
        Plausible references that fell outside their sample's band.
    n_band_checks : int, default 0
        Plausible references checked against their sample's band.
    """

    stream: StreamState
    rls: RlsState
    n_rejected: int = 0
    n_refused: int = 0
    band_log_factor: float = 0.0
    n_band_misses: int = 0
    n_band_checks: int = 0


@dataclass(frozen=True)
class Plausible:
    """Where a reference [mm] is believed: the training positions ``(low, high)`` widened by
    ``margin`` extents, and within ``innovation`` extents of the sample's estimate.

    Parameters
    ----------
    low, high : float
        The training positions [mm] (shifted by the centring's position offset in use).
    extent : float
        Their extent [mm] (> 0): the unit of the margins and of the offset's domain.
    margin : float, default REFERENCE_MARGIN
        Extents by which the range is widened on each side.
    innovation : float, default MAX_INNOVATION
        Largest distance from the estimate, in extents.
    """

    low: float
    high: float
    extent: float
    margin: float = REFERENCE_MARGIN
    innovation: float = MAX_INNOVATION

    @classmethod
    def of(cls, comp: Compensator, position_offset: float,
           adaptation: Any = None) -> Plausible:
        """The bounds of a compensator: its stored training positions, or (older files) the
        positions its scaling maps [-1, 1] to.

        Parameters
        ----------
        comp : Compensator
            The compensator.
        position_offset : float
            The position offset [mm] in use (the stream's; shifts the stored range as
            :meth:`Compensator.estimate_outside` does).
        adaptation : Adaptation or Refit, optional
            Its ``reference_margin`` and ``max_innovation`` (default: the module's).

        Returns
        -------
        Plausible
            Its bounds.
        """
        gates = (REFERENCE_MARGIN, MAX_INNOVATION) if adaptation is None else (
            adaptation.reference_margin, adaptation.max_innovation)
        scale = comp.scaling.position_scale
        if comp.position_range is None:
            return cls(position_offset - scale, position_offset + scale, 2.0 * scale, *gates)
        lo, hi = comp.position_range
        shift = position_offset - comp.scaling.position_offset
        return cls(lo + shift, hi + shift, (hi - lo) if hi > lo else scale, *gates)

    def why_not(self, reference: float, estimate: float) -> str | None:
        """None if `reference` [mm] is plausible at a sample estimated at `estimate` [mm],
        else why not.

        Parameters
        ----------
        reference, estimate : float
            The reference and the sample's estimate before learning from it [mm].

        Returns
        -------
        str or None
            ``"range"`` or ``"innovation"``, or None.
        """
        with np.errstate(invalid="ignore"):  # inf * 0 extents: no check
            pad = self.margin * self.extent
            if not self.low - pad <= reference <= self.high + pad:
                return "range"
            if not abs(reference - estimate) <= self.innovation * self.extent:
                return "innovation"
        return None


def reference_column(reference: np.ndarray | None, n: int, first: int, label: str) -> np.ndarray:
    """`reference` [mm] as one float per sensor sample of a chunk (all NaN, unknown, when None);
    InputError for another count or an infinite one (`first`: the chunk's first sample)."""
    if reference is None:
        return np.full(n, np.nan)
    r = np.asarray(reference, dtype=np.float64).reshape(-1)
    if r.size != n:
        raise InputError(f"{label}: {r.size} references for {n} sensor samples")
    bad = np.flatnonzero(np.isinf(r))
    if bad.size:
        raise InputError(f"{label}: sample {first + bad[0]}: reference is infinite "
                         f"(NaN marks an unknown one)")
    return r
