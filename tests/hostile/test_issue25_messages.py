"""Issue 25.4: what the commands print is right and says what it means.

A broadband recording's spectrum is shown with "no line to pick a cut-off from" instead of a
refusal; ``pl-search`` applies the fit's minimum sample count; ``compare --models ,,,`` names
no model and is refused; an A/B encoder's report gives its logic thresholds in volts, not
"levels 0, 1, 2, 3 V"; ``settling`` says its drift rate is relative to R_final.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from .conftest import Run, snapshot


def test_spectrum_of_the_noise_excitation_is_shown_without_a_cut_off(
        cli: Callable[..., Run], tmp_path: Path) -> None:
    noise = tmp_path / "noise.csv"
    assert cli("simulate-sensor", "--excitation", "noise", "--seed", "1", "--out",
               noise).code == 0
    run = cli("spectrum", noise, "--out", tmp_path / "spec")
    run.clean()
    assert run.code == 0, run.err
    assert ("no spectral line stands 10 dB above the noise floor between 0.1 and 16 Hz, so "
            "there is no line to pick a cut-off from") in run.out
    assert "no cut-off suggested" in run.out and "f_signal =" not in run.out.replace(
        "rule: f_signal =", "")
    report = json.loads((tmp_path / "spec" / "spectrum.json").read_text())
    assert report["f_signal_hz"] is None and report["suggested_cutoff_hz"] is None
    assert report["no_line"].startswith("no spectral line stands 10 dB")
    # the spectrum itself is there: a PSD per frequency and its floor, and the figure
    assert len(report["psd_per_hz"]["differential"]) == len(report["freq_hz"]) > 100
    assert np.all(np.isfinite(report["noise_floor_per_hz"]))
    assert (tmp_path / "spec" / "spectrum.png").stat().st_size > 10_000


def test_pl_search_on_two_samples_is_refused_like_fit(cli: Callable[..., Run],
                                                      good: dict[str, Path],
                                                      tmp_path: Path) -> None:
    two = tmp_path / "two.csv"
    two.write_text("".join(good["fit"].read_text().splitlines(keepends=True)[:3]))
    before = snapshot(tmp_path)
    run = cli("pl-search", two, "--json", tmp_path / "rows.json")
    assert run.code == 2
    # the default grid's largest structure: N = 10, M = 5, 2 samples per parameter
    run.error_line("two.csv", "column 'position'", "2 samples", "at least 38")
    assert "e_rms" not in run.out
    assert snapshot(tmp_path) == before


@pytest.mark.parametrize("models", [",,,", " , ", ""])
def test_compare_with_no_model_named_is_refused(cli: Callable[..., Run],
                                                good: dict[str, Path], tmp_path: Path,
                                                models: str) -> None:
    run = cli("compare", good["fit"], good["val"], "--models", models, "--out",
              tmp_path / "cmp")
    assert run.code == 2
    run.error_line("--models", "names no model", "mpl")
    assert not (tmp_path / "cmp").exists()


def test_ab_encoder_report_gives_thresholds_in_volts(cli: Callable[..., Run],
                                                     tmp_path: Path) -> None:
    raw = tmp_path / "ab.parquet"
    assert cli("simulate-sensor", "--excitation", "sine", "--raw", "--encoder", "ab",
               "--duration", "3", "--scope-rate", "2e4", "--out", raw).code == 0
    run = cli("preprocess", raw, "--out", tmp_path / "ab.csv")
    assert run.code == 0, run.err
    line = next(x for x in run.out.splitlines() if x.strip().startswith("encoder:"))
    assert "levels 0, 1, 2, 3 V" not in line
    report = json.loads((tmp_path / "ab.json").read_text())["report"]
    thresholds = report["encoder_thresholds_v"]
    table = pd.read_parquet(raw, columns=["enc_a", "enc_b"])
    for name, value in zip(("enc_a", "enc_b"), thresholds, strict=True):
        # midway between the channel's two logic levels (each within its scope noise)
        low, high = float(table[name].min()), float(table[name].max())
        assert value == pytest.approx(0.5 * (low + high), abs=0.05 * (high - low))
        assert f"{name} {value:.4g} V" in line
    assert line.strip().startswith("encoder: A/B logic channels, thresholds")


def test_settling_says_its_drift_rate_is_relative_to_r_final(cli: Callable[..., Run],
                                                             tmp_path: Path) -> None:
    log = tmp_path / "log.csv"
    assert cli("simulate-settling", "--out", log).code == 0
    run = cli("settling", log, "--traces", "r2", "--out", tmp_path / "s")
    assert run.code == 0, run.err
    assert "rest time (drift |dR/dt| / R_final < 0.1 %/h)" in run.out


def test_a_few_samples_outside_the_training_range_are_not_rounded_to_zero(
        cli: Callable[..., Run], good: dict[str, Path], tmp_path: Path) -> None:
    """2 of 8000 samples beyond the training range were reported as '(0.0 %)'."""
    table = pd.read_csv(good["val"])
    top = table["sensor"].max()
    span = top - table["sensor"].min()
    table.loc[[100, 200], "sensor"] = top + 0.5 * span  # two samples well past the range
    data = tmp_path / "two_outside.csv"
    table.to_csv(data, index=False)
    run = cli("compensate", good["model"], data, "--out", tmp_path / "c.csv")
    warning = next(line for line in run.err.splitlines() if "lie outside the sensor range" in line)
    assert f"2 sample(s) ({100 * 2 / len(table):.2g} %)" in warning, warning
