"""Forward kernels against the fastest plain C (issue 29, items 1-2): every ratio is to ``fast C``.

Run:  python benchmarks/bench_kernels.py [--quick] [--before REV] [--only FAMILIES]   (a few
      minutes; writes benchmarks/last_run_kernels.txt; --quick: fewer rounds; --before REV: one
      more column, the bare kernel of git revision REV, paired in the same rounds; --only
      pi,boucwen: those families only, nothing written)

Models: every registered family, each fitted (direct mode, centring fit) on the virtual
sensor's sine recording (seed 1) at its default size (mPL also at 3 and 5 cells; ``CASES``):
realistic parameters, e.g. the 5-cell mPL has two nearly linear cells (V_T ~ 1e3). Inputs: that
recording's normalised sensor (8000 samples) and the sine recordings of seeds 2, 3, ...
normalised the same way and joined (100 000).

Columns, ns per sample, each built in this run and called on the same input:

* ``fast C``: ``_c_fast_reference.c``, ``cc -O3 -march=native -fno-math-errno`` (no
  -ffast-math; -fno-math-errno changes no result, only errno), one function per family, sizes
  taken at run time as the numba kernels take them: one exp per cell, sinh from its series
  below |a| = 0.5, per-cell constants out of the loop (mPL, mpl-g); one pow per cell (PL);
  tanh and one expm1 per element (Chua); no libm call (mpl-poly, PI, Preisach, Bobbio, ladder);
  RK4 with 1 / m (Bouc-Wen). Its comment says what was measured for each choice. The
  yardstick;
* ``C fixed``: the same file built once per model with its sizes as compile-time constants
  (``-DFIX_A=..``): loops unrolled, no trip-count tests. What a C programmer writing for one
  model gets beyond it (0.74-0.98x);
* ``C no guard``: the fast C without the series, sinh = (e - 1/e) / 2 everywhere (mPL only):
  what the guard costs (measured: nothing, 0.96-1.10x), and (agreement table) what it saves;
* ``slow C``: ``_c_reference.c`` as ``bench_mpl.py`` builds it (``cc -O2``, libm's sinh, the
  kernel's operation order; mPL only);
* ``simulate``: ``family.simulate`` (the numba kernel with its Python wrapper: checks, rest
  state, knees; a fixed cost per call, so the ratio falls from 8000 to 100k samples);
* ``kernel``: the numba kernel alone, called as the wrapper calls it (Preisach: ``forward``;
  Bouc-Wen: ``simulate`` with its state array);
* ``export``: the model written by ``hystkit export --double`` (the command line, on the model
  file ``hystkit fit`` would write), its ``model_step`` called per sample from a driver that
  includes the generated C file, compiled with the fast C's flags (the compensator around it,
  centring and flags, is ``bench_export.py``'s). Its sizes *and parameter values* are
  constants of the C file, which the compiler folds: for the small linear-algebra families
  (PI, Bobbio, ladder) it beats even ``C fixed``.

Timing: rounds paired and interleaved (each round calls every column once, in turn: A B C A B
C ...; the first call of each is untimed), the thread's CPU time (``time.thread_time``) and the
wall time (``perf_counter``) around a call; each table gives the median ns per sample and, per
column, the median over rounds of that round's ratio to the round's ``fast C`` (pairing cancels
most of the load from other processes). CPU time is the cost: on a busy 2-core machine a
100k-sample call (2-7 ms) outlasts the scheduler's slice and its wall time includes waiting for
other processes (measured: up to 2-4x on some columns, none at 8000 samples).

Agreement: per column, max |y - y_ref| / max |y_ref| on the 8000-sample input, ``y_ref`` the
family's readable reference (``simulate_reference``, a Python loop over ``step``).
"""

from __future__ import annotations

import argparse
import ctypes
import importlib.util
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

