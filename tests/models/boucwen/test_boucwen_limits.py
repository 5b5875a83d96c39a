"""Bouc-Wen limits (issue 10): substep cap, exponent cap, divergence stopped and explained, the
documented random domain stays bounded, short records refused, hypothesis fuzz of the run."""

import os

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hystkit.errors import FitDivergedError
from hystkit.models import boucwen as bw
from hystkit.models import get_family

FAMILY = get_family("boucwen")
EXAMPLES = int(os.environ.get("HYSTKIT_FUZZ_EXAMPLES", "150"))
DT = 0.025


def _sweep(n: int = 600, dt: float = DT) -> np.ndarray:
    t = np.arange(n) * dt
    return 0.9 * np.sin(2 * np.pi * (0.05 + 0.5 * t / t[-1]) * t)


@pytest.mark.parametrize("substeps", [1e12, float("inf"), float("nan"), 2049, 0, 2.5, "abc",
                                      None])
def test_substeps_outside_the_cap_are_refused_before_any_run(substeps):
    with pytest.raises(ValueError, match=r"substeps must be an integer in \[1, 2048\]"):
        bw.BoucWenStructure(substeps=substeps)
    with pytest.raises(ValueError, match="substeps"):
        FAMILY.make_structure(DT, substeps)


def test_substeps_at_the_cap_run():
    s = bw.BoucWenStructure(dt=DT, substeps=bw.MAX_SUBSTEPS)
    y, _ = bw.simulate(s, FAMILY.random_params(s, np.random.default_rng(1)), _sweep(20))
    assert np.all(np.isfinite(y))


@pytest.mark.parametrize("nu", [0.5, 8.5, 1e300])
def test_nu_outside_its_range_is_refused(nu):
    with pytest.raises(ValueError, match=r"nu must lie in \[1, 8\]"):
        bw.BoucWenParams(m=1.0, c=1.0, k=1.0, alpha=1.0, beta=1.0, gamma=0.0, nu=nu)


@pytest.mark.parametrize("seed", range(3))
@pytest.mark.parametrize("dt, size", [(0.025, 1), (0.025, 4), (1.0, 2), (1e-3, 2)])
def test_random_params_stay_within_the_passivity_bound(seed, dt, size):
    s = FAMILY.make_structure(dt, size)
    rng = np.random.default_rng(seed)
    for k in range(15):
        p = FAMILY.random_params(s, rng)
        assert bw.bounded_class(p) and p.nu == 1.0
        u = _sweep(800, dt) if k % 2 else rng.uniform(-1, 1, 800)
        y, _ = FAMILY.simulate(s, p, u)
        x0 = bw.initial_state(s, p, u[0])
        assert np.max(np.abs(y)) <= bw.divergence_bound(s, p, x0, u) / 2, (k, p)


def test_divergence_names_the_sample_and_the_step_when_w0_h_is_too_large():
    p = bw.BoucWenParams(m=1e-6, c=1e-4, k=1.0, alpha=1.0, beta=0.0, gamma=0.0)
    with pytest.raises(FitDivergedError, match=r"diverged at sample \d+ of 100.*w0 h = 14.1"):
        bw.simulate(bw.BoucWenStructure(dt=0.01, substeps=1), p, _sweep(100, 0.01))


def test_divergence_of_an_unbounded_loop_blames_the_loop_not_the_step():
    # beta + gamma < 0: z grows without limit on loading; w0 h = 0.05 is far inside RK4's limit
    p = bw.BoucWenParams(m=1.0, c=1.0, k=1.0, alpha=1.0, beta=-50.0, gamma=-50.0, nu=3.0)
    with pytest.raises(FitDivergedError, match="not both >= 0, so the hysteretic force z") as e:
        bw.simulate(bw.BoucWenStructure(dt=0.05, substeps=1), p, 5 * _sweep(400, 0.05))
    assert "too long" not in str(e.value)


def test_divergence_in_the_bounded_class_is_stopped_at_the_energy_bound():
    # w0 h = 0.3, but a hysteretic element far too stiff for the step
    p = bw.BoucWenParams(m=1.0, c=0.5, k=1.0, alpha=5.0, beta=400.0, gamma=100.0, nu=1.0)
    s = bw.BoucWenStructure(dt=0.12, substeps=1)
    with pytest.raises(FitDivergedError, match="beyond the bound.*too stiff"):
        bw.simulate(s, p, 3 * np.sign(np.sin(np.arange(300) / 3.0)))


@pytest.mark.parametrize("n", [1, 2, 7])
def test_short_records_are_refused_with_a_value_error(n):
    u = np.sin(np.arange(n) + 1.0)
    with pytest.raises(ValueError, match="at least 8 samples"):
        FAMILY.fit(u, 0.9 * u + 0.01, FAMILY.make_structure(DT, 2))


def test_a_constant_output_is_refused_with_a_value_error():
    u = np.sin(np.arange(50) / 5.0)
    with pytest.raises(ValueError, match="varying output"):
        FAMILY.fit(u, np.full(50, 0.3), FAMILY.make_structure(DT, 2))


_MAG = st.floats(-320, 300).map(lambda e: 10.0 ** e)
_SIGNED = st.one_of(st.just(0.0), st.just(5e-324), _MAG,
                    _MAG.map(lambda v: -v))


@settings(max_examples=EXAMPLES, deadline=None)
@given(m=_MAG, c=_MAG, k=_MAG, alpha=_MAG, beta=_SIGNED, gamma=_SIGNED,
       nu=st.floats(0.5, 12.0), substeps=st.integers(1, 8), amp=_MAG,
       seed=st.integers(0, 2**32 - 1))
def test_fuzz_run_is_finite_and_bounded_or_raises_diverged(m, c, k, alpha, beta, gamma, nu,
                                                          substeps, amp, seed):
    try:
        p = bw.BoucWenParams(m=m, c=c, k=k, alpha=alpha, beta=beta, gamma=gamma, nu=nu)
    except ValueError:  # nu outside [1, 8], or an m so small that 1 / m overflows
        assert not 1 <= nu <= 8 or not np.isfinite(1.0 / m)
        return
    s = bw.BoucWenStructure(dt=DT, substeps=substeps, start="equilibrium")
    u = np.random.default_rng(seed).uniform(-1, 1, 200) * min(amp, 1e100)
    try:
        y, x_end = bw.simulate(s, p, u)
    except FitDivergedError as exc:
        assert "diverged at sample" in str(exc)
        return
    assert np.all(np.isfinite(y)) and np.all(np.isfinite(x_end))
    assert np.max(np.abs(y)) <= bw.divergence_bound(s, p, bw.initial_state(s, p, u[0]), u)


def test_a_fit_whose_runs_all_diverge_says_what_the_last_run_did(monkeypatch):
    from hystkit.models.boucwen import fit as bw_fit

    def diverging(u, x0, fresh, theta, dt, n_sub, linear, bound):
        states = np.zeros((u.size, 3))
        return states, np.array([1e200, -1e300, 3.0, u[3]]), 3

    monkeypatch.setattr(bw_fit.kernels, "simulate", diverging)
    u = _sweep(200)
    with pytest.raises(FitDivergedError, match=r"every linear start diverged; the last: the "
                                               r"Bouc-Wen state diverged at sample 4 of 200"):
        FAMILY.fit(u, 0.8 * u, FAMILY.make_structure(DT, 2))
