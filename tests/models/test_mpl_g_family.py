"""The ch. 7 compensator family (mpl-g): its equations against the mPL's and the mpl-poly's
independent kernels, parameter recovery, the inverse, the monotone fit of g, and the sec. 7.2
compensators of table II's sensors against the control code's table-II sensor run."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from hystkit.models import get_family
from hystkit.models.mpl import model as mpl
from hystkit.models.mpl_g import model as mpl_g
from hystkit.models.mpl_g.fit import (
    MONOTONE_RANGE,
    bernstein_slopes,
    canonical,
    fit_mpl_g,
    output_from_slopes,
)
from hystkit.models.mpl_poly import model as mpl_poly

FAMILY = get_family("mpl-g")
DT = 0.025


def _input(n: int = 2400, seed: int = 0) -> np.ndarray:
    """Smooth random input in [-1, 1] with reversals at many amplitudes and rates."""
    rng = np.random.default_rng(seed)
    phase = np.cumsum(rng.uniform(0.0, 0.25, n))
    return np.sin(phase) * (0.55 + 0.45 * np.sin(0.013 * np.arange(n)))


def _known(n_cells: int = 2) -> mpl_g.MplGParams:
    """A model in the fit's gauge (w_0 = 1, V_b = 0) with g increasing on |z| <= 2."""
    return mpl_g.MplGParams(i_s=[0.6, 0.02][:n_cells], v_t=[0.5, 0.2][:n_cells],
                            g=output_from_slopes(0.05, [0.6, 1.3, 0.9]),
                            w=[1.0, -0.45, 0.2][:n_cells + 1], v_b=0.0)


def test_with_a_linear_g_it_is_the_mpl():
    # independent: the mPL's own kernel and params class
    structure = mpl_g.MplGStructure(n_cells=2, dt=DT)
    p = _known()
    linear = mpl_g.MplGParams(i_s=p.i_s, v_t=p.v_t, g=[0.0, 1.0, 0.0, 0.0], w=p.w, v_b=0.3)
    ref = mpl.MplParams(i_s=p.i_s, v_t=p.v_t, w=p.w, v_b=0.3)
    u = _input()
    y, x = mpl_g.simulate(structure, linear, u)
    y_ref, x_ref = mpl.simulate(mpl.MplStructure(n_cells=2, dt=DT), ref, u)
    assert_allclose(y, y_ref, rtol=0, atol=1e-15)
    assert_allclose(x, x_ref, rtol=0, atol=1e-15)


def test_output_is_g_of_the_mpl_output():
    # eq. 5.17: i = g(z) with z the mPL's eq. 5.2 voltage; g evaluated by mpl-poly's function
    structure = mpl_g.MplGStructure(n_cells=2, dt=DT)
    p = _known()
    u = _input(seed=1)
    z, _ = mpl.simulate(mpl.MplStructure(n_cells=2, dt=DT),
                        mpl.MplParams(i_s=p.i_s, v_t=p.v_t, w=p.w, v_b=p.v_b), u)
    y, _ = mpl_g.simulate(structure, p, u)
    assert_allclose(y, mpl_poly.output_current(p, z), rtol=0, atol=1e-14)


def test_compiled_runs_equal_the_readable_reference():
    structure = mpl_g.MplGStructure(n_cells=2, dt=DT)
    p = _known()
    u = _input(500, seed=2)
    y, x_end = mpl_g.simulate(structure, p, u)
    y_ref, x_ref = mpl_g.simulate_reference(structure, p, u)
    assert_allclose(y, y_ref, rtol=0, atol=1e-14)
    assert_allclose(x_end, x_ref, rtol=0, atol=1e-14)
    # the inverse: compiled (Newton in a bracket) and readable (brentq) from the same state
    u_hat, _ = mpl_g.invert(structure, p, y)
    x = mpl_g.rest_state(structure, p, float(y[0]), inverse=True)
    for k in range(200):
        e, x = mpl_g.invert_step(structure, p, x, y[k])
        assert e == pytest.approx(u_hat[k], abs=1e-12), k


@pytest.mark.parametrize("seed", range(5))
def test_inverse_undoes_drawn_models_of_the_documented_domain(seed):
    # random_params promises an increasing g and contracting inverse cells (sum|w_k| < |w_0|)
    structure = mpl_g.MplGStructure(n_cells=3, dt=DT)
    p = FAMILY.random_params(structure, np.random.default_rng(seed))
    u = _input(1500, seed=seed)
    y, _ = mpl_g.simulate(structure, p, u)
    u_hat, _ = mpl_g.invert(structure, p, y)
    assert_allclose(u_hat, u, rtol=0, atol=1e-9)


def test_canonical_form_keeps_every_output():
    structure = mpl_g.MplGStructure(n_cells=2, dt=DT)
    p = mpl_g.MplGParams(i_s=[0.6, 0.02], v_t=[0.5, 0.2], g=[0.1, -0.8, 0.05, -0.02],
                         w=[-1.7, 0.6, 0.3], v_b=0.4)
    c = canonical(p)
    assert c.w[0] == 1.0 and c.v_b == 0.0
    u = _input(seed=3)
    assert_allclose(mpl_g.simulate(structure, c, u)[0], mpl_g.simulate(structure, p, u)[0],
                    rtol=0, atol=1e-12)
    y, _ = mpl_g.simulate(structure, p, u)
    assert_allclose(mpl_g.invert(structure, c, y)[0], mpl_g.invert(structure, p, y)[0],
                    rtol=0, atol=1e-9)


