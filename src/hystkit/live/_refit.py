"""Online adaptation of the whole model: re-fit every parameter on a sliding window of the
stream, from occasional reference positions (paper 9.1's proposal, its "full" variant).

:mod:`._adaptive` re-fits only the output's linear parameters, by recursive least squares;
a sensor whose dynamics change (a cell's time constant, its non-linearity) needs the cell
parameters re-fitted too. Here the stream keeps its last ``window_seconds`` of model input (the
normalised sensor, computed exactly as the plain stream computes it) and the references that
arrived in that time; after every ``every`` new references it fits the family on the window
with per-sample weights 1 at the references and 0 elsewhere (so only the known positions count,
while the model runs through every sample), from one start, the present parameters, on a small
evaluation budget. Only families whose fit can start from given parameters take part (mpl,
mpl-poly, mpl-g: ``Family.start_options``); the others would re-run their whole multi-start at
every refit, which no sample period allows.

- The refit starts the model at rest at the window's first sample, as every fit does; the
  new parameters' state at the window's end (the same run) continues the stream. A window
  several times the model's slowest time constant makes that start immaterial.
- A refit is kept only if its fit succeeded and it lowers the weighted error on the window
  against the present parameters run the same way; otherwise the stream goes on with the
  present parameters and counts the refusal.
- As in :mod:`._adaptive`, a reference is checked for plausibility (range and innovation,
  :class:`~._adaptive_records.Plausible`) before it enters the window; a rejected one is counted
  (``RefitReport.rejected``) and never fitted (one reference of 1e200 mm ended the stream with
  an OverflowError). It still counts towards ``every``, so the refits stay at fixed references.
- As in :mod:`._adaptive`, a sample's estimate is made before its reference is learnt: the
  error at each reference is an honest prediction error. Refits happen after fixed sample
  indices (the n-th reference), so a chunked run gives the bits of the whole run.

Direct compensators only: an inverse compensator's fitted model maps position to sensor, and
the position is known only at the references. A window too short to ever hold enough
references is refused when the stream is made.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..compensation import Compensator
from ..errors import FitDivergedError, InputError
from ..models import FAMILIES
from ._adaptive_records import MAX_INNOVATION, REFERENCE_MARGIN, Plausible, reference_column
from ._readable import StartUp, _advance, _Path, advance_scaled, initial_state
from ._stream_output import StepOutput, StreamOutput
from ._stream_state import StreamState

__all__ = ["Refit", "RefitReport", "RefittingStream"]


@dataclass(frozen=True)
class Refit:
    """When and how a :class:`RefittingStream` re-fits its model.

    Parameters
    ----------
    window_seconds : float
        Length of the sliding window [s] the model is re-fitted on.
    every : int
        Re-fit after this many new references.
    min_references : int or None
        References the window must hold before a refit; None: four per fitted parameter.
    max_nfev : int
        Evaluation budget of each refit's polish (after the fit's short screening run of its
        one start, the present parameters; ``screen_nfev`` of the family's fit, 12); a polish
        that stops on it is continued once with as much again, to tell a flat minimum from a
        failure (:func:`hystkit.identification.fit_multistart`).
    reference_margin, max_innovation : float
        The plausibility gates of a reference, as :class:`~._adaptive_records.Adaptation`.
    """

    window_seconds: float = 60.0
    every: int = 10
    min_references: int | None = None
    max_nfev: int = 50
    reference_margin: float = REFERENCE_MARGIN
    max_innovation: float = MAX_INNOVATION

    def __post_init__(self) -> None:
        if not 0.0 < self.window_seconds < float("inf"):
            raise InputError(f"refit window {self.window_seconds!r} s: must be a finite "
                             f"positive number")
        for name in ("every", "max_nfev"):
            if int(getattr(self, name)) != getattr(self, name) or getattr(self, name) < 1:
                raise InputError(f"refit {name} {getattr(self, name)!r}: must be a positive "
                                 f"integer")
        if self.min_references is not None and self.min_references < 1:
            raise InputError(f"refit min_references {self.min_references!r}: must be >= 1")
        for name in ("reference_margin", "max_innovation"):
            if not getattr(self, name) > 0.0:  # inf allowed: no such check
                raise InputError(f"refit {name} {getattr(self, name)!r}: must be a positive "
                                 f"number")


@dataclass(frozen=True)
class RefitReport:
    """What the refits did so far.

    Parameters
    ----------
    references : int
        References received.
    rejected : int
        Of them, rejected as implausible (out of range, or too far from the estimate); they
        never entered the window.
    kept, refused : int
        Refits whose parameters the stream took, and those it did not (a failed fit, or no
        improvement on the window).
    skipped : int
        Refits that were due but not tried: the window held fewer references than a refit
        needs (at the start of a stream, or after a gap in the references).
    evaluations : int
        Model evaluations of all refits together (their fits' ``n_evaluations``).
    last_cost_before, last_cost_after : float or None
        Weighted SSE (normalised units) on the window of the last kept refit, with the
        parameters before and after it.
    """

    references: int = 0
    rejected: int = 0
    kept: int = 0
    refused: int = 0
    skipped: int = 0
    evaluations: int = 0
    last_cost_before: float | None = None
    last_cost_after: float | None = None


class RefittingStream:
    """A stream that re-fits its whole model on a sliding window of references.

    Parameters
    ----------
    compensator : Compensator
        A deployable direct compensator (centring fit, tare, track or none).
    refit : Refit, optional
        Window and cadence (default :class:`Refit`).
    start, rest_position, label
        As :class:`~._stream.Stream`.

    Raises
    ------
    InputError
        For an inverse compensator, an oracle-centred one, a family whose fit cannot start
        from given parameters, or a window too short to hold the references a refit needs.
    """

    def __init__(self, compensator: Compensator, refit: Refit | None = None,
                 start: StartUp = "rest", *, rest_position: float | None = None,
                 label: str = "stream") -> None:
        if compensator.mode != "direct":
            raise InputError(f"{compensator.source or 'compensator'}: adaptation 'full': an "
                             f"inverse compensator's model maps position to sensor, known "
                             f"only at the references; use a direct one, or 'gain'")
        family = compensator.family
        where = f"{compensator.source or 'compensator'}: adaptation 'full'"
        if not family.capabilities.start_from_params:
            starts = sorted(name for name, f in FAMILIES.items()
                            if f.capabilities.start_from_params)
            raise InputError(f"{where}: the {family.name} fit cannot start from the present "
                             f"parameters (it would re-run its whole multi-start at every "
                             f"refit); it applies to {', '.join(starts)}; use 'gain'")
        self.refit = refit or Refit()
        self.label = label
        self._rest_position = rest_position
        self._path = _Path(compensator, rest_position)
        self._state: StreamState = initial_state(compensator, start)
        n = max(1, round(self.refit.window_seconds / compensator.structure.dt))
        n_params = family.n_params(compensator.structure, compensator.params)
        self._min_refs = self.refit.min_references or 4 * n_params
        if n < self._min_refs:
            raise InputError(f"{where}: a {self.refit.window_seconds:g} s window holds {n} "
                             f"samples, fewer than the {self._min_refs} references a refit "
                             f"needs (4 per parameter); make --window longer")
        self._s = np.full(n, np.nan)  # ring buffers of the window, oldest first once full
        self._p = np.full(n, np.nan)
        self._filled = 0
        self._since = 0
        self._report = RefitReport()
        self._options = {"max_nfev": self.refit.max_nfev}
        self._warm_up()

    def _warm_up(self) -> None:
        """Load the fit's code and compiled kernels now, not inside the first refit of a
        live stream (where they stalled one sample by ~0.7 s): a weighted fit of one
        evaluation on a short probe, whose result is not used."""
        comp = self._path.comp
        probe = 0.5 * np.sin(np.linspace(0.0, 4.0 * np.pi, 64))
        options = comp.family.start_options(comp.structure, comp.params).options
        try:
            comp.family.fit(probe, probe, comp.structure, weights=np.ones(probe.size),
                            max_nfev=1, screen_nfev=1, **options)
        except (FitDivergedError, InputError, ValueError, ArithmeticError,
                np.linalg.LinAlgError):
            pass  # a probe the family cannot fit still loaded its code

    @property
    def compensator(self) -> Compensator:
        """The compensator with the present parameters."""
        return self._path.comp

    @property
    def report(self) -> RefitReport:
        """What the refits did so far (:class:`RefitReport`)."""
        return self._report

    @property
    def n_rejected(self) -> int:
        """References rejected as implausible so far (``report.rejected``)."""
        return self._report.rejected

    @property
    def state(self) -> StreamState:
        """The plain stream's present state, with the present parameters' model state."""
        return self._state

    def step(self, sensor: float, reference: float = float("nan")) -> float:
        """Estimate [mm] for one raw sensor sample; then learn from ``reference`` if known."""
        return self.step_flagged(sensor, reference).estimate

    def step_flagged(self, sensor: float, reference: float = float("nan")) -> StepOutput:
        """Estimate and use-time flags for one raw sensor sample (the bits of
        :meth:`process`); then learn from ``reference`` [mm] if known."""
        out = self.process_flagged(np.array([sensor], dtype=np.float64),
                                   np.array([reference], dtype=np.float64))
        return StepOutput(float(out.estimate[0]),
                          *(None if flag is None else bool(flag[0]) for flag in out[1:]))

    def process(self, sensor: np.ndarray, reference: np.ndarray | None = None) -> np.ndarray:
        """Estimates [mm] for a chunk; ``reference`` [mm] per sample, NaN where unknown."""
        return self.process_flagged(sensor, reference).estimate

    def process_flagged(self, sensor: np.ndarray,
                        reference: np.ndarray | None = None) -> StreamOutput:
        """Estimates and use-time flags for a chunk; refits at the references that
        complete an ``every``."""
        s_raw = np.ascontiguousarray(sensor, dtype=np.float64).reshape(-1)
        r = reference_column(reference, s_raw.size, self._state.n_samples, self.label)
        if s_raw.size == 0:
            return _advance(self._path, self._state, s_raw, self.label)[0]
        # split after each reference that completes an `every`: the refit happens there
        known = np.flatnonzero(np.isfinite(r))
        due = self.refit.every - self._since
        cuts = set((known[due - 1::self.refit.every] + 1).tolist()) if known.size >= due else set()
        parts, begin = [], 0
        for end in sorted(cuts | {s_raw.size}):
            parts.append(self._advance(s_raw[begin:end], r[begin:end]))
            if end in cuts:
                self._refit()
            begin = end
        return StreamOutput(*(None if parts[0][k] is None else np.concatenate(
            [part[k] for part in parts]) for k in range(3)))

    def _advance(self, s_raw: np.ndarray, r: np.ndarray) -> StreamOutput:
        """The plain stream over one part, and the window's buffers updated."""
        path, state = self._path, self._state
        comp = path.comp
        out, self._state, s = advance_scaled(path, state, s_raw, self.label)
        known = np.flatnonzero(np.isfinite(r))
        plausible = Plausible.of(comp, path.position_offset, self.refit)
        rejected = [i for i in known if plausible.why_not(r[i], out.estimate[i]) is not None]
        r = r.copy()
        r[rejected] = np.nan  # before it moves anything: never in the window
        p = (r - path.position_offset) / comp.scaling.position_scale
        self._push(s, p)
        self._since += known.size
        self._report = dataclasses.replace(
            self._report, references=self._report.references + known.size,
            rejected=self._report.rejected + len(rejected))
        return out

    def _push(self, s: np.ndarray, p: np.ndarray) -> None:
        n = self._s.size
        if s.size >= n:
            self._s[:], self._p[:] = s[-n:], p[-n:]
        else:
            self._s[:n - s.size], self._p[:n - s.size] = self._s[s.size:], self._p[s.size:]
            self._s[n - s.size:], self._p[n - s.size:] = s, p
        self._filled = min(n, self._filled + s.size)

    def _refit(self) -> None:
        """Fit on the window from the present parameters; keep the result if it is better."""
        self._since = 0
        s = self._s[self._s.size - self._filled:]
        p = self._p[self._p.size - self._filled:]
        weights = np.isfinite(p).astype(float)
        if weights.sum() < self._min_refs:
            self._report = dataclasses.replace(self._report, skipped=self._report.skipped + 1)
            return
        comp = self._path.comp
        family, structure = comp.family, comp.structure
        target = np.where(np.isfinite(p), p, 0.0)
        options = family.start_options(structure, comp.params).options
        before = _window_cost(family, structure, comp.params, s, target, weights)
        try:
            result = family.fit(s, target, structure, weights=weights, **self._options,
                                **options)
            after = _window_cost(family, structure, result.params, s, target, weights)
        except (FitDivergedError, ValueError, ArithmeticError, np.linalg.LinAlgError):
            self._refused()
            return
        self._report = dataclasses.replace(
            self._report, evaluations=self._report.evaluations + result.n_evaluations)
        if not (np.isfinite(after) and after < before):
            self._refused()
            return
        new = dataclasses.replace(comp, params=result.params)
        _, x_end = family.simulate(structure, result.params, s)
        self._path = _Path(new, self._rest_position)
        self._state = dataclasses.replace(self._state, x=x_end)
        self._report = dataclasses.replace(self._report, kept=self._report.kept + 1,
                                           last_cost_before=before, last_cost_after=after)

    def _refused(self) -> None:
        self._report = dataclasses.replace(self._report, refused=self._report.refused + 1)


def _window_cost(family, structure, params, s: np.ndarray, target: np.ndarray,
                 weights: np.ndarray) -> float:
    """Weighted SSE of ``params`` run from rest at the window's start (as the refit runs)."""
    with np.errstate(over="ignore", invalid="ignore"):
        try:
            y, _ = family.simulate(structure, params, s)
        except FitDivergedError:
            return float("inf")
    r = y - target
    return float(np.sum(weights * r * r))
