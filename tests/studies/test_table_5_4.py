"""Table 5.4 on the virtual sensor: the raw path's rows against the sensor's own truth, the fit
and compensated rows against the compensation package, and the command's files."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest
from numpy.testing import assert_allclose

from hystkit.cli import main
from hystkit.compensation import evaluate, fit_compensator
from hystkit.io import Recording
from hystkit.metrics import loop_area, sinad_db
from hystkit.preprocess import downsample, lowpass_zero_phase
from hystkit.sensors import ScopeSettings, simulate_experiment, simulate_raw
from hystkit.studies import (
    SAME_CENTRING_NOTE,
    Table54Settings,
    measure_table_5_4,
    signal_scores,
)
from hystkit.studies.table_5_4 import _forward

QUICK = Table54Settings(scope_rate=10e3, duration=40.0)


@pytest.fixture(scope="module")
def table() -> dict:
    return measure_table_5_4(QUICK)


def _rows(result: dict) -> dict:
    return {(r["signal"], r["centring"]): r for r in result["rows"]}


def test_raw_rows_match_the_sensors_exact_resistances(table, tmp_path):
    """R1, R2 and R1 - R2 come from bridge voltages and a decoded encoder; the same seed's exact
    gauge resistances and position (RawTruth, before scope noise and quantisation) through the
    document's filter give the same loop area, and the same SINAD for the gauges (the encoder's
    SINAD is its quantisation's: the exact sine has none)."""
    truth = simulate_raw(tmp_path / "val.parquet", QUICK.excitation, QUICK.val_seed,
                         scope=ScopeSettings(fs=QUICK.scope_rate), duration=QUICK.duration)
    exact = truth.recording()
    r1, r2 = downsample(lowpass_zero_phase(truth.resistance, truth.fs_internal, 20.0),
                        truth.fs_internal, 40.0)
    expected = {"R1": (r1 - r1.mean()) / r1.mean(), "R2": (r2 - r2.mean()) / r2.mean(),
                "R1 - R2": exact.sensor, "encoder": exact.position}
    rows = _rows(table)
    for name, y in expected.items():
        row = rows[(name, "–")]
        assert row["loop_area_pct"] == pytest.approx(loop_area(exact.position, y), abs=0.05), name
        if name == "encoder":
            continue
        # 0.5 mV scope noise and the 5 um encoder steps move SINAD by ~0.02 dB and the loop
        # areas by ~0.01 points (measured); the tolerances leave 5x room
        assert row["sinad_db"] == pytest.approx(sinad_db(y, 40.0), abs=0.1), name


@pytest.fixture(scope="module")
def inverse_pair():
    fit_rec = simulate_experiment("sine", 1)
    val_rec = simulate_experiment("sine", 2)
    comp = fit_compensator(fit_rec, 1, model="mpl", mode="inverse", diagnose=False)
    return comp, val_rec


def test_compensated_rows_are_evaluates_scores(inverse_pair):
    """The compensated row is what ``hk.evaluate`` reports, deployable and oracle alike: both
    recordings are centred on their own means, so the two centrings are one row here."""
    comp, rec = inverse_pair
    scores = evaluate(comp, rec)
    rows = _rows({"rows": signal_scores(comp, rec, rec.sensor, -rec.sensor)})
    assert [key for key in rows if key[0] in ("fit", "compensated")] == \
        [("fit", "fit = oracle, see note"), ("compensated", "fit = oracle, see note")]
    row = rows[("compensated", "fit = oracle, see note")]
    assert row["note"] == SAME_CENTRING_NOTE
    for suffix in ("", "_oracle"):
        assert_allclose(row["sinad_db"], scores[f"sinad_db{suffix}"], rtol=1e-12)
        assert_allclose(row["loop_area_pct"], scores[f"loop_area{suffix}"], rtol=1e-12)
    # the hysteresis is taken out: far less loop than the sensor's own
    assert abs(row["loop_area_pct"]) < 0.1 * abs(scores["sensor_loop_area"])


def test_deployable_equals_oracle_on_centred_recordings(inverse_pair):
    """Why the rows are one: the fitting recording's offsets are the validation recording's
    means (both centred on their own means, the same sine position), so the two centrings'
    signals differ by a constant at most, which SINAD and loop area ignore."""
    comp, rec = inverse_pair
    assert_allclose(comp.scaling.sensor_offset, np.mean(rec.sensor), atol=1e-12)
    assert_allclose(comp.position_offset(), np.mean(rec.position), atol=1e-12)
    oracle = comp.oracle()
    for own, other in ((_forward(comp, rec), _forward(oracle, rec)),
                       (comp.estimate(rec, float(np.mean(rec.position))),
                        oracle.estimate(rec, float(np.mean(rec.position))))):
        assert np.ptp(own - other) < 1e-9


