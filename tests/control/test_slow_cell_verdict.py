"""A growing mode slower than the loop's slowest cell is said to be marginal, from that cell;
a loop that grows faster than any of its cells stays UNSTABLE (issue 27, item 8).

``hystkit control --scheme direct --experiment sine`` printed "closed loop UNSTABLE (max |pole|
1.0000000006 ...)" beside "bounded yes". 60-digit arithmetic on the loop's state matrix gives
the same 1 + 6.2223e-10, so the pole is not rounding; it lies outside by 1/81 of the distance
at which the compensator's slowest cell (time constant 1e4 s, mPL's floor, where a cell
integrates over its 200 s record) lies inside. The rule: a growth time at least the slowest
cell's time constant (|pole| - 1 no more than that cell's 1 - |pole|). The constructed
compensator below shows why that is the right line: with the product w G, all that a record
shorter than the cell identifies, held fixed, a cell 10 % faster puts the pole inside.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from hystkit import control as hc
from hystkit.cli._control_report import closed_loop
from hystkit.models.mpl.model import MplParams, MplStructure
from hystkit.studies._report_control import stability_verdict

from ..cli_support import run_cli

IDEAL = hc.linear_block(40.0, name="ideal sensor")


def _loop(tau: float, w1: float, kp: float | None = None) -> hc.ControlLoop:
    """The ch. 7 direct loop with an ideal sensor and a 1-cell mPL compensator whose cell
    (time constant `tau` [s], weight `w1` against the direct path's 1) overturns its static
    gain when ``w1 < -1``."""
    params = MplParams(i_s=[0.5 / (2 * tau)], v_t=[0.5], w=[1.0, w1], v_b=0.0)
    comp = hc.SensorBlock(MplStructure(n_cells=1, dt=hc.TS), params, in_scale=40.0,
                          name="slow compensator")
    pid = hc.DOCUMENT_PID_DIRECT if kp is None else hc.PID(kp, hc.DOCUMENT_PID_DIRECT.ti,
                                                           hc.DOCUMENT_PID_DIRECT.td)
    return hc.ControlLoop("direct", IDEAL, pid, compensator=comp,
                          model=hc.linear_block(40.0, name="model"), sensor_gain=1 / 40.0)


@pytest.mark.parametrize("w1", [-1.01, -1.5])
def test_a_mode_slower_than_the_slowest_cell_is_marginal(w1):
    margins = hc.loop_margins(_loop(100.0, w1))
    assert not margins.closed_loop_stable and margins.growth_time_s >= 100.0
    assert margins.slow_cell == "compensator"
    assert margins.slow_cell_s == pytest.approx(100.0, rel=1e-5)
    # outside by no more than the cell is inside: growth time >= its time constant
    assert margins.max_pole_radius - 1 <= 1 - np.exp(-hc.TS / margins.slow_cell_s)
    text = closed_loop(margins)
    assert text.startswith("marginal, from a slow cell: one mode (|pole| 1 + ")
    assert "slower than the slowest cell of the compensator (time constant 100 s)" in text
    assert "not asymptotically stable" in text and "UNSTABLE" not in text
    verdict, kind = stability_verdict(json.loads(json.dumps(margins.to_dict())))
    assert kind == "note" and verdict == f"closed loop {text} (linearised at rest)"


def test_the_sign_of_such_a_pole_is_the_cells_undetermined_time_constant():
    """w G fixed (what a record shorter than the cell identifies): 10 % faster is stable,
    10 % slower grows ten times faster; each is marginal or stable, never UNSTABLE."""
    product = -1.01 / 100.0
    faster, slower = (hc.loop_margins(_loop(tau, product * tau)) for tau in (90.0, 110.0))
    assert faster.closed_loop_stable and faster.slow_cell is None
    assert slower.slow_cell == "compensator" and slower.growth_time_s < 1100.0


@pytest.mark.parametrize(("w1", "kp"), [(-5.0, None), (-1.01, 545e3)])
def test_a_loop_growing_faster_than_its_cells_stays_unstable(w1, kp):
    """A static gain overturned five-fold (e-fold in 25 s, faster than the 100 s cell) and
    a gain a thousand times too high (e-fold in well under a millisecond)."""
    margins = hc.loop_margins(_loop(100.0, w1, kp))
    assert not margins.closed_loop_stable and margins.growth_time_s < 100.0
    assert margins.slow_cell is None and margins.slow_cell_s is None
    assert closed_loop(margins).startswith("UNSTABLE (max |pole| ")
    verdict, kind = stability_verdict(json.loads(json.dumps(margins.to_dict())))
    assert kind == "bad" and verdict.startswith("closed loop UNSTABLE")


def test_control_says_the_default_loops_slow_pole_in_one_plain_line(tmp_path, capsys):
    code, out, err = run_cli(capsys, "control", "--scheme", "direct", "--experiment", "sine",
                             "--out", tmp_path / "ctl")
    assert code == 0, err
    lines = [line.strip() for line in out.splitlines()]
    verdict = next(line for line in lines if line.startswith("closed loop "))
    assert verdict.startswith("closed loop marginal, from a slow cell: one mode (|pole| 1 + ")
    assert "slower than the slowest cell of the compensator (time constant 1e+04 s)" in verdict
    assert "UNSTABLE" not in out
    metrics = json.loads((tmp_path / "ctl" / "metrics.json").read_text())
    assert metrics["cases"]["sine"]["bounded"]
    linear = metrics["linear"]
    assert linear["slow_cell"] == "compensator" and linear["growth_time_s"] > 8e5
    assert stability_verdict(linear)[1] == "note"