if __name__ == "__main__":
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numba
import numpy as np
from _c_build import (
    ARR,
    BOBBIO_ARGS,
    BOUCWEN_ARGS,
    CHUA_ARGS,
    FAST_FLAGS,
    FAST_SOURCE,
    LADDER_ARGS,
    MPL_ARGS,
    MPL_G_ARGS,
    MPL_POLY_ARGS,
    PI_ARGS,
    PL_ARGS,
    PREISACH_ARGS,
    SLOW_FLAGS,
    SLOW_SOURCE,
    build_fast_reference,
    compile_shared,
    function,
)

from hystkit.compensation import fit_compensator, save_compensator
from hystkit.models.bobbio import model as bobbio
from hystkit.models.boucwen import divergence as boucwen_divergence
from hystkit.models.boucwen import model as boucwen
from hystkit.models.chua import model as chua
from hystkit.models.gpreisach import model as gpreisach
from hystkit.models.ladder import model as ladder
from hystkit.models.mpl import model as mpl
from hystkit.models.mpl_g import model as mpl_g
from hystkit.models.mpl_poly import model as mpl_poly
from hystkit.models.mpl_poly.resistors import knee_points
from hystkit.models.pl import model as pl
from hystkit.models.preisach import model as preisach
from hystkit.sensors import simulate_experiment

HERE = Path(__file__).parent
# each family at its default size (mPL also at 3 and 5 cells): mpl-g, mpl-poly and Chua 1 cell,
# PI 10 plays, Preisach 20 levels, the generalised Preisach 16 levels (two tables), Bouc-Wen 2
# RK4 substeps, Bobbio-Marrucci 10 springs, the ladder 2 cells
CASES = (("mpl", 1), ("mpl", 3), ("mpl", 5), ("pl", 2), ("mpl-g", 1), ("mpl-poly", 1),
         ("chua", 1), ("pi", 10), ("preisach", 20), ("gpreisach", 16), ("boucwen", 2),
         ("bobbio", 10), ("ladder", 2))
LABEL_WIDTH = 12
CELL_FAMILIES = ("mpl", "pl", "mpl-g", "mpl-poly", "chua", "ladder")  # size = cells: the ns/cell column
KERNELS_FOLDER = {"gpreisach": "preisach"}  # the generalised model runs the classical kernels
SIZES = (8000, 100_000)
ROUNDS = {8000: 101, 100_000: 31}
QUICK_ROUNDS = {8000: 31, 100_000: 11}
COLUMNS = ("fast C", "C fixed", "C no guard", "slow C", "simulate", "kernel", "export")
# CPU time first: on a shared machine a call longer than the scheduler's slice (~2 ms here)
# waits for the other processes, which wall time counts and CPU time does not.
CLOCKS = {"cpu": "CPU time (thread)", "wall": "wall time"}

# Calls the exported model's static model_rest / model_step: the generated file is included.
_EXPORT_DRIVER = r"""#include <stdint.h>
#include "{name}.c"
void export_run(const double *u, int64_t n, double *y)
{{
    static real x[1 << 16];  /* the Preisach state: capacity + 1 + capacity running sums */
    model_rest(x, u[0]);
    for (int64_t i = 0; i < n; ++i) y[i] = model_step(x, u[i]);
}}
"""


@dataclass
class Case:
    """One fitted model, its inputs and a callable per column (``fn(u) -> y``)."""

    family: str
    size: int
    comp: object
    inputs: dict = field(default_factory=dict)
    columns: dict = field(default_factory=dict)

    @property
    def label(self) -> str:
        return f"{self.family} {self.size}"


def _inputs(comp, fit_rec) -> dict:
    parts, seed = [comp.normalised_sensor(fit_rec.sensor)], 2
    while sum(p.size for p in parts[1:]) < SIZES[1]:
        parts.append(comp.normalised_sensor(simulate_experiment("sine", seed).sensor))
        seed += 1
    return {SIZES[0]: np.ascontiguousarray(parts[0]),
            SIZES[1]: np.ascontiguousarray(np.concatenate(parts[1:])[:SIZES[1]])}


def c_function(lib, name: str, argtypes):
    """``function`` with every array argument a raw address (``addr``): ndpointer's checks
    cost ~1.5 us an array and call (15 us a call for mpl-poly's nine, 1.8 ns/sample at 8000
    samples), a cost the numba kernels' dispatch (~2 us) does not have."""
    return function(lib, name, [ctypes.c_void_p if t is ARR else t for t in argtypes])


