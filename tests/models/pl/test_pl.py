"""Power-Law model as published (sec. 2.1.7, eq. 2.16-2.18): resistor shape, log-type creep,
kernels, inverse, weight fit, structural search (table 5.1) and its CLI."""

import json
from dataclasses import asdict

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from hystkit.cli._main import main
from hystkit.compensation import evaluate, fit_compensator
from hystkit.io import write_recording
from hystkit.models import get_family, pl
from hystkit.models.pl import fit_pl, format_search_table, structural_search
from hystkit.sensors import simulate_experiment

DT = 0.025
STRUCT = pl.PlStructure(n_cells=3, power=21.0, n_basis=4, dt=DT)
PARAMS = pl.PlParams(i_t=0.5, v_t=0.2, w=[0.8, 0.3, 0.5, -0.2], v_b=0.1, a=[0.5, 2.0, 1.0, 3.0])


def _input(n: int = 4000, seed: int = 0) -> np.ndarray:
    t = np.arange(n) * DT
    noise = np.random.default_rng(seed).standard_normal(n)
    return np.sin(np.pi * t) * np.exp(-t / 60) + 0.3 * np.sin(2.3 * t) + 0.03 * noise


def test_resistor_is_an_odd_power_law_inside_the_thresholds():
    thr = PARAMS.v_t * np.arange(1, 4)
    v = np.outer(np.linspace(-1, 1, 41), thr)  # each column within its own threshold
    d = pl.resistor_current(STRUCT, PARAMS, v)
    expected = PARAMS.i_t / 20 * np.sign(v) * np.abs(v / thr) ** 21  # eq. 2.16, p = 21
    assert_allclose(d, expected, rtol=1e-12, atol=0)  # the same formula, rounding only
    assert_array_equal(pl.resistor_current(STRUCT, PARAMS, -v), -d)  # odd


def test_resistor_is_continuous_at_the_thresholds_and_straight_beyond():
    thr = PARAMS.v_t * np.arange(1, 4)
    eps = 1e-9
    below = pl.resistor_current(STRUCT, PARAMS, thr * (1 - eps))
    above = pl.resistor_current(STRUCT, PARAMS, thr * (1 + eps))
    assert_allclose(above, below, rtol=0, atol=1e-6)  # a jump would be I_T / (p - 1) = 0.025
    g = STRUCT.slope_cap / DT
    far = pl.resistor_current(STRUCT, PARAMS, thr + 0.5)
    assert_allclose(far - pl.resistor_current(STRUCT, PARAMS, thr), g * 0.5, rtol=1e-12)


def test_steep_power_law_hands_over_to_the_capped_slope_at_the_knee():
    # I_T so large that the power law's slope would exceed G = cap/dt below the threshold:
    # the straight branch starts at the knee where the two slopes are equal (eq. 5.29 idea)
    structure = pl.PlStructure(n_cells=1, power=5.0, dt=DT)
    params = pl.PlParams(i_t=100.0, v_t=0.5, w=[1.0, 1.0])
    v = np.linspace(0, 1, 2001)
    slope = np.gradient(pl.resistor_current(structure, params, v[:, None])[:, 0], v)
    assert slope.max() <= structure.slope_cap / DT * (1 + 1e-3)  # finite-difference error
    # so the Euler step stays monotone and the cell never overshoots the input
    _, x = pl.simulate(structure, params, np.r_[np.zeros(5), np.full(200, 3.0)], x0=0.0)
    assert 0 <= x[0] <= 3.0


def test_creep_after_a_step_is_log_type():
    """Driving-point configuration (thresholds k V_T, fig. 2.17b): after a step each cell jumps
    to its threshold along the straight branch, then creeps along the power law,
    ``v_k(t) = k V_T (1 + t / tau_k)^(-1 / (p - 1))``: for ``t >> tau_k`` the log of the gap
    falls by ``ln 10 / (p - 1)`` per decade, so the output changes by nearly the same amount
    in every decade. Measured (p = 21, N = 5): 0.134, 0.136, 0.122, 0.109 per decade over
    1 s .. 10^4 s (exponential relaxation would be flat after a few time constants)."""
    structure = pl.PlStructure(n_cells=5, power=21.0, dt=DT)
    params = pl.PlParams(i_t=1.0, v_t=0.1, w=[0, 1, 1, 1, 1, 1])  # tau_k = k V_T / I_T <= 0.5 s
    t_out = np.array([1.0, 10.0, 100.0, 1000.0, 10000.0])
    y, _ = pl.simulate(structure, params, np.ones(int(t_out[-1] / DT) + 1), x0=0.0)
    per_decade = np.diff(y[np.round(t_out / DT).astype(int)])
    assert np.all(per_decade > 0)
    assert_allclose(per_decade, per_decade.mean(), rtol=0.2)  # constant within 20 % (4 decades)
    # an upper bound from the small-gap expansion: sum_k k V_T ln 10 / (p - 1)
    assert per_decade.max() < 1.5 * np.log(10) / 20


