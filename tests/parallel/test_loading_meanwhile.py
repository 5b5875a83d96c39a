"""`loading_meanwhile`: a parallel command loads what it needs after the map while it waits.

A probe module written for each test records the thread that imported it: with a parallel
executor it is imported by the helper thread before the block ends; with a serial one it is
not imported at all; a module that cannot be imported is left for the code that uses it.
"""

from __future__ import annotations

import sys
import threading

import pytest

from hystkit.parallel import SerialExecutor, loading_meanwhile


class _TwoWorkers:
    """Stands for an open parallel executor: `loading_meanwhile` reads only ``n_workers``."""

    n_workers = 2


@pytest.fixture
def probe(tmp_path, monkeypatch):
    name = f"hystkit_meanwhile_probe_{abs(hash(str(tmp_path)))}"
    (tmp_path / f"{name}.py").write_text(
        "import threading, time\n"
        "time.sleep(0.2)  # still loading while the block's own work runs\n"
        "LOADED_BY = threading.current_thread().name\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    yield name
    sys.modules.pop(name, None)


def test_a_parallel_map_loads_the_modules_in_a_thread_before_the_block_ends(probe):
    with loading_meanwhile(_TwoWorkers(), [probe]):
        main_thread_ran = threading.current_thread() is threading.main_thread()
    assert main_thread_ran
    assert sys.modules[probe].LOADED_BY == "hystkit-loading-meanwhile"
    assert not any(t.name == "hystkit-loading-meanwhile" for t in threading.enumerate())


def test_a_serial_run_loads_nothing(probe):
    with loading_meanwhile(SerialExecutor(), [probe], numba_ready=True):
        pass
    assert probe not in sys.modules


def test_a_module_that_fails_to_import_is_left_to_its_user(probe):
    with loading_meanwhile(_TwoWorkers(), ["hystkit_no_such_module_here", probe],
                           numba_ready=True):
        pass
    assert "hystkit_no_such_module_here" not in sys.modules
    assert probe in sys.modules  # the next one still loaded
