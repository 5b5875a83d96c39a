"""``hystkit stream --adapt``: the adapting stream of the options, its lines one by one with
their references, and the summary of what it learnt (:mod:`hystkit.live._adaptive`,
:mod:`hystkit.live._refit`)."""

from __future__ import annotations

import math

from ..errors import FitDivergedError
from ..live import Adaptation, AdaptiveStream, Refit, RefittingStream
from ._stream_defaults import DEFAULT_REFIT_EVERY, DEFAULT_WINDOW
from ._stream_lines import Reading, Tally, reference_of
from ._stream_options import StreamOptions

__all__ = ["Learning", "adaptive_stream", "run_line"]


class Learning:
    """References used by an adapting stream and its a-priori errors at them [mm]; those it
    rejected as implausible or refused (out of the parameters' domain) are only counted."""

    def __init__(self) -> None:
        self.n = 0
        self.sum_sq = 0.0
        self.ignored = 0

    def add(self, estimate: float, reference: float,
            stream: AdaptiveStream | RefittingStream) -> None:
        ignored = stream.n_rejected + getattr(stream, "n_refused", 0)
        if ignored > self.ignored:  # this reference moved nothing
            self.ignored = ignored
            return
        self.n += 1
        self.sum_sq += (estimate - reference) ** 2

    def _ignored_text(self, stream: AdaptiveStream | RefittingStream) -> str:
        text = (f"; {stream.n_rejected} rejected as implausible (beyond the training "
                f"positions or too far from the estimate)")
        if hasattr(stream, "n_refused"):
            text += (f", {stream.n_refused} refused (the update would have left the "
                     f"parameters' domain)")
        return text

    def summary(self, stream: AdaptiveStream | RefittingStream, adapt: str,
                forgetting: float | None) -> str:
        if adapt == "full":
            refit = stream.refit
            head = (f"hystkit stream: adaptation (full, window {refit.window_seconds:g} s, "
                    f"refit every {refit.every} references): ")
        else:
            head = f"hystkit stream: adaptation ({adapt}, forgetting {forgetting:g}): "
        if not self.n and not self.ignored:
            return head + "no reference arrived; the estimates are the plain stream's"
        used = (f"{self.n} references used, rms error at them before learning from each "
                f"{(self.sum_sq / self.n) ** 0.5:.4g} mm" if self.n else "no reference used")
        used += self._ignored_text(stream)
        if adapt == "full":
            report = stream.report
            return (head + f"{used}; refits: {report.kept} kept, "
                    f"{report.refused} refused, {report.skipped} skipped (the window held "
                    f"too few references), {report.evaluations} model evaluations; now "
                    f"{stream.compensator.params.to_dict()}")
        values = ", ".join(f"{k} {v:.6g}" for k, v in stream.parameters.items())
        state = stream.state
        band = ("" if not state.n_band_checks else
                f"; band: {state.n_band_misses} of {state.n_band_checks} references outside it, "
                f"now x{math.exp(state.band_log_factor):.3g} its calibrated width")
        return head + f"{used}; now {values}{band}"


def run_line(stream: AdaptiveStream | RefittingStream, line: str, reading: Reading,
             tally: Tally, learning: Learning) -> str | None:
    """One input line through an adapting stream: its output line, or None."""
    parsed = reading.parsed(line, tally)
    if parsed is None:
        return None
    text, t, s = parsed
    problem = reading.step_problem(t, reading.previous, stream.compensator.structure.dt)
    if problem is not None:
        tally.add(problem, reading.line_no)
        if problem == "time not advancing":
            return None
    if (reference := reference_of(line, reading.columns)) is None:
        tally.add("reference not a number", reading.line_no)
        reference = math.nan
    try:
        result = stream.step_flagged(s, reference)
    except FitDivergedError:
        tally.add("estimate ran away", reading.line_no)
        return None
    if not math.isnan(reference):
        learning.add(result.estimate, reference, stream)
    reading.previous = t
    flags = (1 if result.sensor_outside else 0) + (2 if result.estimate_outside else 0)
    band = "" if result.lower is None else f",{result.lower!r},{result.upper!r}"
    return f"{text},{result.estimate!r},{flags}{band}\n"


def adaptive_stream(options: StreamOptions, comp, start) -> AdaptiveStream | RefittingStream:
    """The adapting stream ``--adapt`` and its options ask for."""
    if options.adapt == "full":
        refit = Refit(DEFAULT_WINDOW if options.window is None else options.window,
                      DEFAULT_REFIT_EVERY if options.refit_every is None
                      else options.refit_every)
        return RefittingStream(comp, refit, start, label=str(options.model))
    priors = {k: v for k, v in (("prior_gain", options.prior_gain),
                                ("prior_offset", options.prior_offset)) if v is not None}
    adaptation = Adaptation(options.adapt, options.forgetting, **priors)
    return AdaptiveStream(comp, adaptation, start, label=str(options.model), level=options.level)
