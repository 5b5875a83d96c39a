"""The forked workers start when the executor opens and get numba ready before any piece.

Commands open the executor before they read or simulate their recordings, so that the workers'
start (numba's target context, ~0.2 s each) overlaps that work (`hystkit.parallel._forked`).
Checked in a fresh interpreter, whose numba has not been made ready by earlier tests: the
workers exist before the first map, and a piece that does nothing with numba finds its worker's
target context ready (its implementation modules, such as ``numba.np.arraymath``, loaded),
while this process never loaded them.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

_CHECK = textwrap.dedent("""
    import multiprocessing, os, sys
    import numba  # imported, not made ready: numba.np.arraymath is loaded by the refresh
    from hystkit.parallel import open_executor

    def loaded(_):
        return os.getpid(), "numba.np.arraymath" in sys.modules

    with open_executor(2) as executor:
        started = len(multiprocessing.active_children())
        results = executor.map(loaded, range(4))
    print(started, sorted({ready for _, ready in results}),
          len({pid for pid, _ in results} - {os.getpid()}) > 0,
          "numba.np.arraymath" in sys.modules)
""")


@pytest.mark.skipif(not sys.platform.startswith("linux"),
                    reason="the forked executor is Linux's")
def test_workers_start_at_open_with_numba_ready():
    done = subprocess.run([sys.executable, "-c", _CHECK], capture_output=True, text=True,
                          timeout=180, check=False)
    assert done.returncode == 0, done.stderr
    # 2 workers before any map; every piece ran in a worker that was ready; this process
    # (which ran no kernel) never made numba ready itself
    assert done.stdout.split() == ["2", "[True]", "True", "False"]
