"""What ``hystkit control`` and ``hystkit stability --control`` compute, as one call each:
:func:`run_control` (the loop set up, tuned on the non-linear loop when asked, its linearised
margins, the experiment, the noise study, the Bode data) and :func:`examine_loop` (its global
stability). The commands print and write the records they return.

python-control (0.6 s to import) loads only for what needs it: the margins of a loop not in the
disk cache, tuning, the noise study's DOB design, Bode data and the stability analysis; those
are looked up in the package (its lazy table) when asked for.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from .. import control as package
from ._blocks import DisturbanceObserver
from ._disk_cache import cached_loop_margins
from ._experiments import ExperimentResult, run_experiment
from ._loop_margins import LoopMargins
from ._noise import NoiseSpec
from ._setup import LoopError, LoopSetup, SetupResult, setup_loop

__all__ = ["ControlRun", "LoopStudy", "Tuning", "examine_loop", "run_control"]


@dataclass(frozen=True)
class Tuning:
    """The options of :func:`~hystkit.control.tune_nonlinear` (its defaults).

    Parameters
    ----------
    objective : {"rms", "max"}, default "rms"
        ``e_p_rms`` or ``e_p_max`` is minimised.
    budget : int, default 300
        Budget of simulations (``max_evaluations``).
    min_phase_margin : float, default 30.0
        Phase margin the linearised loop keeps [deg].
    min_gain_margin : float, default 6.0
        Gain margin the linearised loop keeps [dB].
    """

    objective: str = "rms"
    budget: int = 300
    min_phase_margin: float = 30.0
    min_gain_margin: float = 6.0


@dataclass(frozen=True, eq=False)
class ControlRun:
    """One ``hystkit control`` run.

    Parameters
    ----------
    setup : SetupResult
        The loop as set up (before a non-linear tuning), its models and their seconds.
    loop : ControlLoop
        The loop that ran (with the tuned PID when tuned).
    tuned : TuneResult or None
    margins : LoopMargins
        The final loop's, linearised at rest.
    result : ExperimentResult or None
    noise_study : dict or None
        ``{"dob_f_q", "noise", "rows"}`` (:func:`~hystkit.control.noise_study`'s rows).
    noise_dob : DisturbanceObserver or None
        The DOB of the noise study.
    bode : tuple of arrays or None
        ``(f, magnitude_db, phase_deg)`` of the open loop.
    """

    setup: SetupResult
    loop: Any
    tuned: Any
    margins: LoopMargins
    result: ExperimentResult | None
    noise_study: dict | None
    noise_dob: DisturbanceObserver | None
    bode: tuple[np.ndarray, np.ndarray, np.ndarray] | None


def run_control(setup: LoopSetup, *, experiment: str | None = None,
                noise: NoiseSpec | None = None, tuning: Tuning | None = None,
                bode: bool = False) -> ControlRun:
    """Set up the loop and run what ``hystkit control`` runs on it.

    Parameters
    ----------
    setup : LoopSetup
    experiment : str, optional
        One of :data:`~hystkit.control.EXPERIMENTS`; None: the linear analysis only.
    noise : NoiseSpec, optional
        Noise in the experiment; also runs the noise study (without and with the noise, each
        without and with the DOB: the loop's own, else :func:`~hystkit.control.design_dob`'s).
    tuning : Tuning, optional
        Re-tune the PID on the non-linear loop (:func:`~hystkit.control.tune_nonlinear`) on
        `experiment` first.
    bode : bool, default False
        Also compute the open loop's Bode data.

    Returns
    -------
    ControlRun

    Raises
    ------
    LoopError
        ``part`` ``sensor``, ``compensator``, ``model`` or ``loop`` (see
        :func:`~hystkit.control.setup_loop`), ``tuning`` (the tuning refused its options) or
        ``noise`` (no DOB for the noise study).
    """
    made = setup_loop(setup)
    loop, tuned = made.loop, None
    if tuning is not None:
        try:
            tuned = package.tune_nonlinear(
                loop, experiment, objective=tuning.objective,
                min_phase_margin=tuning.min_phase_margin,
                min_gain_margin_db=tuning.min_gain_margin, noise=noise,
                max_evaluations=tuning.budget)
        except ValueError as exc:
            raise LoopError("tuning", str(exc)) from None
        loop = replace(loop, pid=tuned.pid)
    margins = cached_loop_margins(loop)  # python-control loads only when not stored
    result = run_experiment(experiment, loop, noise) if experiment else None
    study = dob = None
    if result is not None and noise is not None:
        try:
            dob = loop.dob or package.design_dob(loop)
        except ValueError as exc:
            raise LoopError("noise", str(exc)) from None
        study = {"dob_f_q": dob.f_q, "noise": noise.to_dict(),
                 "rows": package.noise_study(experiment, loop, noise, dob)}
    return ControlRun(made, loop, tuned, margins, result, study, dob,
                      package.bode_data(loop) if bode else None)


@dataclass(frozen=True, eq=False)
class LoopStudy:
    """``hystkit stability --control``: the loop, its global stability and its margins.

    Parameters
    ----------
    setup : SetupResult
        The loop as set up, its models and their seconds.
    report : StabilityReport
        Its global stability (:func:`~hystkit.control.global_stability`).
    margins : LoopMargins
        The linearised loop's margins.
    """

    setup: SetupResult
    report: Any
    margins: LoopMargins


def examine_loop(setup: LoopSetup, experiment: str = "sine") -> LoopStudy:
    """Set up the loop and examine its stability beyond the linearisation.

    Parameters
    ----------
    setup : LoopSetup
    experiment : str, default "sine"
        The experiment simulated (its closed-loop slopes join the sector tested).

    Returns
    -------
    LoopStudy

    Raises
    ------
    LoopError
        As :func:`~hystkit.control.setup_loop`.
    """
    made = setup_loop(setup)
    return LoopStudy(made, package.global_stability(made.loop, experiment),
                     cached_loop_margins(made.loop))
