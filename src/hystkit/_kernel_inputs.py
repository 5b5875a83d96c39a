"""Arrays a compiled kernel only reads, passed read-only.

numba compiles one specialisation per argument type, and a read-only array is another type
than a writable one: a kernel fed a frozen recording's column (read-only) by one command and a
fresh buffer (writable) by another compiled twice, 1-2 s each on a first run (the stream's
kernel: once for ``compensate``, again for ``stream``). Passing what the kernel only reads
through `read_only` gives it one type whatever the caller holds, without a copy.
"""

from __future__ import annotations

import numpy as np

__all__ = ["read_only"]


def read_only(a: np.ndarray) -> np.ndarray:
    """`a` if it is read-only already, else a read-only view of it (no copy: writing to `a`
    still shows through the view)."""
    if not a.flags.writeable:
        return a
    view = a.view()
    view.flags.writeable = False
    return view
