"""The closed-loop kernel is cached on disk per combination of block steps (issue 29: it was
compiled again by every process, 0.6-1.5 s of each ``hystkit control``). Two fresh
interpreters share an empty numba cache folder: the first compiles, the second loads."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from numpy.testing import assert_array_equal

PROBE = """
import json
import numpy as np
from hystkit import control as hc
from hystkit.control import _kernel
from hystkit.models import get_family

mpl = get_family("mpl")
structure = mpl.make_structure(hc.TS, 2)
params = mpl.random_params(structure, np.random.default_rng(3))
loops = {
    # mPL sensor, ideal compensator: steps (mpl.block_forward, identity, identity)
    "mpl": hc.ControlLoop("direct", hc.SensorBlock(structure, params, False, 0.0, 1e3, 0.0, 1.0),
                          hc.DOCUMENT_PID_DIRECT, compensator=hc.linear_block(1e-3),
                          sensor_gain=1e-3),
    # every block ideal: steps (identity, identity, identity)
    "linear": hc.ControlLoop("direct", hc.linear_block(40.0), hc.DOCUMENT_PID_DIRECT,
                             compensator=hc.linear_block(1 / 40.0), sensor_gain=1 / 40.0),
}
report = {}
for name, loop in loops.items():
    response = hc.simulate_loop(loop, hc.sine_reference(300))
    args = loop.kernel_arguments()
    stats = _kernel._kernel(args[6], args[9], args[12]).stats
    report[name] = {"hits": sum(stats.cache_hits.values()),
                    "misses": sum(stats.cache_misses.values()), "y": response.y.tolist()}
print(json.dumps(report))
"""


def _run(cache: Path) -> dict:
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    done = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True,
                          env=env, timeout=600, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_a_loop_compiled_in_one_process_is_loaded_from_the_cache_in_the_next(tmp_path):
    first, second = _run(tmp_path), _run(tmp_path)
    for name in ("mpl", "linear"):
        assert (first[name]["hits"], first[name]["misses"]) == (0, 1), name
        assert (second[name]["hits"], second[name]["misses"]) == (1, 0), name
        # each combination loads its own kernel: the same signals, bit for bit
        assert_array_equal(second[name]["y"], first[name]["y"])
    assert first["mpl"]["y"] != first["linear"]["y"]
    assert list(tmp_path.rglob("*_make*loop*.nbi"))
