"""A fit's own time: wall time less what numba spent compiling or loading kernels meanwhile.

A process's first fit of a family compiles its kernels (~10 s for the mPL on 2 cores with an
empty cache; tens of milliseconds to load them from numba's on-disk cache later), and that time
used to be the model file's ``fit_seconds`` (17-21 s for a 0.05 s fit, issue 29).

Kernels compiled by the workers of a parallel fit are not seen here: a fit that screens its
starts on workers (`fit_multistart`) counts the time its workers spend compiling.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

from .._compilation import compiler_seconds, listen

__all__ = ["FitTimer"]


def _compiler_seconds() -> float:
    listen()
    return compiler_seconds()


@dataclass(frozen=True)
class FitTimer:
    """Started when made; :meth:`seconds` is the wall time since then, less this thread's
    time in numba's compiler (`hystkit._compilation.compiler_seconds`): a fit's ``seconds``,
    whether or not its kernels had to be compiled or loaded.

    Parameters
    ----------
    wall : float, optional
        ``time.perf_counter()`` at the start (default: now).
    compiling : float, optional
        The compiler's seconds in this thread at the start (default: now).
    """

    wall: float = field(default_factory=time.perf_counter)
    compiling: float = field(default_factory=_compiler_seconds)

    def seconds(self) -> float:
        """Wall seconds since the timer started, less the compiler's."""
        elapsed = time.perf_counter() - self.wall
        return max(0.0, elapsed - (compiler_seconds() - self.compiling))