def addr(a: np.ndarray) -> int:
    """The address of a C-contiguous float64 array (kept alive by the caller)."""
    assert a.dtype == np.float64 and a.flags.c_contiguous
    return a.ctypes.data


def _consts(*arrays) -> tuple:
    """Contiguous float64 copies of a model's parameter arrays and their addresses: taken once
    per model, not per call (the closure keeps the arrays alive)."""
    kept = tuple(np.ascontiguousarray(a, dtype=float) for a in arrays)
    return kept, tuple(addr(a) for a in kept)


def _mpl_columns(comp, fast, slow) -> dict:
    s, p = comp.structure, comp.params
    cap, dt = s.slope_cap / s.dt, s.dt
    kept, (i_s, v_t, w, knee) = _consts(p.i_s, p.v_t, p.w, mpl.knee_voltage(s, p))

    def c_run(fn):
        def run(u, kept=kept):
            x, y = np.full(s.n_cells, u[0]), np.empty(u.size)
            fn(addr(u), u.size, addr(x), s.n_cells, i_s, v_t, w, p.v_b, knee, cap, dt, addr(y))
            return y
        return run

    return {"fast C": c_run(c_function(fast, "mpl_fast", MPL_ARGS)),
            "C no guard": c_run(c_function(fast, "mpl_fast_unguarded", MPL_ARGS)),
            "slow C": c_run(c_function(slow, "mpl_simulate", MPL_ARGS))}


def _mpl_kernel(comp, kernels):
    s, p = comp.structure, comp.params
    rest = (p.i_s, p.v_t, p.w, p.v_b, mpl.knee_voltage(s, p), s.slope_cap / s.dt, s.dt)
    return lambda u: kernels.simulate(u, np.full(s.n_cells, u[0]), *rest)[0]


def _pl_columns(comp, fast) -> dict:
    s, p = comp.structure, comp.params
    i_t, thr, knee, power, g_lin, dt = pl.kernel_args(s, p)
    n_basis = np.asarray(p.a).size
    kept, (thr, knee, w, brk, a) = _consts(thr, knee, p.w, pl.basis_breakpoints(s.n_basis),
                                          p.a)
    fn = c_function(fast, "pl_fast", PL_ARGS)

    def run(u, kept=kept):
        x, y = np.full(s.n_cells, u[0]), np.empty(u.size)
        fn(addr(u), u.size, addr(x), s.n_cells, i_t, thr, knee, power, g_lin, dt, w, p.v_b,
           brk, n_basis, a, addr(y))
        return y

    return {"fast C": run}


def _pl_kernel(comp, kernels):
    s, p = comp.structure, comp.params
    rest = (*pl.kernel_args(s, p), p.w, p.v_b, pl.basis_breakpoints(s.n_basis),
            np.ascontiguousarray(p.a, dtype=float))
    return lambda u: kernels.simulate(u, np.full(s.n_cells, u[0]), *rest)[0]


def _mpl_g_args(comp) -> tuple:
    s, p = comp.structure, comp.params
    return (p.i_s, p.v_t, p.w, float(p.v_b), mpl.knee_voltage(s, p), s.slope_cap / s.dt, s.dt,
            np.ascontiguousarray(p.g, dtype=float))


def _mpl_g_columns(comp, fast) -> dict:
    i_s, v_t, w, v_b, knee, cap, dt, gc = _mpl_g_args(comp)
    n_cells = i_s.size
    kept, (i_s, v_t, w, knee, gc) = _consts(i_s, v_t, w, knee, gc)
    fn = c_function(fast, "mpl_g_fast", MPL_G_ARGS)

    def run(u, kept=kept):
        x, y = np.full(n_cells, u[0]), np.empty(u.size)
        fn(addr(u), u.size, addr(x), n_cells, i_s, v_t, w, v_b, knee, cap, dt, addr(y), gc)
        return y

    return {"fast C": run}


