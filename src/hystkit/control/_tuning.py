"""PID re-tuning on the non-linear loop itself (beyond sec. 7.2's linear tuning).

The document tunes its PID on the linear plant. Here the gains are tuned on the loop as it
runs -- hysteretic sensor, compensator, ``S_m``, DOB -- by minimising the plant error of an
experiment over ``(log Kp, log Ti, log Td)`` with Nelder-Mead, from the current gains. Each
evaluation is one compiled run (a few ms for the 10 s sine), so a few hundred evaluations take
seconds. Each gain stays within a factor ``span`` (default 100) of its start: outside it the
search finds degenerate corners (``Kp -> 0`` with ``Td -> inf``, the same derivative gain
``Kp Td``) that say more about the objective's flat directions than about a better PID. The linearised loop's margins (:func:`~hystkit.control.loop_margins`) are the
constraints: a candidate that beats the best so far counts only if its phase and gain margins
reach the minimum and its linearised closed loop has no pole further out than the start's.
The result is never worse than the start: if nothing better and feasible is found, the start
is returned. These margins at rest are the only stability check during the search (sec. 12 of
docs/control.md shows a loop they call stable diverge). The costs are in-sample; the result also
carries the start's and the result's errors on experiments the search never saw (:data:`HELD_OUT`,
and with noise another seed).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import minimize

from ._analysis import loop_margins
from ._blocks import PID
from ._experiments import run_experiment
from ._loop import ControlLoop
from ._loop_margins import LoopMargins
from ._noise import NoiseSpec

__all__ = ["HELD_OUT", "OBJECTIVES", "TuneResult", "tune_nonlinear"]

OBJECTIVES = ("rms", "max")
"""Plant-error measures to minimise: ``e_p_rms`` or ``e_p_max`` (eq. 7.6, 7.8), the worst case
of the experiment."""

HELD_OUT = ("frequency", "amplitude")
"""Experiments the tuned gains are scored on besides the one they were tuned on (that one
itself is skipped; with noise the tuned experiment is re-run on the next seed as well)."""


@dataclass(frozen=True, eq=False)
class TuneResult:
    """Gains, costs and margins before and after :func:`tune_nonlinear`.

    Parameters
    ----------
    pid_start, pid : PID
        Start and result (``pid is pid_start`` when nothing better was found).
    objective : {"rms", "max"}
        The plant-error measure minimised.
    experiment : str
        The experiment whose cases were run.
    cost_start, cost : float
        Plant error [m] (``objective`` over the experiment's cases, the worst case).
    margins_start, margins : LoopMargins
        Margins of the linearised loop at rest with the start and the result.
    min_phase_margin : float
        Phase-margin constraint [deg].
    min_gain_margin_db : float
        Gain-margin constraint [dB].
    n_evaluations : int
        Simulations of the experiment.
    n_margin_checks : int
        Linearisations (only for candidates that beat the best so far).
    seconds : float
        Wall time of the search [s] (the held-out runs not included).
    improved : bool
        A better feasible PID was found.
    message : str
        The optimiser's message.
    held_out : tuple of dict
        Out-of-sample check: per case of each held-out experiment, ``experiment``, ``case``,
        ``seed`` (None without noise), the plant error ``before`` / ``after`` [m] (None for
        an unbounded run) and ``repeats_tuned_run`` (the case is the tuned run itself, e.g.
        the 0.5 Hz case of the frequency sweep after tuning on the sine). Never used by the
        search.
    """

    pid_start: PID
    pid: PID
    objective: str
    experiment: str
    cost_start: float
    cost: float
    margins_start: LoopMargins
    margins: LoopMargins
    min_phase_margin: float
    min_gain_margin_db: float
    n_evaluations: int
    n_margin_checks: int
    seconds: float
    improved: bool
    message: str
    held_out: tuple = ()

    def to_dict(self) -> dict:
        """The result as a JSON-safe dict (costs in m, ``ti = inf`` as None)."""

        def gains(p: PID) -> dict:
            return {"kp": p.kp, "ti": p.ti if np.isfinite(p.ti) else None, "td": p.td}

        return {"objective": self.objective, "experiment": self.experiment,
                "pid_start": gains(self.pid_start), "pid": gains(self.pid),
                "cost_start_m": self.cost_start, "cost_m": self.cost,
                "margins_start": self.margins_start.to_dict(),
                "margins": self.margins.to_dict(),
                "min_phase_margin_deg": self.min_phase_margin,
                "min_gain_margin_db": self.min_gain_margin_db,
                "n_evaluations": self.n_evaluations, "n_margin_checks": self.n_margin_checks,
                "seconds": self.seconds, "improved": self.improved, "message": self.message,
                "held_out": [dict(r) for r in self.held_out],
                "constraint": "linearised margins at rest only (no global stability check)"}


def _feasible(m: LoopMargins, limit: float, min_pm: float, min_gm: float) -> bool:
    return (m.max_pole_radius <= limit
            and (m.phase_margin_deg is not None and m.phase_margin_deg >= min_pm)
            and (m.gain_margin_db is None or m.gain_margin_db >= min_gm))


def _fmt(x: float | None, none: str) -> str:
    return none if x is None else f"{x:.3g}"


def _case_errors(loop: ControlLoop, experiment: str, key: str,
                 noise: NoiseSpec | None) -> dict[str, float | None]:
    """Plant error ``key`` [m] of each case of ``experiment``; None for an unbounded run."""
    result = run_experiment(experiment, loop, noise)
    return {label: (r.metrics()[key] if r.bounded else None)
            for label, r in result.cases.items()}


def _held_out(loop: ControlLoop, tuned: PID, experiment: str, key: str,
              noise: NoiseSpec | None, experiments: tuple[str, ...]) -> tuple[dict, ...]:
    """Before/after plant errors on experiments (and a noise seed) the search never saw."""
    runs = [(e, noise) for e in experiments if e != experiment]
    if noise is not None and not noise.silent:
        runs = [(experiment, replace(noise, seed=noise.seed + 1))] + [
            (e, replace(noise, seed=noise.seed + 1)) for e, _ in runs]
    rows = []
    for name, spec in runs:
        before = _case_errors(loop, name, key, spec)
        after = _case_errors(replace(loop, pid=tuned), name, key, spec)
        rows += [{"experiment": name, "case": label, "seed": None if spec is None else spec.seed,
                  "before": before[label], "after": after[label]} for label in before]
    return tuple(rows)


def tune_nonlinear(loop: ControlLoop, experiment: str = "sine", *, objective: str = "rms",
                   min_phase_margin: float = 30.0, min_gain_margin_db: float = 6.0,
                   noise: NoiseSpec | None = None, max_evaluations: int = 300,
                   span: float = 100.0,
                   held_out: tuple[str, ...] = HELD_OUT) -> TuneResult:
    """Minimise the plant error of ``experiment`` over the PID gains of ``loop``.

    Parameters
    ----------
    loop : ControlLoop
        Its PID is the start; ``Tf`` and anti-windup are kept. A PID without integral action
        (``Ti = inf``) is tuned over ``Kp`` and ``Td`` only.
    experiment : str
        One of :data:`~hystkit.control.EXPERIMENTS`; every case counts, the worst decides.
    objective : {"rms", "max"}
        ``e_p_rms`` or ``e_p_max`` [m]; an unbounded run costs infinity.
    min_phase_margin, min_gain_margin_db : float
        Constraints on the linearised loop at rest [deg, dB]; also no closed-loop pole
        further out than the start's (or the unit circle).
    noise : NoiseSpec, optional
        Tune with this (fixed-seed) noise in every run.
    max_evaluations : int
        Budget of simulations.
    span : float
        Each gain stays within ``[start / span, start * span]``.
    held_out : tuple of str, default :data:`HELD_OUT`
        Experiments to score the start and the result on afterwards (``experiment`` itself is
        skipped; ``()`` for none). With noise, on seed ``noise.seed + 1``, and the tuned
        experiment too.

    Returns
    -------
    TuneResult
        Best feasible gains found (the start if none beat it), costs and margins.

    Raises
    ------
    ValueError
        If `span` is not above 1, `objective` is unknown, or the start gains violate the
        constraints or leave the loop unbounded.
    """
    if not span > 1:
        raise ValueError(f"span must be > 1, got {span!r}")
    if objective not in OBJECTIVES:
        raise ValueError(f"objective must be one of {OBJECTIVES}, got {objective!r}")
    t_start = time.perf_counter()
    start = loop.pid
    key = "e_p_rms" if objective == "rms" else "e_p_max"
    counts = {"runs": 0, "checks": 0}

    def gains(x: np.ndarray) -> PID:
        ti = float(np.exp(x[1])) if np.isfinite(start.ti) else np.inf
        return replace(start, kp=float(np.copysign(np.exp(x[0]), start.kp)), ti=ti,
                       td=float(np.exp(x[-1])) if start.td > 0 else 0.0)

    def cost(pid: PID) -> float:
        counts["runs"] += 1
        result = run_experiment(experiment, replace(loop, pid=pid), noise)
        if not all(r.bounded for r in result.cases.values()):
            return np.inf
        return max(r.metrics()[key] for r in result.cases.values())

    margins_start = loop_margins(loop)
    limit = max(1.0, margins_start.max_pole_radius) + 1e-12
    if not _feasible(margins_start, limit, min_phase_margin, min_gain_margin_db):
        raise ValueError(f"the start gains break the constraints (phase margin "
                         f"{_fmt(margins_start.phase_margin_deg, 'none')} deg, gain margin "
                         f"{_fmt(margins_start.gain_margin_db, 'inf')} dB; "
                         f"need >= {min_phase_margin:.3g} deg, >= {min_gain_margin_db:.3g} dB): "
                         f"lower the minimums or start elsewhere")
    cost_start = cost(start)
    if not np.isfinite(cost_start):
        raise ValueError(f"the start gains leave the {experiment} run unbounded")
    best = {"pid": start, "cost": cost_start, "margins": margins_start}

    def objective_of(x: np.ndarray) -> float:
        pid = gains(x)
        c = cost(pid)
        if not c < best["cost"]:
            # No better than the best: returned unchecked (a margin check per run would
            # double the cost). Nelder-Mead then sees an infeasible point as finite when worse
            # and inf when better; only checked, feasible points are ever kept as the result.
            return c
        counts["checks"] += 1
        m = loop_margins(replace(loop, pid=pid))
        if not _feasible(m, limit, min_phase_margin, min_gain_margin_db):
            return np.inf
        best.update(pid=pid, cost=c, margins=m)
        return c

    x0 = [np.log(abs(start.kp))]
    if np.isfinite(start.ti):
        x0.append(np.log(start.ti))
    if start.td > 0:
        x0.append(np.log(start.td))
    x0 = np.array(x0)
    # first simplex: each gain 30 % up (log steps; Nelder-Mead's default 5 % is too timid)
    simplex = np.vstack([x0] + [x0 + 0.26 * np.eye(x0.size)[i] for i in range(x0.size)])
    box = [(x - np.log(span), x + np.log(span)) for x in x0]
    res = minimize(objective_of, x0, method="Nelder-Mead", bounds=box,
                   options={"maxfev": max_evaluations, "initial_simplex": simplex,
                            "xatol": 1e-3, "fatol": 1e-9 * cost_start})
    improved = best["pid"] is not start
    seconds = time.perf_counter() - t_start
    seed = None if noise is None else noise.seed
    rows = tuple({**r, "repeats_tuned_run": (r["seed"] == seed and r["before"] == cost_start
                                            and r["after"] == best["cost"])}
                 for r in _held_out(loop, best["pid"], experiment, key, noise, tuple(held_out)))
    return TuneResult(start, best["pid"], objective, experiment, cost_start, best["cost"],
                      margins_start, best["margins"], min_phase_margin, min_gain_margin_db,
                      counts["runs"], counts["checks"], seconds, improved, str(res.message),
                      rows)
