"""Loading what a command needs after its parallel map while the workers run it.

During a parallel map this process only waits, and the cores are busy with the workers; what
it loads there (a module's import, numba's target context) costs the map about half its CPU
time (the cores are shared three ways), where after the map it would cost all of it, with the
other core idle. ``generalize`` imports matplotlib for its figure (2 workers, ~0.3 s of
imports) and scipy.io for its ``.mat`` file this way, ``select`` matplotlib and makes numba
ready for the refit of its winner.
"""

from __future__ import annotations

import importlib
import threading
from collections.abc import Iterator, Sequence
from contextlib import contextmanager

from ._contract import Executor, make_numba_ready

__all__ = ["loading_meanwhile"]


@contextmanager
def loading_meanwhile(executor: Executor, modules: Sequence[str] = (), *,
                      numba_ready: bool = False) -> Iterator[None]:
    """While the block runs, import `modules` (and make numba ready) in a thread of this
    process, if `executor` runs the pieces elsewhere; the block's end waits for it.

    Only a head start: a module that fails to import here is imported again where it is
    used, which raises there. A serial executor loads nothing here (the pieces run in this
    process, on its only core, and what they use is then loaded anyway).

    Parameters
    ----------
    executor : Executor
        The open executor of the map that the block runs.
    modules : sequence of str
        Modules to import, e.g. ``("matplotlib.figure",)``.
    numba_ready : bool, default False
        Also make numba ready to load cached kernels (its target context, ~0.2 s), for fits
        this process runs after the map.
    """
    if executor.n_workers <= 1:
        yield
        return
    thread = threading.Thread(target=_load, args=(tuple(modules), numba_ready),
                              name="hystkit-loading-meanwhile", daemon=True)
    thread.start()
    try:
        yield
    finally:
        thread.join()


def _load(modules: tuple[str, ...], numba_ready: bool) -> None:
    for name in modules:
        try:
            importlib.import_module(name)
        except Exception:  # noqa: BLE001, S112  (a head start only: see loading_meanwhile)
            continue
    if numba_ready:
        make_numba_ready()
