"""BLAS on one thread around hystkit's linear algebra, with one controller per process.

hystkit's problems are tall and narrow (n samples x a few to a few hundred parameters) or
small: more BLAS threads do not pay there, and on a busy machine idle OpenBLAS threads spin
(a QR of 8200 x 192 took 164-179 ms of CPU on two threads against 40-43 ms on one, 2 cores
under load). ``threadpoolctl.threadpool_limits`` finds the loaded BLAS libraries anew on each
call (reading /proc/self/maps, ~1-20 ms); the controller here does it once, after hystkit's
imports have loaded numpy's and scipy's BLAS (numba loads ``scipy.linalg``).
"""

from __future__ import annotations

import functools

from threadpoolctl import ThreadpoolController

__all__ = ["one_blas_thread"]


@functools.cache
def _controller() -> ThreadpoolController:
    return ThreadpoolController()


def one_blas_thread():
    """A context manager: BLAS limited to one thread inside it."""
    return _controller().limit(limits=1, user_api="blas")
