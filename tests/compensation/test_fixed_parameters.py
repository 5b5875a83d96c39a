"""Parameters a family's fit holds fixed (``Family.fixed_params``, a gauge): the standard errors
leave them out and call them fixed, not undetermined (issue 14, review sec. 7)."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from hystkit.compensation import fit_compensator
from hystkit.compensation._chunked_errors import chunked_standard_errors
from hystkit.compensation._diagnostics import fixed_mask, parameter_names, standard_errors
from hystkit.compensation._param_vector import flatten_params
from hystkit.models import get_family
from hystkit.models.mpl_g.fit import canonical
from hystkit.sensors import simulate_experiment


@pytest.fixture(scope="module")
def mpl_g_fit():
    return fit_compensator(simulate_experiment("noise", 1), 2, model="mpl-g")


def test_an_mpl_g_fit_has_no_undetermined_parameter(mpl_g_fit):
    se = mpl_g_fit.fit_info["standard_errors"]
    names = parameter_names(mpl_g_fit.params)
    assert se["fixed"] == ["w[0]", "v_b"]
    # the fit's gauge: the stored values are the ones it holds
    assert se["values"][names.index("w[0]")] == 1.0 and se["values"][names.index("v_b")] == 0.0
    undetermined = [n for n, s in zip(names, se["standard_errors"], strict=True)
                    if s is None and n not in se["fixed"]]
    assert undetermined == []
    assert [s is None for s in se["standard_errors"]] == [n in se["fixed"] for n in names]
    # the information criteria count the 3N + 4 fitted numbers, as family.n_params says
    assert mpl_g_fit.fit_info["n_params"] == mpl_g_fit.family.n_params(
        mpl_g_fit.structure, mpl_g_fit.params) == 10


def _mpl_g_problem(n: int = 1500):
    family = get_family("mpl-g")
    structure = family.make_structure(0.025, 2)
    # seed 5: cells in their working range (other draws saturate a cell, which the data then
    # leave undetermined: a property of the draw, not of the gauge)
    params = canonical(family.random_params(structure, np.random.default_rng(5)))
    t = np.arange(n) * 0.025
    u = 0.8 * np.sin(2 * np.pi * 0.3 * t) * np.cos(2 * np.pi * 0.05 * t)
    y = family.simulate(structure, params, u)[0] \
        + 1e-3 * np.random.default_rng(5).standard_normal(n)
    return family, structure, params, u, y


def test_fixed_errors_are_those_of_the_free_parameters_alone():
    """Independent route: the forward-difference Jacobian of the free parameters only, and
    s^2 (J^T J)^-1 by a plain matrix inverse (not the SVD), s^2 = SSE / (n - p_free)."""
    family, structure, params, u, y = _mpl_g_problem()
    fixed = fixed_mask(family, structure, params)
    assert fixed.sum() == 2
    se = standard_errors(lambda q: family.simulate(structure, q, u)[0] - y, params, u.size,
                         fixed)
    theta, rebuild = flatten_params(params)
    r0 = family.simulate(structure, params, u)[0] - y
    columns = []
    for j in np.flatnonzero(~fixed):
        h = 1e-6 * max(abs(theta[j]), 1e-3)
        shifted = theta.copy()
        shifted[j] += h
        columns.append((family.simulate(structure, rebuild(shifted), u)[0] - y - r0) / h)
    jac = np.column_stack(columns)
    covariance = (r0 @ r0) / (u.size - jac.shape[1]) * np.linalg.inv(jac.T @ jac)
    got = np.array([s for s, f in zip(se["standard_errors"], fixed, strict=True) if not f])
    # same Jacobian; inverse and SVD agree to ~cond * eps
    assert_allclose(got, np.sqrt(np.diag(covariance)), rtol=1e-6)
    assert [s for s, f in zip(se["standard_errors"], fixed, strict=True) if f] == [None, None]


@pytest.mark.parametrize("chunk", [97, 100_000])
def test_chunked_equals_dense_with_fixed_parameters(chunk):
    family, structure, params, u, y = _mpl_g_problem()
    dense = standard_errors(lambda q: family.simulate(structure, q, u)[0] - y, params, u.size,
                            fixed_mask(family, structure, params))
    chunked = chunked_standard_errors(family, structure, params, [u], [y], chunk=chunk)
    assert chunked["fixed"] == dense["fixed"] == ["w[0]", "v_b"]
    assert [s is None for s in chunked["standard_errors"]] == \
        [s is None for s in dense["standard_errors"]]
    finite = [i for i, s in enumerate(dense["standard_errors"]) if s is not None]
    assert_allclose([chunked["standard_errors"][i] for i in finite],
                    [dense["standard_errors"][i] for i in finite], rtol=1e-8)


def test_a_two_recording_fit_keeps_the_gauge():
    """The joint polish over several recordings refits the free parameters only."""
    recs = [simulate_experiment("noise", 1), simulate_experiment("noise", 2)]
    comp = fit_compensator(recs, 1, model="mpl-g", diagnose=False)
    # the polish moved the model (else this test would check nothing)
    assert comp.fit_info["joint_fit"].startswith("joint polish over 2 recordings")
    assert comp.params.w[0] == 1.0 and comp.params.v_b == 0.0


def test_families_hold_nothing_fixed_by_default():
    family = get_family("mpl")
    structure = family.make_structure(0.025, 2)
    params = family.random_params(structure, np.random.default_rng(0))
    assert family.fixed_params(structure, params) == ()
    assert not fixed_mask(family, structure, params).any()


def test_an_unknown_fixed_name_is_a_programming_error(monkeypatch):
    family = get_family("mpl-g")
    structure = family.make_structure(0.025, 1)
    params = family.random_params(structure, np.random.default_rng(0))
    monkeypatch.setattr(type(family), "fixed_params", lambda self, s, p: ("w0",))
    with pytest.raises(ValueError, match=r"mpl-g.fixed_params names \['w0'\]"):
        fixed_mask(family, structure, params)
