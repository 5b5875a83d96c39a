"""Closed-loop verdicts from the state matrix: the rounding of an eigenvalue on the unit circle
is not instability (issue 11: the direct loop was reported 'UNSTABLE (max |pole|
1.0000000006)', growing e-fold in 9 days, while every run stayed bounded)."""

from __future__ import annotations

import numpy as np
import pytest

from hystkit.control import classify_poles


def test_a_double_integrator_is_marginal_not_unstable():
    # a 2x2 Jordan block at z = 1, rounded as computed eigenvalues are: 1 +- 1e-8
    a = np.array([[1.0, 1.0], [1e-16, 1.0]])
    assert np.abs(np.linalg.eigvals(a)).max() > 1 + 1e-9  # what used to read as growth
    growth, stable, marginal, radius = classify_poles(np.block([[a, np.zeros((2, 1))],
                                                                [np.zeros((1, 2)), 0.5]]))
    assert (growth, stable, marginal) == (1.0, False, True) and radius > 1


def test_a_simple_pole_on_the_circle_is_marginal():
    assert classify_poles(np.diag([1.0, 0.9, -0.3]))[:3] == (1.0, False, True)


def test_poles_inside_are_stable():
    rot = 0.7 * np.array([[np.cos(1.0), -np.sin(1.0)], [np.sin(1.0), np.cos(1.0)]])
    a = np.block([[rot, np.zeros((2, 1))], [np.zeros((1, 2)), 0.999]])
    assert classify_poles(a)[:3] == (1.0, True, False)


def test_slow_close_stable_poles_stay_stable():
    # three slow, distinct poles within 2e-5 of each other (a loop sampled fast)
    assert classify_poles(np.diag([0.99999, 0.999995, 0.99998]))[:3] == (1.0, True, False)


@pytest.mark.parametrize("outside", [1.0 + 1e-9, 1.001, -1.5])
def test_a_well_conditioned_pole_outside_is_growth(outside):
    growth, stable, marginal, radius = classify_poles(np.diag([outside, 0.2, 1.0]))
    assert growth == abs(outside) == radius and not stable and not marginal


def test_a_double_pole_clearly_outside_still_grows():
    growth, stable, marginal, _ = classify_poles(np.array([[1.01, 1.0], [0.0, 1.01]]))
    assert growth == pytest.approx(1.01) and not stable and not marginal


def test_an_empty_system_is_stable():
    assert classify_poles(np.zeros((0, 0))) == (1.0, True, False, 0.0)


def test_a_pole_that_grows_over_days_is_said_plainly():
    """The default 3-cell mPL's slowest cell integrates over its 200 s record; in the ch. 7
    loop it leaves a pole at 1.0000000006 (e-fold in 9.4 days), which control printed as
    'closed loop UNSTABLE' beside runs that stay bounded (issue 27.8)."""
    from types import SimpleNamespace

    from hystkit.cli._control_report import closed_loop

    slow = SimpleNamespace(closed_loop_stable=False, marginal=False,
                           max_pole_radius=1.0000000006, growth_time_s=8.1e5,
                           cause="its slowest cell overturns the static gain")
    text = closed_loop(slow)
    assert text.startswith("unstable only over days") and "UNSTABLE" not in text
    assert "a factor 1.0004 over a 5-minute run" in text and "slowest cell" in text
    fast = SimpleNamespace(**{**vars(slow), "growth_time_s": 0.04, "max_pole_radius": 1.0126})
    assert closed_loop(fast).startswith("UNSTABLE (max |pole| 1.0126000000: grows e-fold in")