def _mpl_g_kernel(comp, kernels):
    i_s, v_t, w, v_b, knee, cap, dt, gc = _mpl_g_args(comp)
    return lambda u: kernels.simulate(u, np.full(i_s.size, u[0]), gc, w, v_b, i_s, v_t, knee,
                                      cap, dt)[0]


def _mpl_poly_args(comp) -> tuple:
    s, p = comp.structure, comp.params
    return (np.ascontiguousarray(p.f, dtype=float), np.ascontiguousarray(knee_points(s, p)),
            s.slope_cap / s.dt, bool(s.limit), np.ascontiguousarray(p.g, dtype=float), p.w,
            float(p.v_b), s.dt)


def _mpl_poly_columns(comp, fast) -> dict:
    fc, knees, slope, limit, gc, w, v_b, dt = _mpl_poly_args(comp)
    n_cells = fc.shape[0]
    kept, (fc, knees, gc, w) = _consts(fc, knees, gc, w)
    fn = c_function(fast, "mpl_poly_fast", MPL_POLY_ARGS)

    def run(u, kept=kept):
        x, y = np.full(n_cells, u[0]), np.empty(u.size)
        fn(addr(u), u.size, addr(x), n_cells, fc, knees, slope, int(limit), gc, w, v_b, dt,
           addr(y))
        return y

    return {"fast C": run}


def _mpl_poly_kernel(comp, kernels):
    """The kernel with the wrapper's bound when limited (inf: only non-finite states stop)."""
    fc, knees, slope, limit, gc, w, v_b, dt = _mpl_poly_args(comp)
    bound = np.inf if limit else 1e300
    return lambda u: kernels.simulate(u, np.full(fc.shape[0], u[0]), fc, knees, slope, limit,
                                      gc, w, v_b, dt, bound)[0]


def _rest(module, comp, u) -> np.ndarray:
    """The start of ``simulate`` with ``x0=None`` (the family's rest state at ``u[0]``)."""
    return np.array(module.RUNS.initial(comp.structure, comp.params, None, u[0], False),
                    dtype=float)


def _chua_columns(comp, fast) -> dict:
    *arrays, dt = chua.kernel_args(comp.structure, comp.params)
    kept, addresses = _consts(*arrays)
    fn = c_function(fast, "chua_fast", CHUA_ARGS)

    def run(u, kept=kept):
        x, y = _rest(chua, comp, u), np.empty(u.size)
        fn(addr(u), u.size, addr(x), x.size, *addresses, dt, addr(y))
        return y

    return {"fast C": run}


def _chua_kernel(comp, kernels):
    args = chua.kernel_args(comp.structure, comp.params)
    return lambda u: kernels.simulate(u, _rest(chua, comp, u), *args)[0]


def _bobbio_columns(comp, fast) -> dict:
    p = comp.params
    kept, (friction, compliance) = _consts(p.friction, p.compliance)
    fn = c_function(fast, "bobbio_fast", BOBBIO_ARGS)

    def run(u, kept=kept):
        x, y = _rest(bobbio, comp, u), np.empty(u.size)
        fn(addr(u), u.size, addr(x), x.size, friction, compliance, float(p.offset), addr(y))
        return y

    return {"fast C": run}


def _bobbio_kernel(comp, kernels):
    """``simulate`` (``forces`` and the output the wrapper formed from them, a matrix-vector
    product, for revisions before it)."""
    p = comp.params
    if hasattr(kernels, "simulate"):
        return lambda u: kernels.simulate(u, _rest(bobbio, comp, u), p.friction, p.compliance,
                                          float(p.offset))[0]

    def run(u):
        f = kernels.forces(u, _rest(bobbio, comp, u), p.friction)[0]
        return p.compliance[0] * u + f @ p.compliance[1:] + p.offset

    return run


def _ladder_args(comp) -> tuple:
    s, p = comp.structure, comp.params
    return p.band, ladder.effective_conductance(s, p), p.w, float(p.v_b), s.dt


