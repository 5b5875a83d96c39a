"""Global stability of the loop (issue 14 item 8): slope sectors and the circle criterion."""

from __future__ import annotations

import json
from dataclasses import replace

import control as ct
import numpy as np
import pytest
from numpy.testing import assert_allclose

from hystkit import control as hc
from hystkit.sensors import simulate_experiment

from ..cli_support import run_cli

TS = hc.TS
G_S = 0.0184  # m per sensor unit: the scheme (b) gain of the virtual sensor's fits


@pytest.fixture(scope="module")
def preisach_sensor() -> hc.SensorBlock:
    """A rate-independent hysteretic S_r (classical Preisach, 8 levels) fitted on the
    virtual sensor's sine: its increments obey a slope sector (about 0.5 s to fit)."""
    return hc.fit_forward_sensor(simulate_experiment("sine", 2), 8, model="preisach",
                                 name="S_r")


def _weighting(sensor: hc.SensorBlock, kp_factor: float = 1.0) -> hc.ControlLoop:
    pid = hc.DOCUMENT_PID_WEIGHTING
    return hc.ControlLoop("weighting", sensor, replace(pid, kp=pid.kp * kp_factor),
                          model=hc.linear_block(50.0, name="S_m"), sensor_gain=G_S)


def _integrator(a: float, ts: float = 1e-3) -> ct.StateSpace:
    """``G(z) = a / (z - 1)``."""
    return ct.ss([[1.0]], [[1.0]], [[a]], [[0.0]], ts)


# --------------------------------------------------------------------------- closed forms


@pytest.mark.parametrize("a", [0.5, 2.0, 7.3])
@pytest.mark.parametrize("k1_fraction", [0.05, 0.5, 0.95])
def test_circle_bound_of_a_discrete_integrator_is_two_over_a(a, k1_fraction):
    # By hand: with p_i = 1 - k_i a, Re[(z - p2)(conj z - p1)] > 0 on |z| = 1 iff
    # (1 - p1)(1 - p2) > 0 and (1 + p1)(1 + p2) > 0, i.e. 0 < k2 a < 2 for every stable
    # k1: the largest provable upper bound is 2 / a, whatever k1.
    k1 = k1_fraction * 2 / a
    res = hc.circle_criterion(_integrator(a), k1, k1)
    assert res.proved and res.base_stable
    assert_allclose(res.k_max_proved, 2 / a, rtol=1e-9)  # reached at Nyquist exactly
    assert_allclose(res.worst_hz, 0.5 / 1e-3)
    assert not hc.circle_criterion(_integrator(a), k1, 2 / a * (1 + 1e-6)).proved


def test_the_bound_two_over_a_is_where_a_constant_gain_diverges():
    # x+ = (1 - k a) x: the pole leaves the unit circle at k = 2 / a
    a = 0.5
    for k, grows in ((2 / a * 0.999, False), (2 / a * 1.001, True)):
        x = 1.0
        for _ in range(20000):
            x *= 1 - k * a
        assert (abs(x) > 1) is grows


@pytest.mark.parametrize("k1", [5.0, 40.0])
def test_circle_bound_of_the_double_integrator_loop_by_its_formulas(k1):
    # Scheme (b) with the document's PID on the 0.25 kg double integrator: G(z) written out by
    # hand -- exact ZOH P(z) = Ts^2 (z + 1) / (2 m (z - 1)^2), eq. 7.2's
    # C(z) = Kp (1 + Ts / (Ti (z - 1)) + Td (z - 1) / (Ts z)), times g_s -- and
    # max(-Re T_1) found on a dense grid, against python-control's interconnection and the
    # refined search of circle_criterion.
    loop = _weighting(hc.linear_block(50.0))
    p, m = loop.pid, loop.plant.mass
    z = np.exp(1j * np.r_[np.geomspace(1e-7, np.pi, 400000), np.linspace(1e-3, np.pi, 400000)])
    plant = TS ** 2 * (z + 1) / (2 * m * (z - 1) ** 2)
    pid = p.kp * (1 + TS / (p.ti * (z - 1)) + p.td * (z - 1) / (TS * z))
    g = G_S * pid * plant
    worst = np.max(-(g / (1 + k1 * g)).real)
    res = hc.circle_criterion(hc.sector_channel(loop), k1, k1)
    assert res.base_stable
    # the dense grid can only miss the peak from below: the refined bound is at most the grid's
    assert res.k_max_proved <= k1 + 1 / worst * (1 + 1e-12)
    assert_allclose(res.k_max_proved, k1 + 1 / worst, rtol=1e-6)


