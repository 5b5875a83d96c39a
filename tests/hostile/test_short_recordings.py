"""Short recordings: ``evaluate`` refuses fewer samples than a fit needs, ``compensate`` works.

Scores of 2 or 19 samples (an R², a loop area) mean nothing, so ``evaluate`` refuses a
recording shorter than ``MIN_SCORED_SAMPLES`` (20, the minimum of a fit) with one line naming
the file and the count. ``compensate`` is causal (each estimate uses past samples and the model
file only), so a short recording, e.g. a stream's first samples, is compensated: its estimates
are the first rows of the whole recording's.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest
from pandas.testing import assert_frame_equal

from hystkit.compensation._evaluate import MIN_SCORED_SAMPLES
from hystkit.compensation._training_checks import MIN_SAMPLES

from .conftest import snapshot


def _head(good: dict[str, Path], folder: Path, n: int) -> Path:
    path = folder / f"head{n}.csv"
    pd.read_csv(good["val"]).iloc[:n].to_csv(path, index=False)
    return path


def test_the_scoring_minimum_is_the_fitting_minimum() -> None:
    assert MIN_SCORED_SAMPLES == MIN_SAMPLES == 20


@pytest.mark.parametrize("n", [2, 3, MIN_SCORED_SAMPLES - 1])
def test_evaluate_refuses_a_short_recording(cli, good: dict[str, Path], tmp_path: Path,
                                            n: int) -> None:
    path = _head(good, tmp_path, n)
    before = snapshot(tmp_path)
    run = cli("evaluate", good["model"], path, "--json", tmp_path / "scores.json")
    assert run.code == 2, run.err
    run.error_line(path.name, f"{n} samples", f"at least {MIN_SCORED_SAMPLES}")
    assert snapshot(tmp_path) == before


def test_evaluate_scores_the_minimum(cli, good: dict[str, Path], tmp_path: Path) -> None:
    path = _head(good, tmp_path, MIN_SCORED_SAMPLES)
    run = cli("evaluate", good["model"], path, "--json", tmp_path / "scores.json")
    assert run.code == 0, run.err
    assert (tmp_path / "scores.json").is_file()


@pytest.mark.parametrize("n", [2, 5, MIN_SCORED_SAMPLES - 1])
def test_compensate_works_on_a_short_recording(cli, good: dict[str, Path], tmp_path: Path,
                                               n: int) -> None:
    path = _head(good, tmp_path, n)
    whole, short = tmp_path / "whole.csv", tmp_path / "short.csv"
    assert cli("compensate", good["model"], good["val"], "--out", whole).code == 0
    run = cli("compensate", good["model"], path, "--out", short)
    assert run.code == 0, run.err
    run.clean()
    # causal: the short recording's estimates are the whole one's first rows, bit for bit
    assert_frame_equal(pd.read_csv(short), pd.read_csv(whole).iloc[:n])
