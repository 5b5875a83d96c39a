"""The linearised loop's verdict as a record (:func:`~hystkit.control.loop_margins` makes it):
kept apart from the analysis so that reading one (a plot, a stored result) loads no
python-control."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["LoopMargins"]


@dataclass(frozen=True)
class LoopMargins:
    """Crossover and stability margins of the linearised loop.

    Parameters
    ----------
    crossover_hz : float or None
        Gain-crossover frequency ``|L| = 1`` [Hz] (None if ``|L|`` never crosses 1).
    phase_margin_deg : float or None
        Phase margin at the crossover [deg]; None without a crossover.
    gain_margin_db : float or None
        Gain margin ``-20 log10 |L|`` [dB] at the phase crossing (``arg L = -180`` deg) that
        limits the gain from above (see :func:`loop_margins`; negative for an unstable loop
        whose gain is too high); None when no crossing limits it (infinite gain margin).
    phase_crossover_hz : float or None
        Phase-crossover frequency [Hz] at which the gain margin is read.
    closed_loop_stable : bool
        All poles of ``feedback(L, 1)`` strictly inside the unit circle.
    max_pole_radius : float
        Largest ``|pole|`` of the closed loop.
    growth_time_s : float or None
        For an unstable loop, the e-folding time ``Ts / ln max|pole|`` [s] of its fastest
        growing mode: a slow drift (hours) and a blow-up (milliseconds) both count as unstable.
        None when no pole lies outside the unit circle (beyond its rounding).
    cause : str or None
        For an unstable loop, a known cause in words (:func:`static_sign_flips`), else None.
    slow_cell : str or None
        For a loop whose growth is no faster than the slowest cell of its sensor and
        compensator blocks decays (``growth_time_s`` at least that cell's time constant: the
        pole lies outside the unit circle by no more than the cell's pole lies inside it), the
        block with that cell; the growing mode is a marginal one from a slow cell, see
        :func:`slow_cell_words`. None otherwise.
    slow_cell_s : float or None
        That cell's time constant [s]; None with `slow_cell`.
    marginal : bool
        No pole outside the unit circle and at least one on it (within the rounding of its
        eigenvalue, see :func:`classify_poles`): a state the linearised loop neither corrects
        nor amplifies, e.g. a friction element or a dead band of a sensor model that holds its
        state at rest, or a double integrator.
    """

    crossover_hz: float | None
    phase_margin_deg: float | None
    gain_margin_db: float | None
    phase_crossover_hz: float | None
    closed_loop_stable: bool
    max_pole_radius: float
    growth_time_s: float | None = None
    marginal: bool = False
    cause: str | None = None
    slow_cell: str | None = None
    slow_cell_s: float | None = None

    def to_dict(self) -> dict:
        """The fields as a dict (JSON-safe: floats, bools and None)."""
        return dict(vars(self))