def test_a_lower_bound_that_destabilises_proves_nothing():
    res = hc.circle_criterion(_integrator(0.5), -0.1, 1.0)
    assert not res.proved and not res.base_stable and res.k_max_proved is None


def test_every_constant_gain_in_the_proved_sector_is_stable(preisach_sensor):
    # The circle criterion covers every time-varying gain in the sector, so in particular every
    # constant one (Aizerman's direction): eigenvalues, an independent check.
    g = hc.sector_channel(_weighting(preisach_sensor))
    res = hc.circle_criterion(g, 5.0, 6.0)
    assert np.isfinite(res.k_max_proved)
    for k in np.linspace(5.0, 0.999 * res.k_max_proved, 25):
        assert np.max(np.abs(np.linalg.eigvals(ct.feedback(g, k).A))) < 1


@pytest.mark.parametrize("scheme,dob", [("direct", False), ("direct", True),
                                        ("weighting", False)])
def test_channel_closed_by_a_linear_sensor_is_the_linearised_loop(scheme, dob):
    # A linear sensor of slope g and an exact compensator make the channel a constant gain:
    # feedback(G, gain) must have the poles of the linearised loop of _analysis.
    g = 40.0
    loop = hc.ControlLoop(scheme, hc.linear_block(g), hc.DOCUMENT_PID_DIRECT
                          if scheme == "direct" else hc.DOCUMENT_PID_WEIGHTING,
                          compensator=hc.linear_block(1 / g), model=hc.linear_block(g),
                          sensor_gain=1 / g,
                          dob=hc.DisturbanceObserver(20.0) if dob else None)
    gain = 1.0 if scheme == "direct" else g
    closed = ct.feedback(hc.sector_channel(loop), gain)
    radius = np.max(np.abs(np.linalg.eigvals(closed.A)))
    assert_allclose(radius, hc.loop_margins(loop).max_pole_radius, rtol=1e-9)


def test_weighting_with_the_dob_is_outside_the_single_channel_criterion(preisach_sensor):
    loop = replace(_weighting(preisach_sensor), compensator=hc.linear_block(G_S),
                   dob=hc.DisturbanceObserver(20.0))
    with pytest.raises(ValueError, match="two nonlinear channels"):
        hc.sector_channel(loop)
    rep = hc.global_stability(loop)
    assert rep.verdict == "not proved" and "two nonlinear channels" in rep.reason


# --------------------------------------------------------------------------- sectors


def test_sector_of_a_play_operator_is_zero_to_one():
    # backlash of half-width 0.2 on a sine: slope 0 inside the band, 1 on the branches
    u = np.sin(np.linspace(0, 6 * np.pi, 3001))
    y = np.empty_like(u)
    y[0] = u[0]
    for n in range(1, u.size):
        y[n] = min(max(y[n - 1], u[n] - 0.2), u[n] + 0.2)
    sec = hc.chord_sector(u, y)
    assert_allclose([sec.k_min, sec.k_max], [0.0, 1.0], atol=1e-12)
    assert sec.unexplained_step < 1e-12  # rate independent: nothing outside the sector


def test_sector_of_a_linear_block_is_its_gain():
    loop = _weighting(hc.linear_block(37.5))
    sec = hc.measure_sector(loop)["channel"]
    assert_allclose([sec.k_min, sec.k_max], [37.5, 37.5], rtol=1e-9)
    assert sec.unexplained_step < 1e-9


# --------------------------------------------------------------------------- verdicts


def test_hysteretic_loop_is_proved_and_its_run_stays_inside_the_sector(preisach_sensor):
    rep = hc.global_stability(_weighting(preisach_sensor))
    ch = rep.sectors["channel"]
    assert 0 < ch.k_min < ch.k_max  # a hysteretic, monotone sensor
    assert rep.verdict == "proved stable"
    assert ch.k_max < rep.circle.k_max_proved
    assert rep.bounded
    # the closed-loop run's own increments lie in the sector measured on the trained sine
    assert ch.k_min - 1e-9 <= rep.loop_sector.k_min <= rep.loop_sector.k_max <= ch.k_max + 1e-9
    assert rep.sector.k_max < rep.circle.k_max_proved  # the hull of both, tested