def _ladder_columns(comp, fast) -> dict:
    band, g, w, v_b, dt = _ladder_args(comp)
    kept, (band, g, w) = _consts(band, g, w)
    fn = c_function(fast, "ladder_fast", LADDER_ARGS)

    def run(u, kept=kept):
        x, y = _rest(ladder, comp, u), np.empty(u.size)
        fn(addr(u), u.size, addr(x), x.size, band, g, w, v_b, dt, addr(y))
        return y

    return {"fast C": run}


def _ladder_kernel(comp, kernels):
    """``simulate`` (``states`` and the output the wrapper formed from them, a matrix-vector
    product, for revisions before it)."""
    band, g, w, v_b, dt = _ladder_args(comp)
    if hasattr(kernels, "simulate"):
        return lambda u: kernels.simulate(u, _rest(ladder, comp, u), band, g, w, v_b, dt)[0]

    def run(u):
        s = kernels.states(u, _rest(ladder, comp, u), band, g, dt)[0]
        return w[0] * u + s @ w[1:] - v_b

    return run


def _pi_parts(comp) -> tuple:
    s, p = comp.structure, comp.params
    return (np.ascontiguousarray(s.play_thresholds, dtype=float), p.w_h, p.d_s, p.w_s,
            s.creep_gains, p.w_k, float(p.b))


def _pi_columns(comp, fast) -> dict:
    r, w_h, d_s, w_s, c, w_k, b = _pi_parts(comp)
    n_play, n_creep, n_dz = r.size, c.size, d_s.size
    kept, (r, w_h, d_s, w_s, c, w_k) = _consts(r, w_h, d_s, w_s, c, w_k)
    fn = c_function(fast, "pi_fast", PI_ARGS)

    def run(u, kept=kept):
        p, z, y = np.full(n_play, u[0]), np.full(n_creep, u[0]), np.empty(u.size)
        fn(addr(u), u.size, addr(p), n_play, addr(z), n_creep, r, w_h, d_s, w_s, n_dz, c, w_k,
           b, addr(y))
        return y

    return {"fast C": run}


def _pi_kernel(comp, kernels):
    r, w_h, d_s, w_s, c, w_k, b = _pi_parts(comp)
    return lambda u: kernels.simulate(u, np.full(r.size, u[0]), np.full(c.size, u[0]), r, w_h,
                                      d_s, w_s, c, w_k, b)[0]


def _preisach_parts(comp) -> tuple:
    """Demagnetised start staircase and the kernels' tables, weighted, poly, slope (the
    classical and the generalised model alike)."""
    s, p = comp.structure, comp.params
    module = preisach if comp.family.name == "preisach" else gpreisach
    tables, weighted, poly, slope = module.kernel_parts(p)
    return (preisach.demagnetised_state(s.levels - 1), np.ascontiguousarray(tables),
            bool(weighted), np.ascontiguousarray(poly, dtype=float), float(slope))


def _preisach_columns(comp, fast) -> dict:
    start, tables, weighted, poly, slope = _preisach_parts(comp)
    cap, (n_tab, levels, _), n_poly = comp.structure.capacity, tables.shape, poly.size
    kept, (tables, poly) = _consts(tables, poly)
    fn = c_function(fast, "preisach_fast", PREISACH_ARGS)

    def run(u, kept=kept):
        stair, y = np.zeros(cap), np.empty(u.size)
        stair[:start.size] = start
        fn(addr(u), u.size, addr(stair), ctypes.byref(ctypes.c_int64(start.size)), cap, tables,
           levels, n_tab, int(weighted), poly, n_poly, slope, addr(y))
        return y

    return {"fast C": run}


def _preisach_kernel(comp, kernels):
    """``forward`` (``run_tables`` and the output line the wrappers added in numpy, for
    revisions before it)."""
    start, tables, weighted, poly, slope = _preisach_parts(comp)
    cap = comp.structure.capacity
    if hasattr(kernels, "forward"):
        return lambda u: kernels.forward(u, start, tables, weighted, poly, slope, cap)[0]

    def run(u):
        relay = kernels.run_tables(u, start, tables, cap)[0]
        u_clip = np.clip(u, -1.0, 1.0)
        if weighted:
            w = 0.5 * (1.0 + u_clip)
            relay = (1.0 - w) * relay[:, 0] + w * relay[:, 1]
        else:
            relay = relay[:, 0]
        return relay + np.polynomial.polynomial.polyval(u_clip, poly) + slope * (u - u_clip)

    return run


