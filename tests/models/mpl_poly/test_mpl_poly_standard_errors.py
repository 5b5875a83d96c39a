"""An mpl-poly fit declares its gauge (``c_k0``, ``w_0``, ``V_b``) fixed, so the data determine
every other parameter and the standard errors are finite (issue 25 item 3)."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from hystkit.compensation import fit_compensator
from hystkit.compensation._diagnostics import fixed_mask, parameter_names
from hystkit.compensation._param_vector import flatten_params
from hystkit.models import get_family
from hystkit.models.mpl_poly.fit import canonical
from hystkit.sensors import simulate_experiment

FAMILY = get_family("mpl-poly")


@pytest.fixture(scope="module")
def default_fit():
    return fit_compensator(simulate_experiment("sine", 1), model="mpl-poly")


def test_a_default_fit_has_finite_standard_errors(default_fit):
    comp = default_fit
    se = comp.fit_info["standard_errors"]
    names = parameter_names(comp.params)
    assert comp.structure.n_cells == FAMILY.default_size == 1
    assert se["fixed"] == ["f[0][0]", "w[0]", "v_b"]
    values = dict(zip(names, se["values"], strict=True))
    assert (values["f[0][0]"], values["w[0]"], values["v_b"]) == (0.0, 1.0, 0.0)  # the gauge
    errors = dict(zip(names, se["standard_errors"], strict=True))
    assert {n for n, s in errors.items() if s is None} == set(se["fixed"])
    assert all(np.isfinite(s) and s > 0 for n, s in errors.items() if n not in se["fixed"])
    # the information criteria count the 4N + 4 fitted numbers
    assert comp.fit_info["n_params"] == FAMILY.n_params(comp.structure, comp.params) == 8


def _compose(c: np.ndarray, inner: tuple[float, float]) -> np.ndarray:
    """Coefficients of the cubic ``c`` at ``inner[0] + inner[1] x``."""
    coef = np.polynomial.Polynomial(c)(np.polynomial.Polynomial(inner)).coef
    return np.pad(coef, (0, 4 - coef.size))


def _gauge(params, shifts, alpha: float, beta: float):
    """An equivalent model: each cell's state moved by ``shifts[k]`` (``f_k(v) -> f_k(v + s)``,
    ``V_b`` takes up ``w_k s``), then the output resistor's voltage ``z -> alpha z + beta``
    (``g`` re-expanded, ``w`` and ``V_b`` rescaled)."""
    f = np.array([_compose(c, (s, 1.0)) for c, s in zip(params.f, shifts, strict=True)])
    v_b = params.v_b + params.w[1:] @ shifts
    return FAMILY.Params(f=f, g=_compose(params.g, (-beta / alpha, 1 / alpha)),
                         w=alpha * params.w, v_b=alpha * v_b - beta)


def _model(n_cells: int, seed: int):
    structure = FAMILY.make_structure(0.025, n_cells)
    params = canonical(structure, FAMILY.random_params(structure, np.random.default_rng(seed)))
    t = np.arange(2000) * 0.025
    return structure, params, 0.8 * np.sin(2 * np.pi * 0.3 * t) * np.cos(2 * np.pi * 0.05 * t)


@pytest.mark.parametrize("n_cells", [1, 2])
def test_the_fixed_parameters_fix_the_whole_gauge(n_cells):
    """The N + 2 gauge directions leave the output unchanged, and the declared fixed
    parameters move along every one of them: holding them fixes the gauge."""
    structure, params, u = _model(n_cells, 0)
    y = FAMILY.simulate(structure, params, u)[0]
    other = _gauge(params, np.linspace(0.2, 0.4, n_cells), 1.5, 0.3)
    # an equivalent model: same output to rounding (the cubics re-expanded)
    assert_allclose(FAMILY.simulate(structure, other, u)[0], y, rtol=0, atol=1e-9)
    fixed = fixed_mask(FAMILY, structure, params)
    theta = flatten_params(params)[0]
    tangents = []  # d theta / d (shift_1 .. shift_N, log alpha, beta), central differences
    for k in range(n_cells + 2):
        h = 1e-5 * np.eye(n_cells + 2)[k]

        def at(d, h=h):
            return flatten_params(_gauge(params, d * h[:n_cells], np.exp(d * h[n_cells]),
                                         d * h[n_cells + 1]))[0]

        tangents.append((at(1) - at(-1)) / 2e-5)
    tangents = np.column_stack(tangents)
    assert_allclose(flatten_params(_gauge(params, np.zeros(n_cells), 1.0, 0.0))[0], theta)
    sv = np.linalg.svd(tangents[fixed], compute_uv=False)
    assert fixed.sum() == n_cells + 2 and sv.min() > 1e-3 * sv.max()


def test_the_free_parameters_are_determined():
    """Over the free parameters of a canonical model the Jacobian has full rank; over all
    5N + 6 numbers it has N + 2 null directions."""
    structure, params, u = _model(1, 0)
    fixed = fixed_mask(FAMILY, structure, params)
    every = np.linalg.svd(_jacobian(structure, params, u, range(fixed.size)), compute_uv=False)
    free = np.linalg.svd(_jacobian(structure, params, u, np.flatnonzero(~fixed)),
                         compute_uv=False)
    # forward differences (step 1e-6 relative): gauge directions at the differences' noise,
    # below the SE's cut-off 1e-8 (errors_from_factor); determined ones far above it
    assert np.all(every[-3:] / every[0] < 1e-7) and every[-4] / every[0] > 1e-6
    assert free.size == FAMILY.n_params(structure, params) and free.min() / free[0] > 1e-6


def _jacobian(structure, params, u, columns):
    theta, rebuild = flatten_params(params)
    y0 = FAMILY.simulate(structure, params, u)[0]
    out = []
    for j in columns:
        h = 1e-6 * max(abs(theta[j]), 1e-3)
        shifted = theta.copy()
        shifted[j] += h
        out.append((FAMILY.simulate(structure, rebuild(shifted), u)[0] - y0) / h)
    return np.column_stack(out)
