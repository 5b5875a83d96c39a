"""Linearisation and Euler stability of the mPL families (eq. 5.18-5.29) and ``hystkit
stability``."""

from __future__ import annotations

import json

import numpy as np
import pytest
from numpy.testing import assert_allclose

from hystkit.compensation import fit_compensator, save_compensator
from hystkit.errors import FitDivergedError
from hystkit.io import write_recording
from hystkit.models import _cells, family_of, mpl, mpl_poly
from hystkit.models.mpl_poly import PAPER_9_2_TABLE_II, paper_9_2_params
from hystkit.sensors import simulate_experiment
from hystkit.signals import exponential_chirp

from ..cli_support import run_cli

DT = 0.025


def _cells_of(structure, params) -> _cells.Cells:
    return family_of(structure).cells(structure, params)

POLY = (mpl_poly.MplPolyStructure(n_cells=2, dt=DT),
        mpl_poly.MplPolyParams(f=[[0.05, 1.5, 0.4, 2.0], [-0.1, 8.0, 1.0, 300.0]],
                               g=[0.02, 0.9, 0.05, 0.1], w=[1.2, -0.4, -0.3], v_b=0.03))
SINH = (mpl.MplStructure(n_cells=2, dt=DT),
        mpl.MplParams(i_s=[0.1, 0.02], v_t=[0.2, 0.05], w=[1.0, 0.4, -0.3], v_b=-0.6))
FAMILY_MODULES = {"mpl-poly": (POLY, mpl_poly), "mpl": (SINH, mpl)}
# operating points (e0, u0): v = 0, inside the knees, and beyond the knee of the steep cell
POINTS = [(0.3, np.array([0.3, 0.3])), (0.5, np.array([0.1, 0.45])),
          (-0.8, np.array([0.2, 0.4]))]


@pytest.mark.parametrize("family", sorted(FAMILY_MODULES))
@pytest.mark.parametrize("point", range(len(POINTS)))
def test_discrete_eigenvalues_are_one_minus_slope_dt_and_one(family, point):
    (structure, params), _ = FAMILY_MODULES[family]
    e0, u0 = POINTS[point]
    model = _cells.linearise(_cells_of(structure, params), e0, u0)
    a_d = model.discrete()[0]
    slope = _cells_of(structure, params).slope(e0 - u0)
    closed = np.r_[1 - slope * DT, 1.0]  # eq. 5.26 corrected: 1 - f'dt; the constant state: 1
    assert_allclose(_cells.discrete_eigenvalues(model), closed, rtol=0, atol=1e-15)
    # numpy agrees (A_d is triangular, so its eigenvalues are exact up to rounding)
    assert_allclose(np.sort(np.linalg.eigvals(a_d).real), np.sort(closed), rtol=0, atol=1e-12)
    # continuous A: -f'_k and 0 for the constant state
    assert_allclose(np.sort(np.linalg.eigvals(model.a).real), np.sort(np.r_[-slope, 0.0]),
                    atol=1e-12)