def _boucwen_parts(comp, u) -> tuple:
    s, p = comp.structure, comp.params
    x0 = boucwen.initial_state(s, p, u[0])
    return (x0, p.as_array(), s.dt, s.substeps, s.input_hold == "linear",
            boucwen_divergence.divergence_bound(s, p, x0, u))


def _boucwen_columns(comp, fast) -> dict:
    fn = c_function(fast, "boucwen_fast", BOUCWEN_ARGS)

    def run(u):
        x0, theta, dt, n_sub, linear, _ = _boucwen_parts(comp, u)
        y = np.empty(u.size)
        fn(addr(u), u.size, addr(x0), 1, addr(theta), dt, n_sub, int(linear), addr(y))
        return y

    return {"fast C": run}


def _boucwen_kernel(comp, kernels):
    def run(u):
        x0, theta, dt, n_sub, linear, bound = _boucwen_parts(comp, u)
        return kernels.simulate(u, x0, True, theta, dt, n_sub, linear, bound)[0][:, 0]

    return run


# family: (its model module (simulate_reference), its C columns, its bare kernel on a
# kernels module: this tree's or a past revision's, its sizes in the order of the fast C's
# size arguments: the "C fixed" build's -DFIX_A, -DFIX_B, -DFIX_C)
FAMILY_SETUP = {
    "mpl": (mpl, _mpl_columns, _mpl_kernel, lambda comp: (comp.structure.n_cells,)),
    "pl": (pl, _pl_columns, _pl_kernel,
           lambda comp: (comp.structure.n_cells, np.asarray(comp.params.a).size)),
    "mpl-g": (mpl_g, _mpl_g_columns, _mpl_g_kernel, lambda comp: (comp.params.i_s.size,)),
    "mpl-poly": (mpl_poly, _mpl_poly_columns, _mpl_poly_kernel,
                 lambda comp: (np.asarray(comp.params.f).shape[0],)),
    "chua": (chua, _chua_columns, _chua_kernel, lambda comp: (comp.params.k0.size,)),
    "bobbio": (bobbio, _bobbio_columns, _bobbio_kernel,
               lambda comp: (comp.params.friction.size,)),
    "ladder": (ladder, _ladder_columns, _ladder_kernel, lambda comp: (comp.params.band.size,)),
    "pi": (importlib.import_module("hystkit.models.pi.model"), _pi_columns, _pi_kernel,
           lambda comp: (comp.structure.n_play, comp.structure.n_creep,
                         comp.params.d_s.size)),
    "preisach": (preisach, _preisach_columns, _preisach_kernel,
                 lambda comp: (comp.structure.levels, comp.structure.capacity, 1)),
    "gpreisach": (gpreisach, _preisach_columns, _preisach_kernel,
                  lambda comp: (comp.structure.levels, comp.structure.capacity, 2)),
    "boucwen": (boucwen, _boucwen_columns, _boucwen_kernel,
                lambda comp: (comp.structure.substeps,)),
}


def _fixed_column(comp, family: str, label: str, cc: str, tmp: Path, slow):
    """The fast C built with this model's sizes as compile-time constants."""
    _, c_columns, _, sizes = FAMILY_SETUP[family]
    defines = [f"-DFIX_{slot}={size}" for slot, size in zip("ABC", sizes(comp), strict=False)]
    name = label.replace(" ", "_").replace("-", "_")
    lib = compile_shared(cc, (*FAST_FLAGS, *defines), FAST_SOURCE, tmp / f"fixed_{name}.so")
    columns = _mpl_columns(comp, lib, slow) if family == "mpl" else c_columns(comp, lib)
    return columns["fast C"]


