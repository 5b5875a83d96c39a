"""``simulate-sensor --gain-drift``: the drifting virtual sensor of the online-adaptation
example (issue 14.11) from the command line."""

from __future__ import annotations

import numpy as np
import pytest

from hystkit.cli import main
from hystkit.io import read_recording
from hystkit.sensors import gain_ramp


def test_gain_drift_multiplies_the_sensor_by_the_ramp(tmp_path):
    plain, drifting = tmp_path / "plain.csv", tmp_path / "drift.csv"
    assert main(["simulate-sensor", "--excitation", "sine", "--seed", "3", "--out",
                 str(plain)]) == 0
    assert main(["simulate-sensor", "--excitation", "sine", "--seed", "3", "--gain-drift",
                 "-0.1", "--out", str(drifting)]) == 0
    a, b = read_recording(plain), read_recording(drifting)
    np.testing.assert_array_equal(b.time, a.time)
    np.testing.assert_array_equal(b.position, a.position)
    ramp = gain_ramp(a.time, -0.1)
    assert ramp[0] == 1.0 and ramp[-1] == pytest.approx(0.9, abs=1e-15)
    np.testing.assert_allclose(b.sensor, a.sensor * ramp, rtol=1e-15, atol=0)


@pytest.mark.parametrize("extra, message", [
    (["--raw"], "--gain-drift and --references-every apply to the 40 Hz recording"),
    ([], "must be >= -0.9"),
])
def test_gain_drift_refusals(tmp_path, capsys, extra, message):
    drift = "0.1" if extra else "-1"
    code = main(["simulate-sensor", "--excitation", "sine", "--gain-drift", drift,
                 "--out", str(tmp_path / "x.csv"), *extra])
    assert code == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "x.csv").exists()


def test_references_every_writes_occasional_true_positions(tmp_path):
    path = tmp_path / "refs.csv"
    assert main(["simulate-sensor", "--excitation", "sine", "--seed", "4", "--gain-drift", "0.1",
                 "--references-every", "5", "--out", str(path)]) == 0
    import pandas as pd

    frame = pd.read_csv(path)
    known = frame["reference"].notna().to_numpy()
    np.testing.assert_array_equal(frame["reference"][known], frame["position"][known])
    slots = np.floor(frame["time"][known].to_numpy() / 5.0)
    assert np.array_equal(slots, np.arange(40.0))  # one reference in each 5 s of the 200 s run
    assert read_recording(path).n_samples == 8000  # the extra column does not disturb reading