@pytest.mark.parametrize("family", sorted(FAMILY_MODULES))
@pytest.mark.parametrize("point", range(len(POINTS)))
def test_linear_model_is_the_jacobian_of_the_step_map(family, point):
    (structure, params), module = FAMILY_MODULES[family]
    e0, u0 = POINTS[point]
    a_d, b_d, c_d, d_d = _cells.linearise(_cells_of(structure, params), e0, u0).discrete()
    y0, x1 = module.step(structure, params, u0, e0)
    # affine, not only linear: the model reproduces the step at the operating point itself
    assert_allclose(a_d[:2] @ np.r_[u0, 1.0] + b_d[:2] * e0, x1, rtol=0, atol=1e-13)
    assert_allclose(c_d @ np.r_[u0, 1.0] + d_d * e0, y0, rtol=0, atol=1e-13)
    h = 1e-6
    jac_x = np.column_stack([(module.step(structure, params, u0 + h * d, e0)[1]
                              - module.step(structure, params, u0 - h * d, e0)[1]) / (2 * h)
                             for d in np.eye(2)])
    jac_y = np.array([(module.step(structure, params, u0 + h * d, e0)[0]
                       - module.step(structure, params, u0 - h * d, e0)[0]) / (2 * h)
                      for d in np.eye(2)])
    de_x = (module.step(structure, params, u0, e0 + h)[1]
            - module.step(structure, params, u0, e0 - h)[1]) / (2 * h)
    de_y = (module.step(structure, params, u0, e0 + h)[0]
            - module.step(structure, params, u0, e0 - h)[0]) / (2 * h)
    # central differences of smooth maps (the points avoid the knees): error ~h^2 + eps/h
    tol = {"rtol": 0, "atol": 1e-7}
    assert_allclose(a_d[:2, :2], jac_x, **tol)
    assert_allclose(b_d[:2], de_x, **tol)
    assert_allclose(c_d[:2], jac_y, **tol)
    assert_allclose(d_d, de_y, **tol)
    assert_allclose(a_d[2], [0.0, 0.0, 1.0])  # the augmented constant stays 1


def test_the_documents_eq_5_26_is_not_the_eigenvalue():
    """eq. 5.26 prints (1 - f') dt and 0; forward Euler gives 1 - f' dt and 1."""
    s = mpl_poly.MplPolyStructure(n_cells=1, dt=DT)
    p = mpl_poly.MplPolyParams(f=[[0.0, 2.0, 0.0, 1e-9]], g=[0.0, 1.0, 0.0, 0.0],
                               w=[1.0, -1.0])
    model = _cells.linearise(_cells_of(s, p), 0.0, np.zeros(1))
    eig = np.sort(np.linalg.eigvals(model.discrete()[0]).real)
    assert_allclose(eig, [1 - 2.0 * DT, 1.0], atol=1e-12)
    assert not np.any(np.isclose(eig, (1 - 2.0) * DT)) and not np.any(np.isclose(eig, 0.0))


@pytest.mark.parametrize(("slope_dt", "stable"), [(0.5, True), (1.8, True), (2.2, False)])
def test_criterion_eq_5_28_predicts_perturbation_growth(slope_dt, stable):
    # a linear cell f(v) = G v without the limit: a perturbation of the rest state is
    # multiplied by exactly 1 - G dt per sample, the eigenvalue
    s = mpl_poly.MplPolyStructure(n_cells=1, dt=DT, limit=False)
    p = mpl_poly.MplPolyParams(f=[[0.0, slope_dt / DT, 0.0, 1e-300]], g=[0.0, 1.0, 0.0, 0.0],
                               w=[0.0, 1.0])
    lam = _cells.discrete_eigenvalues(_cells.linearise(_cells_of(s, p), 0.0, np.zeros(1)))[0]
    y, _ = mpl_poly.simulate(s, p, np.zeros(40), x0=1e-3)
    assert_allclose(y, 1e-3 * lam ** np.arange(40), rtol=1e-12)
    assert (abs(lam) < 1) == stable == (0 < slope_dt < 2)


def test_sinh_slope_matches_finite_differences_inside_and_beyond_the_knee():
    structure, params = SINH
    knee = mpl.knee_voltage(structure, params)
    v = np.array([[-0.5 * knee[0], 0.3 * knee[1]], [2 * knee[0], -3 * knee[1]]])
    h = 1e-7
    fd = (mpl.resistor_current(structure, params, v + h)
          - mpl.resistor_current(structure, params, v - h)) / (2 * h)
    assert_allclose(_cells_of(structure, params).slope(v), fd, rtol=1e-6)
    assert_allclose(_cells_of(structure, params).slope(v)[1], 1 / DT)  # the cap