@pytest.fixture(scope="module")
def noise_preisach() -> hc.SensorBlock:
    """Preisach S_r (8 levels) fitted on the virtual sensor's noise run: in the cubic run's
    closed loop its slopes go below those of the trained sine (about 1.3 s to fit)."""
    return hc.fit_forward_sensor(simulate_experiment("noise", 2), 8, model="preisach",
                                 name="S_r")


def test_run_leaving_the_training_sector_widens_the_sector_tested(noise_preisach):
    loop = _weighting(noise_preisach)
    rep = hc.global_stability(loop, "cubic")
    ch, run = rep.sectors["channel"], rep.loop_sector
    assert run.k_min < ch.k_min - 1.0  # the run leaves the trained sine's sector (15.6 < 18.4)
    # the sector tested is the hull of both, and the circle result is that of the hull
    assert (rep.sector.k_min, rep.sector.k_max) == (min(ch.k_min, run.k_min),
                                                    max(ch.k_max, run.k_max))
    assert len(rep.sector_sources) == 2
    hull = hc.circle_criterion(hc.sector_channel(loop), rep.sector.k_min, rep.sector.k_max)
    assert rep.circle.to_dict() == hull.to_dict()
    assert rep.verdict == "proved stable" and "leave the trained sine" in rep.reason
    assert "constant reference" in rep.reason


def test_a_hull_beyond_the_proved_bound_is_not_proved(noise_preisach):
    # Kp x 85: the trained sine's sector alone would be proved (bound 64.0 > k_max 63.6),
    # the hull with the cubic run's lower slopes is not (bound 62.5 < 63.6)
    loop = _weighting(noise_preisach, kp_factor=85.0)
    rep = hc.global_stability(loop, "cubic")
    ch = rep.sectors["channel"]
    assert hc.circle_criterion(hc.sector_channel(loop), ch.k_min, ch.k_max).proved
    assert rep.sector.k_min < ch.k_min and not rep.circle.proved
    assert rep.verdict == "not proved" and rep.bounded


def test_linear_sensor_inside_the_proved_sector_is_proved(preisach_sensor):
    top = hc.global_stability(_weighting(preisach_sensor)).circle.k_max_proved
    rep = hc.global_stability(_weighting(hc.linear_block(0.5 * top)))
    assert rep.verdict == "proved stable" and rep.bounded


def test_too_wide_a_sector_is_not_proved_and_the_run_diverges(preisach_sensor):
    # Kp 300 times the document's: the sector reaches far beyond what the criterion proves,
    # and the simulation shows the divergence, so the verdict may say "unstable"
    rep = hc.global_stability(_weighting(preisach_sensor, kp_factor=300.0))
    assert rep.sectors["channel"].k_max > rep.circle.k_max_proved
    assert not rep.circle.proved and not rep.bounded
    assert rep.verdict == "unstable" and rep.stop_time > 0
    # the same loop at the document's Kp was proved: the verdict depends on the gain
    mid = hc.global_stability(_weighting(preisach_sensor, kp_factor=60.0))
    assert mid.verdict == "not proved" and mid.bounded  # sufficient only: not "unstable"


def test_report_is_json_safe(preisach_sensor):
    json.dumps(hc.global_stability(_weighting(preisach_sensor)).to_dict(), allow_nan=False)


# --------------------------------------------------------------------------- CLI


def test_cli_stability_of_a_control_setup(capsys, tmp_path):
    out = tmp_path / "stab.json"
    code, stdout, err = run_cli(capsys, "stability", "--control", "--scheme", "direct",
                             "--json", out)
    assert code == 0, err
    report = json.loads(out.read_text())
    # the docs' table: the default direct loop's channel has slopes below 0, so condition 1
    # fails at k_min and nothing is proved; its sine run stays bounded
    assert report["verdict"] == "not proved" and report["bounded"]
    assert report["sector"]["k_min"] < 0 and report["circle"]["base_stable"] is False
    assert report["sectors"]["channel"]["k_min"] < 0
    assert {"sensor", "compensator", "channel"} <= set(report["sectors"])
    assert "global stability:" in stdout and "circle criterion" in stdout


@pytest.mark.parametrize("argv,fragment", [
    (["stability", "--control"], "--scheme"),
    (["stability"], "MODEL.json"),
    (["stability", "m.json", "--control", "--scheme", "direct"], "no MODEL.json"),
    (["stability", "m.json", "--scheme", "direct"], "need --control"),
])
def test_cli_stability_bad_combinations_are_one_line(capsys, argv, fragment):
    code, _, err = run_cli(capsys, *argv)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("hystkit: error: ") and fragment in lines[0]
