"""Robust and weighted costs of ``fit_multistart`` and the families' fits (issue 14.4).

Checked against values computed here, not by the code under test: the weighted linear least
squares solution in closed form, the stationarity of the weighted robust objective (its
gradient by finite differences of ``sum f^2 rho(w r^2 / f^2)`` with scipy's documented
``rho``, through the family's own ``simulate``), and the recovery of known parameters from
data with injected spikes.
"""

from __future__ import annotations

import numpy as np
import pytest

from hystkit.errors import InputError
from hystkit.identification import fit_multistart, objective
from hystkit.models.mpl import fit as mpl_fit
from hystkit.models.mpl import model as mpl


def _rho(z: np.ndarray, loss: str) -> np.ndarray:
    """scipy.optimize.least_squares' loss functions, as its documentation states them."""
    return {"linear": z, "soft_l1": 2 * ((1 + z) ** 0.5 - 1),
            "huber": np.where(z <= 1, z, 2 * np.sqrt(z) - 1), "cauchy": np.log(1 + z)}[loss]


def _robust(r: np.ndarray, loss: str, f: float, w: np.ndarray | None = None) -> float:
    z = r ** 2 if w is None else w * r ** 2
    return float(f ** 2 * np.sum(_rho(z / f ** 2, loss)))


# --- a linear model: closed forms -----------------------------------------------------------

def _linear_problem(seed: int = 0):
    rng = np.random.default_rng(seed)
    a = rng.standard_normal((200, 3))
    b = a @ np.array([1.0, -2.0, 0.5]) + 0.1 * rng.standard_normal(200)
    return a, b


def _fit_linear(a, b, **options):
    bounds = (np.full(3, -10.0), np.full(3, 10.0))
    return fit_multistart(lambda th: a @ th - b, [np.zeros(3)], bounds, lambda th: th, None,
                          jac=lambda th: a, **options)


def test_weighted_linear_fit_is_the_closed_form_solution():
    a, b = _linear_problem()
    w = np.random.default_rng(1).uniform(0, 3, b.size)
    res = _fit_linear(a, b, weights=w)
    expected = np.linalg.solve(a.T @ (w[:, None] * a), a.T @ (w * b))
    np.testing.assert_allclose(res.theta, expected, rtol=1e-8, atol=1e-10)
    r = a @ res.theta - b
    assert res.cost == pytest.approx(float(r @ r), rel=1e-12)  # the plain SSE
    assert res.objective == pytest.approx(float(w @ r ** 2), rel=1e-9)
    assert res.weighted and res.loss == "linear" and res.objective_label == "SSE weighted by per-sample weights"


@pytest.mark.parametrize("loss", ["soft_l1", "huber", "cauchy"])
def test_robust_linear_fit_satisfies_its_stationarity_condition(loss):
    a, b = _linear_problem()
    b[::17] += 5.0  # outliers
    f = 0.2
    w = np.random.default_rng(2).uniform(0.5, 2, b.size)
    res = _fit_linear(a, b, loss=loss, f_scale=f, weights=w)
    # d/dtheta sum f^2 rho(w r^2 / f^2) = 2 sum rho'(z) w r a_i, with rho' by differences
    r = a @ res.theta - b
    z = w * r ** 2 / f ** 2
    drho = (_rho(z * (1 + 1e-7), loss) - _rho(z * (1 - 1e-7), loss)) / (2e-7 * z)
    gradient = 2 * a.T @ (drho * w * r)
    scale = 2 * np.abs(a).T @ np.abs(drho * w * r)  # the size of the terms that cancel
    assert np.all(np.abs(gradient) < 1e-6 * scale)
    assert res.objective == pytest.approx(_robust(r, loss, f, w), rel=1e-9)
    assert res.cost == pytest.approx(float(r @ r), rel=1e-12)


def test_objective_matches_scipy_definitions():
    r = np.array([0.1, -0.5, 2.0, -3.0])
    w = np.array([1.0, 0.5, 2.0, 0.0])
    for loss in ("linear", "soft_l1", "huber", "cauchy"):
        assert objective(r, loss, 0.7, w) == pytest.approx(
            _robust(r, loss, 0.7, w) if loss != "linear" else float(w @ r ** 2), rel=1e-14)


