"""The bounded least-squares solve of the Preisach-family fits: scipy's nnls, checked by the KKT
conditions, with BVLS as the fallback (``preisach.fit.bounded_lstsq``).

Objectives are compared at ``rel=1e-12``: both solvers stop at a point that satisfies the KKT
conditions of the same convex problem to within rounding, so their minima agree to the
rounding of ``||r x - b||^2`` (~``p eps``, 1e-14 here; 4e-16 seen), not just approximately.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from scipy.optimize import lsq_linear
from scipy.optimize import nnls as scipy_nnls

from hystkit.models import get_family
from hystkit.models.preisach import fit as pfit
from hystkit.sensors import simulate_experiment

N_FIT = 1600


def _bvls(r, b, nonneg):
    """The solve before nnls, as ``bounded_lstsq`` falls back to it."""
    sol = lsq_linear(r, b, bounds=(np.where(nonneg, 0.0, -np.inf), np.inf), method="bvls",
                     tol=1e-12)
    return np.where(nonneg, np.maximum(sol.x, 0.0), sol.x)


def _objective(r, b, x):
    d = r @ x - b
    return float(d @ d)


def _problem(seed: int, p: int = 40, n_free: int = 8, rank: int | None = None):
    """A reduced (square, triangular) problem with mixed free and non-negative columns whose
    unconstrained solution has many negative entries (so many bounds are active)."""
    rng = np.random.default_rng(seed)
    a = rng.standard_normal((2 * p, p))
    if rank is not None:  # repeat columns and zero one: rank-deficient
        a[:, rank:] = a[:, rng.integers(0, rank, p - rank)]
        a[:, -1] = 0.0
    r = np.linalg.qr(np.column_stack([a, rng.standard_normal(2 * p)]), mode="r")
    nonneg = np.ones(p, bool)
    nonneg[rng.choice(p, n_free, replace=False)] = False
    return r[:p, :p], r[:p, p], nonneg


def test_kkt_holds_on_a_problem_solved_by_hand():
    # min ||x - (-1, 2)||: with x >= 0 the answer is (0, 2) (gradient (1, 0): points inwards)
    r, b = np.eye(2), np.array([-1.0, 2.0])
    both = np.array([True, True])
    assert pfit.kkt_holds(r, b, np.array([0.0, 2.0]), both)
    for wrong in ([0.5, 2.0], [0.0, 1.9], [-1.0, 2.0], [np.nan, 2.0]):
        assert not pfit.kkt_holds(r, b, np.array(wrong), both)
    # the first entry free: its gradient must vanish, so (0, 2) is no longer the answer
    first_free = np.array([False, True])
    assert pfit.kkt_holds(r, b, np.array([-1.0, 2.0]), first_free)
    assert not pfit.kkt_holds(r, b, np.array([0.0, 2.0]), first_free)


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("n_free", [0, 1, 8])
def test_nnls_agrees_with_bvls_on_random_problems(seed, n_free):
    r, b, nonneg = _problem(seed, n_free=n_free)
    x, message, success = pfit.bounded_lstsq(r, b, nonneg)
    assert success and message.startswith("nnls")
    expected = _bvls(r, b, nonneg)
    assert np.sum(expected == 0.0) >= 5  # the bounds matter
    assert _objective(r, b, x) == pytest.approx(_objective(r, b, expected), rel=1e-12)
    # full rank: one minimiser, so the answers agree too
    assert_allclose(x, expected, rtol=0, atol=1e-10)
    assert np.all(x[nonneg] >= 0.0)


@pytest.mark.parametrize("seed", range(3))
def test_rank_deficient_problem_reaches_the_same_minimum(seed):
    r, b, nonneg = _problem(seed, rank=25)
    x, message, success = pfit.bounded_lstsq(r, b, nonneg)
    assert success and message.startswith("nnls") and pfit.kkt_holds(r, b, x, nonneg)
    # repeated columns: many minimisers, one minimum
    assert _objective(r, b, x) == pytest.approx(_objective(r, b, _bvls(r, b, nonneg)),
                                                rel=1e-12)


def test_all_zero_target_gives_zero_weights():
    rng = np.random.default_rng(3)
    a = rng.standard_normal((200, 30))
    a[:, 10:20] = a[:, :10]  # rank-deficient
    a[:, 20] = 0.0
    nonneg = np.r_[np.ones(29, bool), False]
    x, message, success = pfit.solve_regularised(a, np.zeros(200), np.zeros((0, 30)), nonneg)
    assert success and message.startswith("nnls")
    assert_array_equal(x, np.zeros(30))


def _moved(z):
    """A positive entry moved off its optimum: a non-zero gradient where it must vanish."""
    z = z.copy()
    z[np.argmax(z)] *= 1.0 + 1e-6
    return z


def _dropped(z):
    """A positive entry set to 0 (scipy issue 25389's kind): on its bound, gradient outwards."""
    z = z.copy()
    z[np.argmax(z)] = 0.0
    return z


@pytest.mark.parametrize("spoil", [_moved, _dropped])
def test_a_wrong_nnls_answer_falls_back_to_bvls(monkeypatch, spoil):
    r, b, nonneg = _problem(1, n_free=8)
    monkeypatch.setattr(pfit, "nnls",
                        lambda a, rhs: (spoil(scipy_nnls(a, rhs)[0]), 0.0))
    x, message, success = pfit.bounded_lstsq(r, b, nonneg)
    assert message.startswith("bvls (nnls failed the optimality check): ") and success
    assert_array_equal(x, _bvls(r, b, nonneg))


def test_nnls_at_its_iteration_limit_falls_back_to_bvls(monkeypatch):
    r, b, nonneg = _problem(2, n_free=1)

    def gives_up(a, rhs):
        raise RuntimeError("Maximum number of iterations reached.")

    monkeypatch.setattr(pfit, "nnls", gives_up)
    x, message, success = pfit.bounded_lstsq(r, b, nonneg)
    assert message.startswith("bvls (nnls: Maximum number of iterations reached.): ")
    assert success
    assert_array_equal(x, _bvls(r, b, nonneg))


@functools.cache
def _data():
    """The family contract test's data: sensor -> position on the virtual noise run."""
    rec = simulate_experiment("noise", 1)
    s = rec.sensor[:N_FIT] - rec.sensor[:N_FIT].mean()
    p = rec.position[:N_FIT] - rec.position[:N_FIT].mean()
    return rec.dt, s / np.max(np.abs(s)), p / np.max(np.abs(p))


def _failing_nnls(a, rhs):
    raise RuntimeError("forced")


@pytest.mark.parametrize("name", ["preisach", "gpreisach"])
def test_family_fit_is_the_bvls_fit(monkeypatch, name):
    family = get_family(name)
    dt, s, p = _data()
    structure = family.make_structure(dt, family.default_size)
    new = family.fit(s, p, structure)
    monkeypatch.setattr(pfit, "nnls", _failing_nnls)
    old = family.fit(s, p, structure)
    assert "nnls (scipy), optimality checked" in new.message
    assert "bvls (nnls: forced)" in old.message
    assert new.converged and old.converged
    assert new.cost == pytest.approx(old.cost, rel=1e-12)
    for field in ("everett", "everett_minus", "everett_plus", "nu", "offset"):
        if hasattr(new.params, field):
            assert_allclose(getattr(new.params, field), getattr(old.params, field),
                            rtol=0, atol=1e-10)
