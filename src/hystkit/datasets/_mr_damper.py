"""Magnetorheological damper, force vs displacement (UTFSM MSc thesis, 2022).

Folder ``mr_damper_utfsm``. Training: 30 sine runs (6 amplitude/frequency settings x 5 coil
currents), ASCII files ``<amp>mm<freq>Hz<current>A.txt`` ('x' for the decimal point in the
names) with columns t [s], x [mm], dx/dt [mm/s], F [N]; their time column is uniform (1 ms or
5 ms) and used as it is. Validation: ``validacion_earthquake.mat``, one earthquake-type
displacement record with the force measured at five currents, no time column: time is the
row index over the documented 1 kHz. Both were filtered by the authors (moving averages).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..errors import InputError
from ._dataset import Dataset, DatasetInfo, Provenance, VariantInfo
from ._files import read_mat_matrix, read_table

__all__ = ["INFO", "load_mr_damper"]

NAME = "mr_damper"
FOLDER = "mr_damper_utfsm"
_COMMIT = "08753ffd7abd5b19053f7e79149c3a68f49bf73c"
_TRAIN_DIR = "Cap7_ModeloMR/BoucWen Ajuste 2/Preprocesamiento-sinusoidales/Preprocesados"
_EQ_FILE = "validacion_earthquake.mat"
_EQ_FS = 1000.0  # Hz, documented
_SETTINGS = ((2, 5.0), (5, 3.0), (10, 1.0), (25, 0.1), (25, 0.25), (25, 0.5))  # mm, Hz
_CURRENTS = (0.0, 0.25, 0.5, 0.75, 1.0)  # A
_EQ_CURRENTS = (0.2, 0.4, 0.6, 0.8, 1.0)  # A, columns 2-6 of the validation matrix
# Rows per training file (the tests check them against the files).
_TRAIN_ROWS = {
    "2mm5Hz": (449, 451, 448, 479, 450), "5mm3Hz": (4032, 4313, 4257, 4187, 4308),
    "10mm1Hz": (11654, 11251, 11274, 11504, 11854),
    "25mm0x1Hz": (19035, 9509, 9363, 9253, 10492),
    "25mm0x25Hz": (4486, 4658, 4614, 4613, 4453), "25mm0x5Hz": (4940, 4818, 4891, 4963, 4595),
}
_CREDIT = ("D. Maurel E., MSc thesis 'Simulacion hibrida en tiempo real de sistemas "
           "estructurales equipados con amortiguador magneto-reologico', UTFSM, Chile, 2022; "
           "data acquired by Maria Quiroz; (c) 2022 mequiroz, MIT licence")


def _x(value: float) -> str:
    return f"{value:g}".replace(".", "x")


def _train_variants() -> dict[str, tuple[str, float, float, float, int]]:
    """variant -> (file stem, amplitude mm, frequency Hz, current A, rows)."""
    table = {}
    for amp, freq in _SETTINGS:
        setting = f"{amp}mm{_x(freq)}Hz"
        for cur, rows in zip(_CURRENTS, _TRAIN_ROWS[setting], strict=True):
            table[f"{amp}mm_{freq:g}Hz_{cur:g}A"] = (f"{setting}{_x(cur)}A", amp, freq, cur, rows)
    return table


_TRAIN = _train_variants()
_EQ = {f"earthquake_{cur:g}A": (j + 1, cur) for j, cur in enumerate(_EQ_CURRENTS)}


def _source(variant: str) -> Provenance:
    if variant in _TRAIN:
        stem = _TRAIN[variant][0]
        repo_path, local = f"{_TRAIN_DIR}/{stem}.txt", f"train_sinusoids/{stem}.txt"
    else:
        repo_path, local = "Cap7_ModeloMR/BoucWen Ajuste 2/Validacion/validacion.mat", _EQ_FILE
    return Provenance(repository="github.com/DanielMaurelE/vRTHS_AMBC_MRdamper", commit=_COMMIT,
                      paths=(repo_path,), licence="MIT",
                      licence_file="LICENSE_MIT_mequiroz.txt", credit=_CREDIT,
                      files=(f"{FOLDER}/{local}",))


def _read(folder: Path, variant: str) -> Dataset:
    common = {"name": NAME, "variant": variant, "input_name": "displacement",
              "input_unit": "mm", "output_name": "damper force", "output_unit": "N"}
    if variant in _TRAIN:
        stem, amp, freq, cur, _ = _TRAIN[variant]
        local = f"train_sinusoids/{stem}.txt"
        table = read_table(folder / local, 4)
        return Dataset(
            **common, time=table[:, 0], input=table[:, 1], output=table[:, 3],
            description=f"Training run: {amp} mm, {freq:g} Hz sine displacement, coil current "
                        f"{cur:g} A (several cycles incl. a short start-up transient).",
            provenance=_source(variant),
            time_note="time column of the file",
            channels={"velocity": table[:, 2]}, channel_units={"velocity": "mm/s"},
            conditions={"amplitude_mm": float(amp), "frequency_Hz": freq, "current_A": cur},
            notes=("authors' pre-processing: moving average over 1/10 period, mean removed",
                   "velocity is the authors' finite difference of the displacement"))
    column, cur = _EQ[variant]
    data = read_mat_matrix(folder / _EQ_FILE, "data")
    if data.shape[1] != 6:
        raise InputError(f"{folder / _EQ_FILE}: variable 'data' has {data.shape[1]} columns, "
                         "expected 6")
    return Dataset(
        **common, time=np.arange(data.shape[0]) / _EQ_FS, input=data[:, 0],
        output=data[:, column],
        description=f"Validation run: earthquake-type commanded displacement (about -8 ... "
                    f"+7 mm, 65 s), force at coil current {cur:g} A.",
        provenance=_source(variant),
        time_note=f"no time column: row index / {_EQ_FS:g} Hz (documented rate)",
        conditions={"current_A": cur},
        notes=(("authors' pre-processing: 300-sample (0.3 s) moving average; the five currents "
               "are separate runs time-aligned by the authors"),))


_VARIANTS = tuple(
    VariantInfo(v, rows, 1000.0 if (a, f) in ((10, 1.0), (5, 3.0)) else 200.0, "train",
                f"{a} mm {f:g} Hz sine, {c:g} A")
    for v, (_, a, f, c, rows) in _TRAIN.items()
) + tuple(VariantInfo(v, 64648, _EQ_FS, "validation", f"earthquake displacement, {c:g} A")
          for v, (_, c) in _EQ.items())

INFO = DatasetInfo(
    name=NAME, folder=FOLDER,
    what="MR damper force vs displacement: 30 sine runs (train) + earthquake record "
         "(validation) at several coil currents",
    input_name="displacement", input_unit="mm", output_name="damper force", output_unit="N",
    licence="MIT", variants=_VARIANTS, default_variant="10mm_1Hz_0.5A", reader=_read,
    source=_source)


def load_mr_damper(variant: str = "10mm_1Hz_0.5A", *,
                   root: str | os.PathLike[str] | None = None) -> Dataset:
    """Load one MR damper run.

    Parameters
    ----------
    variant : str
        Training runs ``"<amp>mm_<freq>Hz_<current>A"`` (amp 2, 5, 10, 25 mm; currents 0,
        0.25, 0.5, 0.75, 1 A; e.g. ``"25mm_0.1Hz_0.75A"``) or validation runs
        ``"earthquake_<current>A"`` (0.2, 0.4, 0.6, 0.8, 1 A).
    root : path-like, optional
        Shared data root (default: ``$HYSTKIT_SHARED_DATA`` or a ``shared/data`` found above).

    Returns
    -------
    Dataset
        input = displacement [mm], output = force [N]; training runs also carry the channel
        ``velocity`` [mm/s]; ``conditions`` hold amplitude, frequency and current.
    """
    return INFO.read(variant, root)