def test_an_offset_sensor_gets_both_centrings(inverse_pair):
    """A validation sensor offset by 10 % of its range is no longer centred like the fitting
    recording. The mPL's cells depend on ``e - v`` only, so its inverse just shifts with the
    offset (same scores); the Preisach grid does not: its deployable rows differ from the
    oracle ones and both are shown."""
    _, rec = inverse_pair
    comp = fit_compensator(simulate_experiment("sine", 1), 8, model="preisach",
                           mode="inverse", diagnose=False)
    shifted = Recording(time=rec.time, position=rec.position,
                        sensor=rec.sensor + 0.1 * np.ptp(rec.sensor))
    rows = _rows({"rows": signal_scores(comp, shifted, rec.sensor, -rec.sensor)})
    assert [key for key in rows if key[0] in ("fit", "compensated")] == \
        [("fit", "fit (deployable)"), ("compensated", "fit (deployable)"),
         ("fit", "recording (oracle)"), ("compensated", "recording (oracle)")]
    assert not any("note" in row for row in rows.values())
    # the oracle centres the shifted sensor back: its compensated row is the unshifted one's
    scores = evaluate(comp, rec)
    assert_allclose(rows[("compensated", "recording (oracle)")]["sinad_db"],
                    scores["sinad_db_oracle"], rtol=1e-9)
    assert abs(rows[("compensated", "fit (deployable)")]["sinad_db"]
               - scores["sinad_db_oracle"]) > 1.0


def test_fit_row_is_the_forward_model_in_sensor_units(inverse_pair):
    """Inverse of forward is the identity: the compensator run on the fit row's sensor signal
    gives the position back (checks the fit row's offsets, polarity and scale)."""
    comp, rec = inverse_pair
    for c in (comp, comp.oracle()):
        predicted = _forward(c, rec)
        back = c.estimate(Recording(time=rec.time, position=rec.position, sensor=predicted),
                          float(np.mean(rec.position)))
        # the oracle re-centres on the predicted signal's own mean, which differs from the
        # measured one's by the model's misfit: an offset of a few um
        tolerance = 1e-9 if c is comp else 0.02
        assert_allclose(back, rec.position, atol=tolerance)


def test_table_needs_an_inverse_model(inverse_pair):
    _, rec = inverse_pair
    direct = fit_compensator(simulate_experiment("sine", 1), 1, model="mpl", diagnose=False)
    with pytest.raises(ValueError, match="mode='inverse'"):
        signal_scores(direct, rec, rec.sensor, rec.sensor)


def test_cli_writes_json_and_csv_and_keeps_them(tmp_path, capsys):
    out = tmp_path / "t54"
    assert main(["table", "5.4", "--quick", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    data = json.loads((out / "table_5_4.json").read_text())
    with open(out / "table_5_4.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert [r["signal"] for r in rows] == [r["signal"] for r in data["rows"]]
    for row, saved in zip(rows, data["rows"], strict=True):
        assert float(row["sinad_db"]) == pytest.approx(saved["sinad_db"], rel=1e-12)
        assert f"{saved['loop_area_pct']:.4g}" in printed
    before = (out / "table_5_4.json").read_bytes()
    assert main(["table", "5.4", "--quick", "--out", str(out)]) == 2
    assert "exists" in capsys.readouterr().err
    assert (out / "table_5_4.json").read_bytes() == before
    assert main(["table", "5.4", "--quick", "--out", str(out), "--force"]) == 0


def test_cli_refuses_a_model_without_inverse(capsys):
    assert main(["table", "5.4", "--model", "boucwen"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("hystkit: error:") and "boucwen" in err and err.count("\n") == 1


def test_cli_size_defaults_to_the_familys(capsys):
    """No --size: the document's 1 cell for mpl, the family's default size otherwise."""
    from hystkit.models import get_family

    code = main(["table", "5.4", "--model", "preisach", "--quick"])
    printed = capsys.readouterr().out
    size = get_family("preisach").default_size
    assert f"model preisach, size {size}: " in printed
    assert f"fitting preisach (size {size})" in printed
    assert code == 0 and "| compensated |" in printed
