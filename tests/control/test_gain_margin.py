"""Gain margin of the linear loop against an independent computation (issue 25 item 1).

The loop with the ideal sensor and the exact compensator is ``C(z) P(z)`` in both schemes
(eq. 7.2 PID, ZOH of ``1 / (m s^2)``). Its gain margin is computed here twice without
:mod:`hystkit.control`'s analysis: from the frequency response written out by hand (``-20 log10
|C P|`` where ``arg C P = -180`` deg), and as the factor on ``Kp`` at which a root of the
closed loop's characteristic polynomial ``den_C den_P + num_C num_P`` leaves the unit circle
(bisection).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.optimize import brentq

from hystkit import control as hc

TS = hc.TS
PIDS = {"direct": hc.DOCUMENT_PID_DIRECT, "weighting": hc.DOCUMENT_PID_WEIGHTING}


def _linear(scheme: str, pid: hc.PID) -> hc.ControlLoop:
    return hc.ControlLoop(scheme, hc.linear_block(40.0, name="ideal sensor"), pid,
                          compensator=hc.linear_block(1 / 40.0, name="exact compensator"),
                          model=hc.linear_block(40.0, name="model"), sensor_gain=1 / 40.0)


def _response(pid: hc.PID, f: np.ndarray) -> np.ndarray:
    """``C(z) P(z)`` at ``z = exp(j 2 pi f Ts)``, written out (eq. 7.2 and the ZOH plant)."""
    zm1 = np.expm1(2j * np.pi * f * TS)
    z = 1 + zm1
    c = pid.kp * (1 + TS / (pid.ti * zm1) + pid.td * zm1 / (TS * z))
    p = TS ** 2 * (z + 1) / (2 * hc.MASS * zm1 ** 2)
    return c * p


def _closed_loop_radius(pid: hc.PID, k: float) -> tuple[float, float]:
    """Largest root radius and its frequency [Hz] of ``1 + k C P`` (characteristic polynomial)."""
    num_c = k * pid.kp * np.polyadd(np.polyadd([1.0, -1.0, 0.0], [TS / pid.ti, 0.0]),
                                    pid.td / TS * np.array([1.0, -2.0, 1.0]))
    den_c = [1.0, -1.0, 0.0]  # z (z - 1)
    num_p = TS ** 2 * np.array([1.0, 1.0])  # Ts^2 (z + 1)
    den_p = 2 * hc.MASS * np.array([1.0, -2.0, 1.0])  # 2 m (z - 1)^2
    roots = np.roots(np.polyadd(np.polymul(den_c, den_p), np.polymul(num_c, num_p)))
    i = np.argmax(np.abs(roots))
    return float(np.abs(roots[i])), float(abs(np.angle(roots[i])) / (2 * np.pi * TS))


def _critical_gain(pid: hc.PID) -> tuple[float, float]:
    """Factor on ``Kp`` above 1 at which a closed-loop root reaches the unit circle, and where."""
    lo, hi = 1.0, 1e4
    assert _closed_loop_radius(pid, lo)[0] < 1 < _closed_loop_radius(pid, hi)[0]
    while hi / lo > 1 + 1e-12:
        mid = np.sqrt(lo * hi)
        lo, hi = (mid, hi) if _closed_loop_radius(pid, mid)[0] < 1 else (lo, mid)
    return hi, _closed_loop_radius(pid, hi)[1]


def _hand_margin(pid: hc.PID) -> tuple[float, float]:
    """``-20 log10 |C P|`` [dB] and frequency [Hz] of the crossing of -180 deg with ``|C P| < 1``."""
    f = np.linspace(1.0, 0.5 / TS * 0.999, 20001)
    h = _response(pid, f)
    found = []
    for j in np.nonzero(np.sign(h.imag[:-1]) != np.sign(h.imag[1:]))[0]:
        f_pc = brentq(lambda x: _response(pid, np.array([x]))[0].imag, f[j], f[j + 1],
                      xtol=1e-13)
        h_pc = _response(pid, np.array([f_pc]))[0]
        if h_pc.real < 0 and abs(h_pc) < 1:
            found.append((-20 * np.log10(abs(h_pc)), f_pc))
    assert len(found) == 1  # one phase crossing limits the gain from above
    return found[0]


@pytest.mark.parametrize("scheme", PIDS)
def test_gain_margin_matches_hand_response_and_root_locus(scheme):
    pid = PIDS[scheme]
    m = hc.loop_margins(_linear(scheme, pid))
    gm_hand, f_hand = _hand_margin(pid)
    k_crit, f_crit = _critical_gain(pid)
    # the same frequency response, both refined to 1e-12: agreement to rounding
    assert_allclose(m.gain_margin_db, gm_hand, rtol=1e-9)
    assert_allclose(m.phase_crossover_hz, f_hand, rtol=1e-9)
    # bisection to 1e-12 on k; the critical root sits on the circle at the phase crossing
    assert_allclose(m.gain_margin_db, 20 * np.log10(k_crit), rtol=1e-9)
    assert_allclose(m.phase_crossover_hz, f_crit, rtol=1e-6)
    assert m.phase_crossover_hz > m.crossover_hz


@pytest.mark.parametrize("scheme", PIDS)
@pytest.mark.parametrize("factor", [0.9, 1.1, 40.0])
def test_gain_margin_around_the_critical_gain(scheme, factor):
    """Kp scaled to ``factor`` times its critical value: the margin is ``-20 log10 factor``."""
    pid = PIDS[scheme]
    k_crit, _ = _critical_gain(pid)
    loop = _linear(scheme, replace(pid, kp=pid.kp * k_crit * factor))
    m = hc.loop_margins(loop)
    assert m.closed_loop_stable == (factor < 1)
    assert m.closed_loop_stable == (_closed_loop_radius(pid, k_crit * factor)[0] < 1)
    # |L| scales with Kp; bisection to 1e-12 on k
    assert_allclose(m.gain_margin_db, -20 * np.log10(factor), rtol=1e-8)


def test_tune_nonlinear_keeps_the_minimum_gain_margin():
    """``--tune-nonlinear --min-gain-margin 6`` binds: checked against the root locus."""
    loop = _linear("weighting", PIDS["weighting"])
    free = hc.tune_nonlinear(loop, max_evaluations=40, min_gain_margin_db=0.0, held_out=())
    bound = hc.tune_nonlinear(loop, max_evaluations=40, min_gain_margin_db=6.0, held_out=())
    free_db = 20 * np.log10(_critical_gain(free.pid)[0])
    bound_db = 20 * np.log10(_critical_gain(bound.pid)[0])
    assert free_db < 6.0 <= bound_db  # without the constraint the search goes below 6 dB
    assert bound.improved and bound.cost > free.cost  # the constraint costs some tracking
    assert_allclose(bound.margins.gain_margin_db, bound_db, rtol=1e-9)
