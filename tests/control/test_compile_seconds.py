"""The closed loop reports JIT compilation apart from simulation (issue 11.5: ``control``
printed compile time as simulation time)."""

from __future__ import annotations

import json
import subprocess
import sys

from numpy.testing import assert_array_equal

from hystkit import control as hc

GAIN = 40.0  # sensor units per metre of an ideal linear sensor


def _loop() -> hc.ControlLoop:
    return hc.ControlLoop("direct", hc.linear_block(GAIN, name="ideal sensor"),
                          hc.DOCUMENT_PID_DIRECT,
                          compensator=hc.linear_block(1 / GAIN, name="exact compensator"),
                          sensor_gain=1 / GAIN)


def test_a_second_run_compiles_nothing_and_gives_the_same_signals():
    loop, r = _loop(), hc.sine_reference(400)
    first = hc.simulate_loop(loop, r)
    second = hc.simulate_loop(loop, r)
    assert second.compile_seconds == 0.0
    assert_array_equal(second.y, first.y)
    assert second.metrics()["compile_seconds"] == 0.0


def test_first_run_in_a_process_counts_the_compilation_separately():
    """A fresh interpreter compiles the kernel on the first run: that time is in
    ``compile_seconds``, not in ``seconds``, which for 100 steps is far below it."""
    probe = f"""
import json
from hystkit import control as hc
loop = hc.ControlLoop("direct", hc.linear_block({GAIN}), hc.DOCUMENT_PID_DIRECT,
                      compensator=hc.linear_block(1 / {GAIN}), sensor_gain=1 / {GAIN})
a = hc.simulate_loop(loop, hc.sine_reference(100))
b = hc.simulate_loop(loop, hc.sine_reference(100))
print(json.dumps([a.compile_seconds, a.seconds, b.compile_seconds]))
"""
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         check=True, timeout=300).stdout
    compile_first, simulate_first, compile_second = json.loads(out.strip().splitlines()[-1])
    assert compile_first > 0.0 and compile_second == 0.0
    assert simulate_first < compile_first
