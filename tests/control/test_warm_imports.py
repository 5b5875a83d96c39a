"""What a loop run loads (issue 29: a warm ``hystkit control`` spent 0.15-0.19 s of CPU importing
pandas, which only :meth:`LoopResponse.to_pandas` uses). A fresh interpreter runs an
experiment, then asks for the DataFrame: pandas is loaded by the second and not by the first."""

from __future__ import annotations

import subprocess
import sys

PROBE = """
import sys
from hystkit import control as hc

gain = 1 / 40.0
loop = hc.ControlLoop("direct", hc.linear_block(40.0), hc.DOCUMENT_PID_DIRECT,
                      compensator=hc.linear_block(gain), sensor_gain=gain)
result = hc.run_experiment("sine", loop)
print("pandas" in sys.modules)
frame = next(iter(result.cases.values())).to_pandas()
print("pandas" in sys.modules, len(frame))
"""


def test_a_loop_run_loads_no_pandas_and_its_frame_does():
    done = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True,
                          timeout=600, check=False)
    assert done.returncode == 0, done.stderr[-2000:]
    after_run, after_frame = done.stdout.strip().splitlines()[-2:]
    assert after_run == "False"
    assert after_frame.split() == ["True", "19841"]
