"""Fit-time guards fire on constructed bad fits; multi-recording fits recover known parameters."""

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.optimize import curve_fit

from hystkit.compensation import fit_compensator
from hystkit.compensation._diagnostics import bound_flags, fit_status, standard_errors
from hystkit.errors import InputError
from hystkit.identification import FitResult
from hystkit.io import Recording
from hystkit.models import get_family
from hystkit.models.mpl import MplParams, MplStructure

DT = 0.025


def test_a_constant_estimate_is_collapsed():
    target = np.sin(np.linspace(0, 20, 400))
    status, message = fit_status(np.full(400, 0.1), target, 0.9 * target, None, True)
    assert status == "collapsed" and "constant" in message


def test_a_fit_worse_than_its_line_says_so():
    target = np.sin(np.linspace(0, 20, 400))
    status, _ = fit_status(0.5 * target + 0.3, target, target, None, True)
    assert status == "worse_than_line"


def _on_bound_result(**extra):
    return FitResult(structure=None, params=None, cost=0.0, n_evaluations=1, seconds=0.0,
                     converged=True, message="", n_starts=1,
                     theta=np.array([0.5, np.log(1e3) - 2e-7]),
                     bounds=(np.array([0.0, np.log(1e-3)]), np.array([1.0, np.log(1e3)])),
                     **extra)


def test_parameters_on_a_bound_are_flagged_never_ok():
    target = np.sin(np.linspace(0, 20, 400))
    flags, notes = bound_flags(_on_bound_result())
    assert flags == ["theta[1] (upper)"] and notes == []
    status, message = fit_status(target, target, 0.9 * target, flags, True)
    assert status == "on_bounds" and "theta[1] (upper)" in message
    assert fit_status(target, target, 0.9 * target, [], True)[0] == "ok"


def test_a_bound_hit_is_reported_by_name():
    target = np.sin(np.linspace(0, 20, 400))
    flags, _ = bound_flags(_on_bound_result(names=("w", "log_v_t")))
    status, message = fit_status(target, target, 0.9 * target, flags, True)
    assert status == "on_bounds" and message.endswith("search box: log_v_t (upper)")


def test_a_model_limit_is_not_on_bounds():
    target = np.sin(np.linspace(0, 20, 400))
    flags, notes = bound_flags(_on_bound_result(
        names=("w", "log_v_t"), limits=((None, None), (None, "the resistor is linear"))))
    assert flags == [] and notes == ["the resistor is linear"]
    assert fit_status(target, target, 0.9 * target, flags, True)[0] == "ok"


def test_a_fit_without_bounds_has_no_bound_flags():
    result = FitResult(structure=None, params=None, cost=0.0, n_evaluations=1, seconds=0.0,
                       converged=True, message="", n_starts=1)
    assert bound_flags(result) == (None, [])


def test_standard_errors_agree_with_scipy_curve_fit():
    """Independent route: curve_fit's covariance s^2 (J^T J)^-1 at its own optimum."""
    family = get_family("mpl")
    structure = MplStructure(n_cells=1, dt=DT)
    rng = np.random.default_rng(3)
    u = np.convolve(rng.normal(size=800), np.ones(20) / 20, mode="same") * 4
    truth = MplParams(i_s=[0.05], v_t=[0.5], w=[0.8, 0.3], v_b=0.1)
    y = family.simulate(structure, truth, u)[0] + rng.normal(scale=0.01, size=u.size)

    def model(_, i_s, v_t, w0, w1, v_b):
        return family.simulate(structure, MplParams(i_s=[i_s], v_t=[v_t], w=[w0, w1], v_b=v_b),
                               u)[0]

    popt, pcov = curve_fit(model, u, y, p0=[0.05, 0.5, 0.8, 0.3, 0.1])
    best = MplParams(i_s=[popt[0]], v_t=[popt[1]], w=[popt[2], popt[3]], v_b=popt[4])
    se = standard_errors(lambda p: family.simulate(structure, p, u)[0] - y, best, u.size)
    # finite-difference Jacobians on both sides: agreement to a few per cent
    assert_allclose(se["standard_errors"], np.sqrt(np.diag(pcov)), rtol=0.05)
    assert_allclose(se["values"], popt)


def test_a_two_row_recording_is_refused_with_one_line():
    rec = Recording(time=[0.0, DT], sensor=[0.0, 1.0], position=[0.0, 1.0], source="two.csv")
    with pytest.raises(InputError, match=r"two.csv: column 'position': 2 samples; a fit needs"):
        fit_compensator(rec, 1)


def test_too_many_parameters_for_the_data_are_refused():
    t = np.arange(60) * DT
    rec = Recording(time=t, sensor=np.sin(t), position=np.sin(t + 0.1), source="short.csv")
    with pytest.raises(InputError, match="samples per parameter"):
        fit_compensator(rec, 20, model="mpl", diagnose=False)  # 62 parameters, 60 samples


def _recording(u_norm, offset, mean_b, s_scale, true_params, structure, seed):
    """Sensor = rest, then motion, plus this recording's own offset; position from the true
    model on the normalised sensor (what the compensator will see after tare)."""
    p, _ = get_family("mpl").simulate(structure, true_params, u_norm)
    t = np.arange(u_norm.size) * DT
    return Recording(time=t, sensor=u_norm * s_scale + mean_b + offset, position=2.0 * p + 0.3,
                     source=f"sim{seed}.csv")


def test_three_recordings_with_different_offsets_recover_known_parameters():
    structure = MplStructure(n_cells=1, dt=DT)
    truth = MplParams(i_s=[0.08], v_t=[0.3], w=[0.9, 0.5], v_b=0.05)
    rng = np.random.default_rng(7)
    bases = []
    for _ in range(3):
        motion = np.convolve(rng.normal(size=1200), np.ones(15) / 15, mode="same")
        bases.append(np.concatenate([np.zeros(80), 2.5 * motion]))  # 2 s at rest first
    all_b = np.concatenate(bases)
    mean_b, s_scale = all_b.mean(), np.max(np.abs(all_b - all_b.mean()))
    recs = [_recording((b - mean_b) / s_scale, offset, mean_b, 3.0, truth, structure, k)
            for k, (b, offset) in enumerate(zip(bases, (0.0, 4.0, -7.0), strict=True))]
    comp = fit_compensator(recs, 1, center="tare", tare_seconds=2.0)
    # the tare removes each offset exactly; input normalisation is then the one used above,
    # so the resistor (i_s, v_t) is recovered as is and the output weights up to the affine
    # position normalisation p_n = (2 p + 0.3 - mean) / scale
    assert_allclose(comp.params.i_s, truth.i_s, rtol=1e-3)
    assert_allclose(comp.params.v_t, truth.v_t, rtol=1e-3)
    for rec in recs:
        assert_allclose(comp.estimate(rec), rec.position, atol=1e-4 * np.ptp(rec.position))
    assert comp.fit_info["status"] in ("ok", "on_bounds")
    assert "joint polish" in comp.fit_info["joint_fit"]
