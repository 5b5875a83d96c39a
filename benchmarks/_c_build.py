"""Building the C yardsticks of issue 29 (``_c_fast_reference.c``, ``_c_reference.c``) in the
run that times them: one place for the flags and ctypes signatures, used by ``bench_kernels.py``
and ``bench_mpl.py``."""

from __future__ import annotations

import ctypes
import subprocess
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent
FAST_SOURCE = HERE / "_c_fast_reference.c"
SLOW_SOURCE = HERE / "_c_reference.c"
# -fno-math-errno changes no value (exp and pow only stop setting errno), but lets the compiler
# treat them as pure: the 5-cell mPL ran 18 % faster with it (24.6 -> 20.1 ns/sample, same bits)
FAST_FLAGS = ("-O3", "-march=native", "-fno-math-errno", "-shared", "-fPIC")
SLOW_FLAGS = ("-O2", "-shared", "-fPIC")  # bench_mpl.py's _c_reference.c, libm's sinh

ARR = np.ctypeslib.ndpointer(dtype=np.float64, flags="C_CONTIGUOUS")
_I64, _DBL = ctypes.c_int64, ctypes.c_double
# mpl_fast, mpl_fast_unguarded, mpl_simulate: (u, n, x, n_cells, i_s, v_t, w, v_b, knee, cap,
# dt, y), x updated in place
MPL_ARGS = [ARR, _I64, ARR, _I64, ARR, ARR, ARR, _DBL, ARR, _DBL, _DBL, ARR]
PL_ARGS = [ARR, _I64, ARR, _I64, _DBL, ARR, ARR, _DBL, _DBL, _DBL, ARR, _DBL, ARR, _I64, ARR,
           ARR]
# mpl_g_fast: MPL_ARGS, then gc (4)
MPL_G_ARGS = [*MPL_ARGS, ARR]
# mpl_poly_fast: (u, n, x, n_cells, fc (n_cells x 4), knees (n_cells x 2), s, limit, gc, w, v_b,
# dt, y)
MPL_POLY_ARGS = [ARR, _I64, ARR, _I64, ARR, ARR, _DBL, _I64, ARR, ARR, _DBL, _DBL, ARR]
# chua_fast: (u, n, x, n_el, k0, k_inf, y_s, g, v_g, band, knee, cap, dt, y)
CHUA_ARGS = [ARR, _I64, ARR, _I64, ARR, ARR, ARR, ARR, ARR, ARR, ARR, ARR, _DBL, ARR]
# bobbio_fast: (u, n, x, n_forces, a (n_forces), c (n_forces + 1), b, y)
BOBBIO_ARGS = [ARR, _I64, ARR, _I64, ARR, ARR, _DBL, ARR]
# ladder_fast: (u, n, x, n_cells, band, g, w, v_b, dt, y)
LADDER_ARGS = [ARR, _I64, ARR, _I64, ARR, ARR, ARR, _DBL, _DBL, ARR]
# pi_fast: (u, n, p, n_play, z, n_creep, r, w_h, d_s, w_s, n_dz, c, w_k, b, y)
PI_ARGS = [ARR, _I64, ARR, _I64, ARR, _I64, ARR, ARR, ARR, ARR, _I64, ARR, ARR, _DBL, ARR]
# preisach_fast: (u, n, s, &n_s, capacity, A (K x L x L), L, K, weighted, poly, n_poly, slope,
# y)
PREISACH_ARGS = [ARR, _I64, ARR, ctypes.POINTER(_I64), _I64, ARR, _I64, _I64, _I64, ARR, _I64,
                 _DBL, ARR]
# boucwen_fast: (u, n, x (4), fresh, theta (7), dt, n_sub, linear, y)
BOUCWEN_ARGS = [ARR, _I64, ARR, _I64, ARR, _DBL, _I64, _I64, ARR]


def compile_shared(cc: str, flags, source: Path, out: Path,
                   include: Path | None = None) -> ctypes.CDLL:
    """``cc FLAGS [-I include] -o out source -lm``, loaded."""
    extra = ["-I", str(include)] if include else []
    subprocess.run([cc, *flags, *extra, "-o", str(out), str(source), "-lm"], check=True,
                   capture_output=True, text=True)
    return ctypes.CDLL(str(out))


def function(lib: ctypes.CDLL, name: str, argtypes) -> ctypes._CFuncPtr:
    fn = getattr(lib, name)
    fn.argtypes, fn.restype = argtypes, None
    return fn


def build_fast_reference(cc: str, workdir: Path) -> ctypes.CDLL:
    """``_c_fast_reference.c`` at ``FAST_FLAGS`` (functions mpl_fast, mpl_fast_unguarded,
    pl_fast, mpl_g_fast, mpl_poly_fast, chua_fast,
    bobbio_fast, ladder_fast, pi_fast, preisach_fast, boucwen_fast)."""
    return compile_shared(cc, FAST_FLAGS, FAST_SOURCE, Path(workdir) / "fast.so")


def fast_mpl(cc: str, workdir: Path) -> ctypes._CFuncPtr:
    """The fast reference's ``mpl_fast``, signature ``MPL_ARGS``."""
    return function(build_fast_reference(cc, workdir), "mpl_fast", MPL_ARGS)