def test_bernstein_slopes_give_a_monotone_g_and_round_trip():
    rng = np.random.default_rng(4)
    z = np.linspace(-MONOTONE_RANGE, MONOTONE_RANGE, 4001)
    for _ in range(200):
        b = np.exp(rng.uniform(np.log(1e-6), np.log(1e3), 3)) * rng.choice([-1.0, 1.0])
        g = output_from_slopes(rng.uniform(-1, 1), b)
        slope = mpl_g.output_slope(mpl_g.MplGParams(i_s=[1.0], v_t=[1.0], g=g, w=[1.0, 0.0]), z)
        assert np.all(np.sign(b[0]) * slope > 0)
        assert_allclose(bernstein_slopes(g), b, rtol=1e-9, atol=1e-12 * np.max(np.abs(b)))


@pytest.mark.parametrize("n_cells", [1, 2])
def test_fit_recovers_known_parameters(n_cells):
    structure = mpl_g.MplGStructure(n_cells=n_cells, dt=DT)
    truth = _known(n_cells)
    u = _input(4000, seed=5)
    y, _ = mpl_g.simulate(structure, truth, u)
    result = fit_mpl_g(u, y, structure, max_nfev=400)
    got = result.params
    fitted, _ = mpl_g.simulate(structure, got, u)
    assert result.converged
    assert np.sqrt(np.mean((fitted - y) ** 2)) < 1e-7  # noise-free data: an exact fit
    order = np.argsort(got.v_t)[::-1]  # cells are interchangeable: match them by V_T
    assert_allclose(got.v_t[order], truth.v_t, rtol=1e-4)
    assert_allclose(got.i_s[order], truth.i_s, rtol=1e-4)
    assert_allclose(got.w[1:][order], truth.w[1:], rtol=0, atol=1e-5)
    assert_allclose(got.g, truth.g, rtol=0, atol=1e-5)
    assert got.w[0] == 1.0 and got.v_b == 0.0  # the fit's gauge


def test_fitted_g_is_monotone_on_its_range_and_never_worse_than_the_mpl():
    from hystkit.models.mpl.fit import fit_mpl
    from hystkit.sensors import simulate_experiment

    rec = simulate_experiment("noise", 1)
    s = rec.sensor - rec.sensor.mean()
    p = rec.position - rec.position.mean()
    s, p = s / np.max(np.abs(s)), p / np.max(np.abs(p))
    structure = mpl_g.MplGStructure(n_cells=1, dt=rec.dt)
    result = fit_mpl_g(s, p, structure)
    z = np.linspace(-MONOTONE_RANGE, MONOTONE_RANGE, 2001)
    assert np.all(mpl_g.output_slope(result.params, z) > 0)
    linear = fit_mpl(s, p, mpl.MplStructure(n_cells=1, dt=rec.dt))
    assert result.cost <= linear.cost * (1 + 1e-9)  # it starts from the mPL's optimum


def test_a_veto_on_every_curved_g_returns_the_accepted_mpl():
    # inverse mode vetoes candidates whose inverse diverges; here every curved g is vetoed
    structure = mpl_g.MplGStructure(n_cells=1, dt=DT)
    u = _input(2000, seed=6)
    y, _ = mpl_g.simulate(structure, _known(1), u)
    result = fit_mpl_g(u, y, structure, accept=lambda p: p.g[2] == 0 and p.g[3] == 0,
                       accept_reason="curved")
    assert result.params.g[2] == 0 and result.params.g[3] == 0
    assert "g kept linear" in result.message and "(curved)" in result.message
    linear, _ = mpl_g.simulate(structure, result.params, u)
    assert np.sum((linear - y) ** 2) == pytest.approx(result.cost, rel=1e-9)  # SSE, eq. 5.9


@pytest.mark.parametrize("column", ["sine", "chirp", "decay", "noise"])
def test_preset_training_run_is_the_control_codes_table_ii_sensor(column):
    """The data the sec. 7.2 compensators are fitted on equal, to 1e-12, what the control
    code's table-II sensor (its own scaling and block path) gives on eq. 7.3's sine."""
    from hystkit.control import table_ii_sensor
    from hystkit.models.mpl_g.presets import TRAINING_DT, table_ii_response

    position, sensor = table_ii_response(column)
    t = np.arange(position.size) * TRAINING_DT
    signal, _ = table_ii_sensor(column).simulate(3e-3 * np.sin(np.pi * t), TRAINING_DT)
    assert_allclose(position, np.sin(np.pi * t), rtol=0, atol=1e-15)
    assert_allclose(sensor, signal, rtol=0, atol=1e-12)


def test_ch7_preset_reports_its_own_fit_quality():
    """The preset's R^2 recomputed through the control code's sensor block and the family's
    protocol equals the one it reports; the compensator is a good fit (document: 0.995)."""
    from hystkit.control import table_ii_sensor

    presets = FAMILY.presets()
    assert sorted(presets) == [f"ch7-table-ii-{c}" for c in ("chirp", "decay", "noise", "sine")]
    structure, params, info = presets["ch7-table-ii-noise"]
    t = np.arange(8000) * structure.dt
    signal, _ = table_ii_sensor("noise").simulate(3e-3 * np.sin(np.pi * t), structure.dt)
    s = (signal - info["sensor_center"]) / info["sensor_scale"]
    target = (np.sin(np.pi * t) - info["position_center"]) / info["position_scale"]
    estimate, _ = FAMILY.simulate(structure, params, s)
    r2 = 1 - np.sum((estimate - target) ** 2) / np.sum((target - target.mean()) ** 2)
    assert r2 == pytest.approx(info["r2"], abs=1e-9)
    assert r2 > 0.995 and info["converged"]