def test_kernel_matches_readable_reference():
    u = _input()
    y, x_end = pl.simulate(STRUCT, PARAMS, u)
    y_ref, x_ref = pl.simulate_reference(STRUCT, PARAMS, u)
    assert_allclose(x_end, x_ref, rtol=0, atol=1e-14)  # same Euler arithmetic, pow rounding
    assert_allclose(y, y_ref, rtol=0, atol=1e-13)  # f^-1 walks the segments in another order


def test_output_resistor_inverse_is_exact():
    i = np.linspace(-3, 3, 301)
    assert_allclose(pl.output_resistor_inverse(PARAMS, pl.output_resistor(PARAMS, i)), i,
                    rtol=0, atol=1e-14)


def test_inverse_undoes_forward():
    u = _input()
    y, _ = pl.simulate(STRUCT, PARAMS, u)
    e_hat, _ = pl.invert(STRUCT, PARAMS, y, x0=np.full(3, u[0]))
    assert_allclose(e_hat, u, rtol=0, atol=1e-12)  # closed-form f, then eq. 2.20


def test_recovers_known_weights_for_a_fixed_structure():
    structure = pl.PlStructure(n_cells=2, power=5.0, n_basis=3, smoothing=0.0, dt=DT)
    # scale fixed as in the fit: mean slope of f equal to 1 (sum a_j = M)
    true = pl.PlParams(i_t=0.3, v_t=0.35, w=[0.6, 0.5, -0.3], v_b=0.05, a=[0.8, 1.0, 1.2])
    u = _input(3000)
    y, _ = pl.simulate(structure, true, u)
    fit = fit_pl(u, y, structure)
    p = fit.params
    assert fit.cost / np.sum(y**2) < 1e-8  # noise-free data: essentially exact
    assert_allclose([p.i_t, p.v_t], [true.i_t, true.v_t], rtol=1e-2)
    assert_allclose(p.w, true.w, atol=1e-2)
    assert_allclose(p.a, true.a, atol=1e-2)
    assert p.v_b == pytest.approx(true.v_b, abs=1e-2)


def test_structural_search_finds_the_true_structure_or_better():
    true_structure = pl.PlStructure(n_cells=2, power=5.0, n_basis=1, dt=DT)
    true = pl.PlParams(i_t=0.3, v_t=0.35, w=[0.6, 0.5, -0.3], v_b=0.0)
    u = _input(2000)
    y, _ = pl.simulate(true_structure, true, u)
    rows = structural_search(u, y, DT, {"n": (1, 2), "p": (5.0, 21.0), "m": (1,), "s": (0.001,)})
    assert len(rows) == 4
    true_row = next(r for r in rows if r["n_cells"] == 2 and r["power"] == 5.0)
    best = min(rows, key=lambda r: r["e_rms_pct"])
    assert true_row["e_rms_pct"] < 0.01  # the true structure refits its own data
    assert best["e_rms_pct"] <= true_row["e_rms_pct"]
    assert all(r["e_rms_pct"] > 10 * true_row["e_rms_pct"] for r in rows if r["n_cells"] == 1)
    table = format_search_table(rows)
    assert "Power-Law" in table and table.count("\n") == 5


def test_params_round_trip_and_validation():
    assert pl.PlParams.from_dict(json.loads(json.dumps(PARAMS.to_dict()))) == PARAMS
    assert pl.PlStructure(**json.loads(json.dumps(asdict(STRUCT)))) == STRUCT
    for bad in ({"i_t": 0.0}, {"v_t": -1.0}, {"a": [1.0, -1.0]}, {"w": [1.0, np.nan]}):
        with pytest.raises(ValueError):
            pl.PlParams(**{**PARAMS.to_dict(), **bad})
    for bad in ({"n_cells": 0}, {"power": 1.0}, {"n_basis": 0}, {"smoothing": -1.0},
                {"dt": 0.0}, {"slope_cap": 2.0}):
        with pytest.raises(ValueError):
            pl.PlStructure(**bad)
    with pytest.raises(ValueError):
        pl.simulate(pl.PlStructure(n_cells=2), PARAMS, _input(10))


def test_cli_runs_a_small_search(tmp_path, capsys):
    rec = simulate_experiment("sine", 1)
    data = write_recording(rec, tmp_path / "fit.csv")
    out = tmp_path / "search.json"
    code = main(["pl-search", str(data), "--n", "1,2", "--p", "21", "--m", "1",
                 "--json", str(out)])
    assert code == 0
    assert "Power-Law" in capsys.readouterr().out
    rows = json.loads(out.read_text())["rows"]
    assert [r["n_cells"] for r in rows] == [1, 2]
    assert all(np.isfinite(r["e_rms_pct"]) for r in rows)


def test_compensator_on_the_virtual_sensor():
    assert get_family("pl") is pl.FAMILY and pl.FAMILY.has_inverse
    comp = fit_compensator(simulate_experiment("sine", 1), model="pl")
    scores = evaluate(comp, simulate_experiment("sine", 2))
    assert np.isfinite(scores["r2"])
    assert scores["r2"] > scores["linear_r2"]
