"""The closed-loop kernel is cached on disk per combination of block steps (issue 29: it was
compiled again by every process, 0.6-1.5 s of each ``hystkit control``). Fresh interpreters
share an empty numba cache folder: the first to run a combination compiles it, the next ones
load it, and a process that runs several combinations runs each one's own code."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from numpy.testing import assert_array_equal

PROBE = """
import json, sys
import numpy as np
from hystkit import control as hc
from hystkit.control import _kernel
from hystkit.models import get_family

def loop(name):
    # the same argument types, different block steps: (mpl.block_forward, identity, identity)
    # and (identity, identity, identity)
    if name == "mpl":
        mpl = get_family("mpl")
        structure = mpl.make_structure(hc.TS, 2)
        params = mpl.random_params(structure, np.random.default_rng(3))
        sensor, gain = hc.SensorBlock(structure, params, False, 0.0, 1e3, 0.0, 1.0), 1e-3
    else:
        sensor, gain = hc.linear_block(40.0), 1 / 40.0
    return hc.ControlLoop("direct", sensor, hc.DOCUMENT_PID_DIRECT,
                          compensator=hc.linear_block(gain), sensor_gain=gain)

if sys.argv[2:] == ["--rest-only"]:  # the blocks' own kernels, not the loop
    hc.rest_state(loop(sys.argv[1]))
    sys.exit()
runs = []
for name in sys.argv[1].split(","):
    this = loop(name)
    response = hc.simulate_loop(this, hc.sine_reference(300))
    args = this.kernel_arguments()
    kernel = _kernel._kernel(args[6], args[9], args[12])
    runs.append({"name": name, "hits": sum(kernel.stats.cache_hits.values()),
                 "misses": sum(kernel.stats.cache_misses.values()),
                 "symbol": next(iter(kernel.overloads.values())).fndesc.mangled_name,
                 "y": response.y.tolist()})
print(json.dumps(runs))
"""


def _run(cache: Path, *argv: str) -> list[dict]:
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    done = subprocess.run([sys.executable, "-c", PROBE, *argv], capture_output=True, text=True,
                          env=env, timeout=600, check=False)
    assert done.returncode == 0, done.stderr[-2000:]
    return json.loads(done.stdout.strip().splitlines()[-1]) if done.stdout.strip() else []


def test_each_combination_is_cached_apart_and_runs_its_own_code(tmp_path):
    """Two combinations compiled in two processes, then loaded and run by turns in a third,
    give the first runs' signals bit for bit.

    With the mPL's own kernels cached first, each of the two processes compiles the loop and
    nothing else, so numba numbers both compilations alike. Named by that number alone, the
    two loops had one symbol name (a process that loaded both could run one's code for the
    other, or crash); the combination is part of the name."""
    _run(tmp_path, "mpl", "--rest-only")
    [linear], [mpl] = _run(tmp_path, "linear"), _run(tmp_path, "mpl")
    assert (linear["hits"], linear["misses"]) == (mpl["hits"], mpl["misses"]) == (0, 1)
    assert linear["symbol"] != mpl["symbol"]
    assert linear["y"] != mpl["y"]
    later = _run(tmp_path, "mpl,linear,mpl,linear")
    for run in later:
        first = mpl if run["name"] == "mpl" else linear
        assert (run["hits"], run["misses"]) == (1, 0)
        assert run["symbol"] == first["symbol"]
        assert_array_equal(run["y"], first["y"])