def test_report_of_a_limited_model_is_stable_everywhere():
    structure, params = POLY
    u = exponential_chirp(np.arange(4000) * DT, amplitude=1.0)
    report = _cells.cell_report(_cells_of(structure, params), u)
    assert report["stable_everywhere"] and report["n_violations"] == 0
    assert report["n_points"] == 4000 * 2 + 2  # two cells, one rest point each
    assert_allclose(report["knees"], mpl_poly.knee_points(structure, params))
    assert -1 < report["eigenvalue_min"] <= report["eigenvalue_max"] < 1
    assert report["eigenvalue_min"] == pytest.approx(0.0, abs=1e-12)  # steep cell at the cap
    json.dumps(report)  # plain JSON


def test_report_flags_the_repelling_middle_rest_point_of_a_bistable_cell():
    s = mpl_poly.MplPolyStructure(n_cells=1, dt=DT)
    p = mpl_poly.MplPolyParams(f=[[0.0, -4.0, 0.0, 4.0]], g=[0.0, 1.0, 0.0, 0.0],
                               w=[1.0, -1.0])
    report = _cells.cell_report(_cells_of(s, p), np.zeros(100))
    rest = report["rest"][0]
    assert_allclose(rest["v"], [-1.0, 0.0, 1.0], atol=1e-12)
    assert_allclose(rest["eigenvalue"], [1 - 8 * DT, 1 + 4 * DT, 1 - 8 * DT], atol=1e-12)
    assert not report["stable_everywhere"] and report["n_violations"] == 1


def test_report_refuses_a_diverging_unlimited_model():
    p = paper_9_2_params(PAPER_9_2_TABLE_II["chirp"])
    fast = exponential_chirp(np.arange(4000) * DT, f1=10.0, amplitude=1.0)
    with pytest.raises(FitDivergedError):
        _cells.cell_report(_cells_of(mpl_poly.MplPolyStructure(limit=False), p), fast)
    assert _cells.cell_report(_cells_of(mpl_poly.MplPolyStructure(), p), fast)["n_points"] == 4001


# --------------------------------------------------------------------------- CLI


@pytest.fixture(scope="module")
def model_files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("stability")
    rec = simulate_experiment("chirp", 1)
    files = {}
    for model in ("mpl", "mpl-poly"):
        files[model] = save_compensator(fit_compensator(rec, model=model), folder / f"{model}.json")
    files["recording"] = write_recording(rec, folder / "chirp.csv")
    return files


@pytest.mark.parametrize("model", ["mpl", "mpl-poly"])
def test_cli_prints_and_writes_the_analysis(model_files, model, tmp_path, capsys):
    out = tmp_path / "stability.json"
    code, stdout, stderr = run_cli(capsys, "stability", model_files[model], "--json", out)
    assert code == 0, stderr
    assert f": {model} (" in stdout and "1 state(s)" in stdout
    assert "knees x- = " in stdout and "augmented constant state has eigenvalue 1" in stdout
    assert "0 < f'·dt < 2 everywhere (eq. 5.28): yes" in stdout
    assert "eigenvalues of A: stable" in stdout
    report = json.loads(out.read_text())
    assert report["model"] == model and report["stable_everywhere"] is True
    details = report["details"]
    assert details["stable_everywhere"] is True
    assert len(details["knees"]) == 1 and details["trajectory"]["n_samples"] == 4000
    # one cell: the generic eigenvalue scan and eq. 5.26 agree on the largest |1 - f' dt|
    assert report["radius_max"] == pytest.approx(
        max(abs(details["eigenvalue_min"]), abs(details["eigenvalue_max"])), rel=1e-6)


def test_cli_uses_a_recording_as_the_probe(model_files, capsys):
    code, stdout, stderr = run_cli(capsys, "stability", model_files["mpl-poly"], "--data",
                                model_files["recording"])
    assert code == 0, stderr
    assert f"driven by {model_files['recording']}" in stdout


def test_cli_missing_model_file_is_one_line(tmp_path, capsys):
    code, _, stderr = run_cli(capsys, "stability", tmp_path / "missing.json")
    assert code == 2 and "file not found" in stderr