def _export_column(comp, label: str, cc: str, tmp: Path):
    """``hystkit export --double`` on the saved model, its model_step compiled as fast C."""
    name = label.replace(" ", "_").replace("-", "_")
    model_file = tmp / f"{name}.json"
    save_compensator(comp, model_file)
    folder = tmp / f"{name}_c"
    subprocess.run([sys.executable, "-m", "hystkit", "export", str(model_file), "--double",
                    "--name", name, "--out", str(folder)], check=True, capture_output=True)
    driver = folder / "bench_driver.c"
    driver.write_text(_EXPORT_DRIVER.format(name=name))
    lib = compile_shared(cc, FAST_FLAGS, driver, folder / "driver.so", include=folder)
    fn = c_function(lib, "export_run", [ARR, ctypes.c_int64, ARR])

    def run(u):
        y = np.empty(u.size)
        fn(addr(u), u.size, addr(y))
        return y

    return run


def load_kernels_at(rev: str, tmp: Path, family: str = "mpl"):
    """``models/<family>/kernels.py`` of git revision ``rev`` as a module of its own, for a
    paired before/after in one run; ImportError if it imports its package (relative
    imports)."""
    source = f"{rev}:src/hystkit/models/{family}/kernels.py"
    text = subprocess.run(["git", "-C", str(HERE), "show", source], capture_output=True,
                          text=True, check=True).stdout
    path = tmp / f"{family}_kernels_{rev.replace('/', '_')}.py"
    path.write_text(text)
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def build_cases(cc: str, tmp: Path, before_rev: str | None = None,
                only: set | None = None) -> list[Case]:
    fast = build_fast_reference(cc, tmp)
    slow = compile_shared(cc, SLOW_FLAGS, SLOW_SOURCE, tmp / "slow.so")
    fit_rec = simulate_experiment("sine", 1)
    cases = []
    for family, size in CASES:
        if only is not None and family not in only:
            continue
        comp = fit_compensator(fit_rec, size, model=family, diagnose=False)
        case = Case(family, size, comp, _inputs(comp, fit_rec))
        _, c_columns, kernel, _ = FAMILY_SETUP[family]
        case.columns = _mpl_columns(comp, fast, slow) if family == "mpl" else c_columns(comp,
                                                                                        fast)
        case.columns["C fixed"] = _fixed_column(comp, family, case.label, cc, tmp, slow)
        model = comp.family
        case.columns["simulate"] = (
            lambda u, m=model, s=comp.structure, p=comp.params: m.simulate(s, p, u)[0])
        folder = KERNELS_FOLDER.get(family, family.replace("-", "_"))
        case.columns["kernel"] = kernel(comp, importlib.import_module(
            f"hystkit.models.{folder}.kernels"))
        case.columns["export"] = _export_column(comp, case.label, cc, tmp)
        if before_rev:
            try:
                past = load_kernels_at(before_rev, tmp, folder)
            except ImportError:  # a kernels.py that imports its package: no column
                past = None
            if past is not None:
                case.columns[f"kernel@{before_rev}"] = kernel(comp, past)
        cases.append(case)
    return cases


def agreement(case: Case) -> dict:
    u = case.inputs[SIZES[0]]
    module = FAMILY_SETUP[case.family][0]
    ref, _ = module.simulate_reference(case.comp.structure, case.comp.params, u)
    scale = float(np.max(np.abs(ref)))
    return {name: float(np.max(np.abs(fn(u) - ref))) / scale for name, fn in case.columns.items()}


def time_case(case: Case, n: int, rounds: int) -> dict:
    """Per clock (``cpu``: this thread's CPU time, ``wall``: perf_counter): median ns per
    sample per column, and the median of the per-round ratios to fast C."""
    u = case.inputs[n]
    for fn in case.columns.values():
        fn(u)
    seconds = {clock: {name: [] for name in case.columns} for clock in CLOCKS}
    for _ in range(rounds):
        for name, fn in case.columns.items():
            c0, t0 = time.thread_time(), time.perf_counter()
            fn(u)
            seconds["wall"][name].append(time.perf_counter() - t0)
            seconds["cpu"][name].append(time.thread_time() - c0)
    out = {}
    for clock, by_name in seconds.items():
        base = by_name["fast C"]
        out[clock] = {name: (statistics.median(t) * 1e9 / n,
                             statistics.median(a / b for a, b in zip(t, base, strict=True)))
                      for name, t in by_name.items()}
    return out


