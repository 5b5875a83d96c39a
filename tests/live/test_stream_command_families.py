"""``hystkit stream`` of the compensators that once took the Python path (the ladder both
ways, Bobbio and generalised Preisach direct, the PI inverse) runs compiled and writes
``compensate``'s numbers bit for bit (issue 29, item 4): their offline runs compute in their
blocks' order (the ladder's read-out summed in its block's order, ``models/ladder/kernels``;
compiled forward passes for Bobbio and the generalised Preisach; the PI inverse carries the
forward plays and forms its inverse plays from them each sample, ``models/pi/kernels.invert``),
so the stream's probe accepts the block."""

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
# (model, mode, size): small models, fitted in a few seconds on 600 samples
FITTED = [("ladder", "direct", 3), ("ladder", "inverse", 3), ("bobbio", "direct", 4),
          ("gpreisach", "direct", 6), ("pi", "inverse", 4)]


@pytest.fixture(scope="module", params=FITTED, ids=lambda c: f"{c[0]}-{c[1]}")
def fitted(request, tmp_path_factory) -> dict[str, Path]:
    """A compensator fitted on 600 samples of the virtual sine run, a validation run of
    another seed and ``compensate``'s output on it."""
    model, mode, size = request.param
    folder = tmp_path_factory.mktemp(f"{model}_{mode}")
    files = {}
    for name, seed in (("train", 1), ("val", 2)):
        whole = folder / f"{name}_whole.csv"
        assert main(["simulate-sensor", "--excitation", "sine", "--seed", str(seed),
                     "--out", str(whole)]) == 0
        files[name] = folder / f"{name}.csv"
        pd.read_csv(whole).iloc[:ROWS].to_csv(files[name], index=False)
    files["model"] = folder / "model.json"
    assert main(["fit", str(files["train"]), "--model", model, "--cells", str(size), "--mode",
                 mode, "--out", str(files["model"])]) == 0
    files["compensated"] = folder / "c.csv"
    assert main(["compensate", str(files["model"]), str(files["val"]), "--out",
                 str(files["compensated"])]) == 0
    return files


def test_the_family_streams_compiled_with_the_bits_of_compensate(fitted, capsys):
    assert Stream(load_compensator(fitted["model"])).compiled
    code, out, err = run_cli(capsys, "stream", fitted["model"], "--in", fitted["val"])
    assert code == 0, err
    streamed, written = _exact(io.StringIO(out)), _exact(fitted["compensated"])
    assert streamed.shape[0] == written.shape[0] == ROWS
    compared = [name for name in ("position_estimate", "position_lower", "position_upper")
                if name in written]
    assert set(compared) == {"position_estimate", "position_lower", "position_upper"}
    assert set(compared) <= set(streamed.columns)
    for name in compared:
        assert np.all(np.isfinite(written[name]))
        assert_array_equal(streamed[name].to_numpy(), written[name].to_numpy(), err_msg=name)


def _exact(source) -> pd.DataFrame:
    """A CSV's columns, the numbers parsed by Python's ``float`` (correctly rounded: the bits
    that were written with ``repr``)."""
    frame = pd.read_csv(source, dtype=str)
    return frame.apply(lambda column: column.map(float))