@pytest.mark.parametrize(("options", "match"), [
    ({"loss": "l1"}, "loss must be one of"),
    ({"loss": "huber", "f_scale": 0.0}, "f_scale must be a positive"),
    ({"loss": "huber", "f_scale": np.nan}, "f_scale must be a positive"),
    ({"weights": np.ones(199)}, r"one entry per residual entry \(200\)"),
    ({"weights": -np.ones(200)}, "entry 0 is -1.0"),
    ({"weights": np.r_[np.ones(5), np.nan, np.ones(194)]}, "entry 5 is nan"),
    ({"weights": np.zeros(200)}, "must not all be zero"),
])
def test_bad_cost_options_are_refused(options, match):
    a, b = _linear_problem()
    with pytest.raises(ValueError, match=match):
        _fit_linear(a, b, **options)


# --- the mPL family: known parameters, spikes -----------------------------------------------

STRUCTURE = mpl.MplStructure(n_cells=1, dt=0.025, slope_cap=1.0)
TRUE = mpl.MplParams(i_s=np.array([0.1]), v_t=np.array([0.2]), w=np.array([1.0, 0.4]),
                     v_b=-0.6)  # paper 9.1's initial values


@pytest.fixture(scope="module")
def spiky():
    """Data from known parameters with 0.5 % noise and 2 % spikes of a quarter of the range."""
    t = np.arange(3000) * STRUCTURE.dt
    u = np.sin(2 * np.pi * 0.1 * t) * np.minimum(1.0, 0.2 + t / 40)
    clean = mpl.simulate(STRUCTURE, TRUE, u)[0]
    rng = np.random.default_rng(3)
    noisy = clean + 0.005 * rng.standard_normal(u.size)
    spikes = rng.choice(u.size, u.size // 50, replace=False)
    y = noisy.copy()
    y[spikes] += rng.choice([-1.0, 1.0], spikes.size) * 0.5 * np.max(np.abs(clean))
    return {"u": u, "y": y, "noisy": noisy, "clean": clean, "spikes": spikes}


def _theta_error(result) -> float:
    return float(np.max(np.abs(result.params.to_vector() - TRUE.to_vector())))


def test_unit_weights_reach_the_unweighted_optimum(spiky):
    plain = mpl_fit.fit_mpl(spiky["u"], spiky["y"], STRUCTURE)
    ones = mpl_fit.fit_mpl(spiky["u"], spiky["y"], STRUCTURE, weights=np.ones(spiky["u"].size))
    assert ones.cost == pytest.approx(plain.cost, rel=1e-7)
    np.testing.assert_allclose(ones.params.to_vector(), plain.params.to_vector(), atol=1e-4)
    assert ones.objective == pytest.approx(ones.cost, rel=1e-12)


def test_robust_losses_recover_the_known_parameters_despite_spikes(spiky):
    # measured: linear 0.41 (log V_T off by 0.41), soft_l1 0.011, huber 0.0097, cauchy 0.0041
    errors = {loss: _theta_error(mpl_fit.fit_mpl(spiky["u"], spiky["y"], STRUCTURE, loss=loss,
                                                 f_scale=0.02))
              for loss in ("linear", "soft_l1", "huber", "cauchy")}
    assert errors["linear"] > 0.2
    for loss in ("soft_l1", "huber", "cauchy"):
        assert errors[loss] < 0.03, errors
        assert errors[loss] < errors["linear"] / 10, errors


@pytest.mark.parametrize("loss", ["linear", "huber", "cauchy"])
def test_returned_optimum_is_stationary_for_the_weighted_robust_objective(spiky, loss):
    u, y = spiky["u"], spiky["y"]
    w = np.random.default_rng(4).uniform(0.2, 1.0, u.size)
    f = 0.02
    res = mpl_fit.fit_mpl(u, y, STRUCTURE, loss=loss, f_scale=f, weights=w)

    def cost(theta):
        params = mpl.MplParams.from_vector(theta, STRUCTURE.n_cells)
        return _robust(mpl.simulate(STRUCTURE, params, u)[0] - y, loss, f, w)

    def gradient(theta):
        steps = 1e-6 * np.maximum(1.0, np.abs(theta))
        return np.array([(cost(theta + e) - cost(theta - e)) / (2 * e[i])
                         for i, e in enumerate(np.diag(steps))])

    theta = res.params.to_vector()
    assert res.objective == pytest.approx(cost(theta), rel=1e-8)
    lower, upper = res.bounds
    g = gradient(theta)
    # projected: a coordinate on a bound may keep a gradient pointing out of the box
    g[(theta <= lower + 1e-8) & (g > 0)] = 0.0
    g[(theta >= upper - 1e-8) & (g < 0)] = 0.0
    # the same objective's gradient at the unweighted SSE fit, which is not its minimum
    g_sse = gradient(mpl_fit.fit_mpl(u, y, STRUCTURE).params.to_vector())
    assert np.linalg.norm(g) < 1e-4 * np.linalg.norm(g_sse)


def test_zero_weight_on_the_spikes_recovers_the_clean_fit(spiky):
    u = spiky["u"]
    w = np.ones(u.size)
    w[spiky["spikes"]] = 0.0
    dropped = mpl_fit.fit_mpl(u, spiky["y"], STRUCTURE, weights=w)
    # what the spiked samples hold does not matter: the spike-free data give the same fit
    same = mpl_fit.fit_mpl(u, spiky["noisy"], STRUCTURE, weights=w)
    np.testing.assert_allclose(dropped.params.to_vector(), same.params.to_vector(), atol=1e-6)
    # and it is the fit of the spike-free data within the noise (linear on spikes: 0.41)
    clean_fit = mpl_fit.fit_mpl(u, spiky["noisy"], STRUCTURE)
    np.testing.assert_allclose(dropped.params.to_vector(), clean_fit.params.to_vector(),
                               atol=5e-3)
    assert _theta_error(dropped) < 0.01


@pytest.mark.parametrize("cells", [1, 2])
def test_a_weighted_fit_on_normal_equations_reaches_scipys_trf_optimum(spiky, cells):
    """Weights keep the default solver (normal equations of the sqrt(w)-scaled residual and
    Jacobian): the same weighted minimum as scipy's trf on that residual, in fewer runs."""
    u = spiky["u"]
    w = np.ones(u.size)
    w[spiky["spikes"]] = 0.0
    structure = mpl.MplStructure(n_cells=cells, dt=STRUCTURE.dt, slope_cap=1.0)
    tr = mpl_fit.fit_mpl(u, spiky["y"], structure, weights=w)
    trf = mpl_fit.fit_mpl(u, spiky["y"], structure, weights=w, solver="trf")
    assert tr.converged and trf.converged and tr.weighted
    assert tr.objective == pytest.approx(trf.objective, rel=1e-7)
    simulated = [mpl.simulate(structure, r.params, u)[0] for r in (tr, trf)]
    np.testing.assert_allclose(*simulated, atol=1e-4 * np.ptp(spiky["clean"]))
    assert tr.n_evaluations < trf.n_evaluations


# --- the linear-least-squares families: weights by row scaling --------------------------------

LINEAR_FAMILIES = ["preisach", "gpreisach", "bobbio", "pi"]


@pytest.fixture(scope="module")
def loop_data():
    t = np.arange(1500) * 0.025
    u = np.sin(2 * np.pi * 0.2 * t) * (0.5 + 0.5 * np.sin(2 * np.pi * 0.01 * t))
    y = np.tanh(1.5 * u) + 0.1 * np.sin(2 * np.pi * 0.2 * t - 0.5)
    return u, y / np.max(np.abs(y))


def _family_fit(name, u, y, **options):
    from hystkit.models import get_family

    family = get_family(name)
    return family.fit(u, y, family.make_structure(0.025, family.default_size), **options)


@pytest.mark.parametrize("name", LINEAR_FAMILIES)
def test_linear_family_equal_weights_give_the_unweighted_fit(name, loop_data):
    u, y = loop_data
    plain = _family_fit(name, u, y)
    scaled = _family_fit(name, u, y, weights=np.full(u.size, 3.0))
    assert scaled.cost == pytest.approx(plain.cost, rel=1e-9)
    assert scaled.objective == pytest.approx(3.0 * plain.cost, rel=1e-9)


@pytest.mark.parametrize("name", LINEAR_FAMILIES)
def test_linear_family_ignores_the_targets_of_zero_weight_samples(name, loop_data):
    u, y = loop_data
    w = np.ones(u.size)
    w[::7] = 0.0
    moved = y.copy()
    moved[::7] *= 0.5  # inside the range: PI's output thresholds stay
    a, b = _family_fit(name, u, y, weights=w), _family_fit(name, u, moved, weights=w)
    assert a.objective == pytest.approx(b.objective, rel=1e-8)
    assert a.objective < a.cost  # the zero-weight samples' misfit is in the SSE only


def test_preisach_integer_weights_equal_repeated_rows(loop_data):
    from hystkit.models.preisach import fit as pfit
    from hystkit.models.preisach import model as pmodel

    u, y = loop_data
    levels = 6
    a = np.column_stack([pmodel.cell_regressors(levels, u), np.ones(u.size)])
    d = pfit.smoothness_rows(levels)
    penalty = np.column_stack([d, np.zeros(d.shape[0])]) * np.sqrt(1e-3 * u.size)
    rows, cols = np.tril_indices(levels - 1)
    hysteretic, nonneg = np.r_[rows != cols, False], np.r_[np.ones(rows.size, bool), False]
    w = np.random.default_rng(5).integers(0, 3, u.size).astype(float)

    def solve(a, y, penalty, weights=None):
        return pfit.fit_oriented(a, y, penalty, hysteretic, nonneg, "auto", lambda c: c, None,
                                 None, "", weights).params

    repeat = w.astype(int)
    expected = solve(np.repeat(a, repeat, axis=0), np.repeat(y, repeat),
                     penalty * np.sqrt(repeat.sum() / u.size))
    np.testing.assert_allclose(solve(a, y, penalty, w), expected, atol=1e-8)


@pytest.mark.parametrize("name", LINEAR_FAMILIES)
def test_linear_family_refuses_a_robust_loss(name, loop_data):
    u, y = loop_data
    with pytest.raises(InputError, match=f"model '{name}' fits by .*least squares; the huber "
                                         f"loss is not available"):
        _family_fit(name, u, y, loss="huber")


# --- variable projection: the ladder (robust projection) and PL (weighted projection) --------

@pytest.fixture(scope="module")
def ladder_data():
    from hystkit.models import get_family
    from hystkit.models.ladder import model as ladder

    family = get_family("ladder")
    structure = family.make_structure(0.025, 2)
    rng = np.random.default_rng(1)
    t = np.arange(4000) * 0.025
    u = np.sin(2 * np.pi * 0.1 * t) * np.minimum(1.0, 0.2 + t / 40)
    clean = ladder.simulate(structure, family.random_params(structure, rng), u)[0]
    clean /= np.max(np.abs(clean))
    spikes = rng.choice(u.size, u.size // 50, replace=False)
    y = clean.copy()
    y[spikes] += rng.choice([-1.0, 1.0], spikes.size) * 0.5
    return structure, u, y, clean


def _ladder_output(structure, params, u):
    from hystkit.models.ladder import model as ladder

    return ladder.simulate(structure, params, u)[0]


def test_ladder_robust_losses_ignore_spikes(ladder_data):
    from hystkit.models.ladder import fit as ladder_fit

    structure, u, y, clean = ladder_data
    rms = {}
    for loss in ("linear", "huber", "cauchy"):
        res = ladder_fit.fit_ladder(u, y, structure, loss=loss, f_scale=0.02)
        rms[loss] = float(np.sqrt(np.mean((_ladder_output(structure, res.params, u) - clean)
                                          ** 2)))
    # measured: linear 4.1e-3, huber 1.8e-4, cauchy 5.9e-6 (RMS error against the clean run)
    assert rms["huber"] < rms["linear"] / 10 and rms["cauchy"] < rms["linear"] / 10, rms


def test_ladder_weighted_robust_optimum_is_stationary_in_every_parameter(ladder_data):
    """The projection's weights and bias minimise the same cost as the outer solver, so the
    whole parameter vector (bands, conductances, weights, bias) is stationary."""
    from hystkit.compensation._param_vector import flatten_params
    from hystkit.models.ladder import fit as ladder_fit

    structure, u, y, _ = ladder_data
    w = np.random.default_rng(6).uniform(0.2, 1.0, u.size)
    f = 0.02
    res = ladder_fit.fit_ladder(u, y, structure, loss="huber", f_scale=f, weights=w)
    plain = ladder_fit.fit_ladder(u, y, structure)

    def gradient(params):
        vector, rebuild = flatten_params(params)

        def cost(v):
            return _robust(_ladder_output(structure, rebuild(v), u) - y, "huber", f, w)

        steps = 1e-6 * np.maximum(1.0, np.abs(vector))
        return vector, np.array([(cost(vector + e) - cost(vector - e)) / (2 * e[i])
                                 for i, e in enumerate(np.diag(steps))])

    vector, g = gradient(res.params)
    n = structure.n_cells
    free = np.ones(vector.size, bool)
    free[:n] = vector[:n] > 1e-9  # a band on its lower bound (0) may keep a gradient
    _, g_plain = gradient(plain.params)
    assert np.linalg.norm(g[free]) < 1e-4 * np.linalg.norm(g_plain[free])


def test_pl_weights_scale_invariance_and_zero_weight_targets():
    from hystkit.models import get_family
    from hystkit.models.pl import fit as pl_fit
    from hystkit.models.pl import model as pl

    family = get_family("pl")
    structure = family.make_structure(0.025, 2)
    t = np.arange(2000) * 0.025
    u = np.sin(2 * np.pi * 0.1 * t) * np.minimum(1.0, 0.2 + t / 20)
    y = pl.simulate(structure, family.random_params(structure, np.random.default_rng(2)), u)[0]
    y /= np.max(np.abs(y))
    starts = pl_fit.default_starts(structure)[:4]
    plain = pl_fit.fit_pl(u, y, structure, starts=starts)
    scaled = pl_fit.fit_pl(u, y, structure, starts=starts, weights=np.full(u.size, 4.0))
    assert scaled.cost == pytest.approx(plain.cost, rel=1e-6)
    w = np.ones(u.size)
    w[500:700] = 0.0
    moved = y.copy()
    moved[500:700] = y[500:700][::-1]
    a = pl_fit.fit_pl(u, y, structure, starts=starts, weights=w)
    b = pl_fit.fit_pl(u, moved, structure, starts=starts, weights=w)
    assert a.objective == pytest.approx(b.objective, rel=1e-8)
    assert a.cost != pytest.approx(b.cost, rel=1e-4)


@pytest.mark.parametrize("loss", ["soft_l1", "huber"])
def test_irls_and_trust_region_reach_the_same_convex_minimum(loss):
    from hystkit.identification import robust_linear_fit

    a, b = _linear_problem()
    b[::13] -= 4.0
    w = np.random.default_rng(7).uniform(0.5, 2, b.size)
    irls = robust_linear_fit(a, b, loss, 0.3, w)
    trf = _fit_linear(a, b, loss=loss, f_scale=0.3, weights=w).theta
    np.testing.assert_allclose(irls, trf, rtol=1e-6)


# Not boucwen: its search box and starts come from all of y (amplitude, linear-oscillator
# starts), so even zero-weight targets shape where it searches.
@pytest.mark.parametrize("name", ["mpl", "mpl-g", "mpl-poly", "pl", "chua", "ladder"])
def test_every_iterative_family_ignores_the_targets_of_zero_weight_samples(name, loop_data):
    """Weights reach each family's cost aligned with its samples: reversing the targets of a
    zero-weight block changes neither the fit nor its minimised cost, under a robust loss."""
    u, y = loop_data
    w = np.ones(u.size)
    w[600:800] = 0.0
    moved = y.copy()
    moved[600:800] = y[600:800][::-1]
    a, b = (_family_fit(name, u, target, loss="soft_l1", f_scale=0.05, weights=w)
            for target in (y, moved))
    assert a.loss == "soft_l1" and a.weighted
    assert a.objective == pytest.approx(b.objective, rel=1e-7)
    assert a.cost != pytest.approx(b.cost, rel=1e-5)


def test_boucwen_robust_losses_ignore_spikes():
    from hystkit.models import get_family

    family = get_family("boucwen")
    structure = family.make_structure(0.025, family.default_size)
    t = np.arange(2000) * 0.025
    u = np.sin(2 * np.pi * 0.2 * t) * (0.5 + 0.5 * np.sin(2 * np.pi * 0.02 * t))
    clean = family.simulate(structure, family.random_params(structure,
                                                            np.random.default_rng(3)), u)[0]
    clean /= np.max(np.abs(clean))
    rng = np.random.default_rng(4)
    spikes = rng.choice(u.size, u.size // 50, replace=False)
    y = clean.copy()
    y[spikes] += rng.choice([-1.0, 1.0], spikes.size) * 0.5
    rms = {}
    for loss in ("linear", "huber", "cauchy"):
        res = family.fit(u, y, structure, loss=loss, f_scale=0.02)
        assert res.loss == loss
        out = family.simulate(structure, res.params, u)[0]
        rms[loss] = float(np.sqrt(np.mean((out - clean) ** 2)))
    # measured: linear 3.0e-3, huber 1.2e-4, cauchy 5.0e-6 (RMS error against the clean run)
    assert rms["huber"] < rms["linear"] / 10 and rms["cauchy"] < rms["linear"] / 10, rms
