"""``hystkit stream`` of a fitted ladder runs compiled and writes ``compensate``'s numbers bit
for bit (issue 29, item 4): the ladder's forward run sums its read-out in its block's order
(``models/ladder/kernels.simulate``), so the stream's probe accepts the block."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from numpy.testing import assert_array_equal

from hystkit.cli import main
from hystkit.compensation import load_compensator
from hystkit.live import Stream

from ..cli_support import run_cli

ROWS = 600


@pytest.fixture(scope="module", params=["direct", "inverse"])
def ladder(request, tmp_path_factory) -> dict[str, Path]:
    """A 3-section ladder fitted (``--mode``: the parameter) on 600 samples of the virtual
    sine run, a validation run of another seed and ``compensate``'s output on it."""
    folder = tmp_path_factory.mktemp(f"ladder_{request.param}")
    files = {}
    for name, seed in (("train", 1), ("val", 2)):
        whole = folder / f"{name}_whole.csv"
        assert main(["simulate-sensor", "--excitation", "sine", "--seed", str(seed),
                     "--out", str(whole)]) == 0
        files[name] = folder / f"{name}.csv"
        pd.read_csv(whole).iloc[:ROWS].to_csv(files[name], index=False)
    files["model"] = folder / "model.json"
    assert main(["fit", str(files["train"]), "--model", "ladder", "--cells", "3", "--mode",
                 request.param, "--out", str(files["model"])]) == 0
    files["compensated"] = folder / "c.csv"
    assert main(["compensate", str(files["model"]), str(files["val"]), "--out",
                 str(files["compensated"])]) == 0
    return files


def test_a_ladder_streams_compiled_with_the_bits_of_compensate(ladder, capsys):
    assert Stream(load_compensator(ladder["model"])).compiled
    code, out, err = run_cli(capsys, "stream", ladder["model"], "--in", ladder["val"])
    assert code == 0, err
    streamed, written = _exact(io.StringIO(out)), _exact(ladder["compensated"])
    assert streamed.shape[0] == written.shape[0] == ROWS
    compared = [name for name in ("position_estimate", "position_lower", "position_upper")
                if name in written]
    assert "position_estimate" in compared and set(compared) <= set(streamed.columns)
    for name in compared:
        assert np.all(np.isfinite(written[name]))
        assert_array_equal(streamed[name].to_numpy(), written[name].to_numpy(), err_msg=name)


def _exact(source) -> pd.DataFrame:
    """A CSV's columns, the numbers parsed by Python's ``float`` (correctly rounded: the bits
    that were written with ``repr``)."""
    frame = pd.read_csv(source, dtype=str)
    return frame.apply(lambda column: column.map(float))
