"""
The Bouc-Wen hysteretic benchmark (Noel & Schoukens 2016) end to end with hystkit's boucwen
===========================================================================================

Not run when the site is built: it needs the shared Bouc-Wen data and h5py, which the build
machine (CI) does not have. Its results are in :doc:`/models/boucwen`.

Data: ``boucwen_benchmark`` in the shared data folder (read-only; origin and licence in its
README.txt; ``hystkit datasets show boucwen`` names the five files of github.com/forgi86/dynonet
and where they go; without them this script ends in one line saying so). Training: a 5-period random-phase multisine (8192 samples per period, 750 Hz,
50 N rms, 5-150 Hz) with the generator's band-limited output noise. Validation: the official
noiseless multisine (one steady-state period) and sine sweep (18 -> 52 Hz at 10 Hz/min from rest).

Method (docs/models/boucwen.md):

1. The force, known at 750 Hz, is band-limited; the model runs on it interpolated 4x (DFT
   zero-padding for the periodic multisines, a polyphase FIR for the sweep), 2 RK4 substeps per
   fine sample (3 kHz grid, 6 kHz integration), and its output is read every 4th fine sample.
2. Fit on the average of training periods 2-5 (the first holds the transient from rest; the
   average halves the noise): one period of force run twice from rest, the second compared.
   All 7 parameters (m, c, k, alpha, beta, gamma, nu) by least squares on the simulation error.
3. Validate: multisine in steady state (two periods, the second compared), sweep from rest.
   RMS error in metres, the benchmark's figure of merit.

The true parameters are run through the same pipeline, and once more through an emulation of
the generator (15 kHz, MATLAB ``decimate(y, r, 'fir')`` = a 31-tap Hamming FIR per stage,
zero-phase): the multisine was decimated in stages 2, 2, 5 as in the benchmark's example
script, the sweep in one stage of 20 (found by trying both; see the doc).

Run: ``python examples/boucwen_benchmark.py [DATA_FOLDER]`` (needs h5py for train.h5; the
folder defaults to ``boucwen_benchmark`` below the shared data root, found as
``hystkit.datasets.find_root`` does). 20-35 s on the shared 2-core machine, most of it the fit.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from scipy.io import loadmat
from scipy.signal import firwin

from hystkit.datasets import DATASETS, DataNotFoundError, find_root
from hystkit.models import boucwen
from hystkit.models.boucwen import fit_boucwen

FS = 750.0  # benchmark sample rate [Hz]
PERIOD = 8192  # samples per multisine period
UPSAMPLE = 4  # band-limited interpolation of the force before the model
SUBSTEPS = 2  # RK4 steps per fine sample
GENERATOR_RATE = 20  # the generator integrated at 15 kHz = 20 x 750 Hz
# Published validation RMS on the multisine [m]. PNLSS: Noel, Esfahani, Kerschen, Schoukens,
# "A nonlinear state-space approach to hysteresis identification", MSSP 84 (2017) 171-184,
# polynomial degrees 3-5-7: -98.32 dB re 1 m (as tabulated in the pyvib PNLSS example).
PUBLISHED = (("PNLSS, degrees 3-5-7 (Noel et al. 2017)", 10 ** (-98.32 / 20)),
             ("best known (figure given to us; source not checked)", 7.5e-6))


INFO = DATASETS["boucwen"]
FILES = ("train.h5", "uval_multisine.mat", "yval_multisine.mat", "uval_sinesweep.mat",
         "yval_sinesweep.mat")


def data_folder(argument: str | None) -> Path:
    """The benchmark folder: the argument, else ``boucwen_benchmark`` below the shared data
    root (``$HYSTKIT_SHARED_DATA``, else a ``shared/data`` found above), with its five files.

    Raises
    ------
    DataNotFoundError
        No shared data root, or a file missing: one line saying where the files come from.
    """
    folder = Path(argument) if argument else find_root()[0] / INFO.folder
    missing = [name for name in FILES if not (folder / name).is_file()]
    if missing:
        more = f" (and {len(missing) - 1} more)" if len(missing) > 1 else ""
        raise DataNotFoundError(
            f"{folder / missing[0]}: file not found{more}; the benchmark's files come from "
            f"{INFO.provenance().repository} ({INFO.licence}): 'hystkit datasets show boucwen' "
            "lists them and where they go")
    return folder


def load(folder: Path) -> dict[str, np.ndarray]:
    """Training multisine (h5) and the two validation sets (.mat), as 1-D arrays."""
    import h5py  # only this example reads HDF5; the library does not need it

    with h5py.File(folder / "train.h5", "r") as f:
        data = {"u_train": np.asarray(f["multisine/u"]).ravel(),
                "y_train": np.asarray(f["multisine/y"]).ravel()}
    for name in ("uval_multisine", "yval_multisine", "uval_sinesweep", "yval_sinesweep"):
        data[name] = loadmat(folder / f"{name}.mat")[name].ravel()
    return data


def decimate_fir(y: np.ndarray, stages: Sequence[int], periodic: bool) -> np.ndarray:
    """MATLAB ``decimate(y, r, 'fir')`` per stage: ``fir1(30, 1/r)``, zero-phase, keep 1 in r."""
    for r in stages:
        b = firwin(31, 1.0 / r)  # Hamming window, unit DC gain: fir1's design
        if periodic:
            kernel = np.zeros(y.size)
            kernel[:b.size] = b
            kernel = np.roll(kernel, -(b.size // 2))
            y = np.fft.irfft(np.fft.rfft(y) * np.fft.rfft(kernel), y.size)
        else:
            y = np.convolve(y, b, mode="same")
        y = y[::r]
    return y


def multisine_response(structure: boucwen.BoucWenStructure, params: boucwen.BoucWenParams,
                       u_period: np.ndarray, factor: int) -> np.ndarray:
    """Steady-state output of one period on the fine grid (two periods run from rest)."""
    u_fine = boucwen.bandlimited_upsample(u_period, factor, periodic=True)
    y, _ = boucwen.simulate(structure, params, np.tile(u_fine, 2))
    return y[u_fine.size:]


def sweep_response(structure: boucwen.BoucWenStructure, params: boucwen.BoucWenParams,
                   u: np.ndarray, factor: int) -> np.ndarray:
    """Output on the fine grid of a run from rest."""
    y, _ = boucwen.simulate(structure, params,
                            boucwen.bandlimited_upsample(u, factor, periodic=False))
    return y


def rms(e: np.ndarray) -> float:
    return float(np.sqrt(np.mean(e**2)))


def validate(params: boucwen.BoucWenParams, data: dict[str, np.ndarray],
             generator: bool = False) -> tuple[float, float]:
    """Validation RMS [m] on the multisine and the sweep; ``generator`` emulates the data's
    15 kHz integration and FIR decimation instead of reading every 4th fine sample."""
    factor = GENERATOR_RATE if generator else UPSAMPLE
    structure = boucwen.BoucWenStructure(dt=1.0 / (FS * factor),
                                         substeps=1 if generator else SUBSTEPS)
    y_ms = multisine_response(structure, params, data["uval_multisine"], factor)
    y_sw = sweep_response(structure, params, data["uval_sinesweep"], factor)
    if generator:
        y_ms = decimate_fir(y_ms, (2, 2, 5), periodic=True)
        y_sw = decimate_fir(y_sw, (20,), periodic=False)
    else:
        y_ms, y_sw = y_ms[::factor], y_sw[::factor]
    return rms(y_ms - data["yval_multisine"]), rms(y_sw - data["yval_sinesweep"])


def fit(data: dict[str, np.ndarray]):
    """Fit on the average of training periods 2-5 (see the module docstring)."""
    u_period = data["u_train"][:PERIOD]
    y_mean = data["y_train"][PERIOD:].reshape(-1, PERIOD).mean(axis=0)
    structure = boucwen.BoucWenStructure(dt=1.0 / (FS * UPSAMPLE), substeps=SUBSTEPS)
    u_fine = boucwen.bandlimited_upsample(u_period, UPSAMPLE, periodic=True)
    return fit_boucwen(np.tile(u_fine, 2), y_mean, structure, stride=UPSAMPLE, discard=PERIOD)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").strip().partition("\n")[0])
    parser.add_argument("folder", nargs="?", help="boucwen_benchmark data folder")
    args = parser.parse_args(argv)
    folder = data_folder(args.folder)
    t_start = time.perf_counter()
    data = load(folder)
    periods = data["y_train"].reshape(-1, PERIOD)
    noise = rms(np.diff(periods[1:], axis=0)) / np.sqrt(2.0)  # periods differ only by noise
    result = fit(data)
    true = boucwen.BENCHMARK_PARAMS
    rows = [("hystkit boucwen fit (this script)", *validate(result.params, data)),
            ("  same, generator emulated", *validate(result.params, data, generator=True)),
            ("true parameters", *validate(true, data)),
            ("  same, generator emulated", *validate(true, data, generator=True))]
    rows += [(name, value, float("nan")) for name, value in PUBLISHED]

    print(f"training output noise (from period differences): {noise:.2e} m rms")
    print(f"fit: {result.seconds:.1f} s, {result.n_evaluations} residual and Jacobian "
          f"evaluations, training rms {np.sqrt(result.cost / PERIOD):.2e} m (on the 4-period "
          f"average)")
    print(f"{'':10s}{'fitted':>14s}{'true':>14s}")
    for name in ("m", "c", "k", "alpha", "beta", "gamma", "nu"):
        print(f"{name:10s}{getattr(result.params, name):14.6g}{getattr(true, name):14.6g}")
    print()
    print(f"{'validation RMS error [m]':54s}{'multisine':>11s}{'sine sweep':>12s}")
    for name, e_ms, e_sw in rows:
        sweep = f"{e_sw:12.2e}" if np.isfinite(e_sw) else f"{'-':>12s}"
        print(f"{name:54s}{e_ms:11.2e}{sweep}")
    print(f"\ntotal {time.perf_counter() - t_start:.0f} s")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except DataNotFoundError as exc:  # one line: where the data come from and where they go
        sys.exit(f"boucwen_benchmark.py: {exc}")
    except ImportError as exc:  # h5py, for train.h5
        sys.exit(f"boucwen_benchmark.py: {exc} (pip install 'h5py>=3.10')")