def _cpu() -> str:
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("model name"):
            return line.split(":", 1)[1].strip()
    return platform.processor() or "unknown"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer rounds")
    parser.add_argument("--before", metavar="REV", help="add the bare kernels of git revision "
                        "REV (paired with this tree's)")
    parser.add_argument("--only", metavar="FAMILIES", help="comma-separated families (e.g. "
                        "pi,boucwen), for development; does not write last_run_kernels.txt")
    args = parser.parse_args()
    only = set(args.only.split(",")) if args.only else None
    quick = args.quick
    columns = [*COLUMNS, *([f"kernel@{args.before}"] if args.before else [])]
    rounds = QUICK_ROUNDS if quick else ROUNDS
    cc = os.environ.get("CC", "cc")
    version = subprocess.run([cc, "--version"], capture_output=True, text=True,
                             check=True).stdout.splitlines()[0]
    head = git_head()
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    flags = " ".join(sys.argv[1:])
    lines = [(f"# bench_kernels.py {flags}, hystkit {head}; {_cpu()}, "
              f"{os.cpu_count()} cores, load {load}"),
             (f"# {version}; fast C / export: cc {' '.join(FAST_FLAGS)}; slow C: cc "
              f"{' '.join(SLOW_FLAGS)}; numpy {np.__version__}, numba {numba.__version__}"),
             (f"# rounds paired and interleaved: {rounds[SIZES[0]]} (8000 samples), "
              f"{rounds[SIZES[1]]} (100k); ns = median ns/sample; (x) = median of per-round "
              f"ratios to fast C")]

    def emit(text: str = "") -> None:
        lines.append(text)
        print(text, flush=True)

    print("\n".join(lines), flush=True)
    with tempfile.TemporaryDirectory(prefix="hystkit-kernels-") as tmp:
        t0 = time.perf_counter()
        cases = build_cases(cc, Path(tmp), args.before, only)
        emit(f"# fits, exports and builds: {time.perf_counter() - t0:.1f} s")
        emit()
        emit("Agreement with the readable reference (simulate_reference), 8000 samples: "
             "max|y - y_ref| / max|y_ref|")
        emit(f"{'model':<{LABEL_WIDTH}}" + "".join(f"{c:>16}" for c in columns))
        for case in cases:
            agree = agreement(case)
            emit(f"{case.label:<{LABEL_WIDTH}}" + "".join(
                f"{agree[c]:>16.1e}" if c in agree else f"{'-':>16}" for c in columns))
        for n in SIZES:
            results = [time_case(case, n, rounds[n]) for case in cases]
            for clock, clock_name in CLOCKS.items():
                emit()
                emit(f"{n} samples, {clock_name}: ns/sample (ratio to fast C)")
                emit(f"{'model':<{LABEL_WIDTH}}" + "".join(f"{c:>18}" for c in columns)
                     + f"{'ns/cell fast':>14}")
                for case, r in zip(cases, results, strict=True):
                    row = r[clock]
                    cells = "".join(f"{row[c][0]:>10.1f} ({row[c][1]:4.2f})" if c in row
                                    else f"{'-':>18}" for c in columns)
                    per_cell = (f"{row['fast C'][0] / case.size:>14.1f}"
                                if case.family in CELL_FAMILIES else f"{'-':>14}")
                    emit(f"{case.label:<{LABEL_WIDTH}}{cells}{per_cell}")
    emit(f"# load at the end: {', '.join(f'{x:.2f}' for x in os.getloadavg())}")
    if only is None:
        (HERE / "last_run_kernels.txt").write_text("\n".join(lines) + "\n")
    return 0


def git_head() -> str:
    out = subprocess.run(["git", "-C", str(HERE), "rev-parse", "--short", "HEAD"],
                         capture_output=True, text=True, check=False).stdout.strip()
    return out or "?"


if __name__ == "__main__":
    sys.exit(main())
