"""Piezo micromanipulator with capacitive displacement sensor (Aye & Ang, ICSTSD 2018).

Folder ``piezo_micromanipulator_capsensor``: an identification run and a test run whose
parts are uncompensated and under the author's inverse-hysteresis (DBO) feedforward. The files
have no time column: time is the row index over the documented 200 Hz (``Fs=200`` in the
author's scripts; 8027 rows = 40.1 s and 14155 rows = 70.8 s agree with the README).

Alignment follows the author: the identification run pairs output and input of the same row
(0 samples lag); in the test run the output of row k+1 belongs to the input of row k (1 sample
lag), so the test run's output is moved one sample earlier and its last input row dropped.
With that alignment the linear-fit residual of the output against the desired displacement is
2.48 (segment 0-16 s) and 0.326 (58-70 s) sensor units, the README's ~2.5 and ~0.33.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ._dataset import Dataset, DatasetInfo, Provenance, VariantInfo
from ._files import read_table

__all__ = ["INFO", "load_piezo_micromanipulator"]

NAME = "piezo_micromanipulator"
FS = 200.0  # Hz, the author's Fs
_COMMIT = "79fd060d86cdf69be2388e29bf57b0766c273650"
_REPO_DIR = "MatLabCode/DiscreteBacklashModel"
_CREDIT = ("Y. N. Aye, W. T. Ang, 'A Discrete Backlash Operator for Identification and "
           "Compensation of Hysteresis and Non-linearity for Piezoelectric Micromanipulator', "
           "ICSTSD 2018, Yangon; data (c) 2019 Yan Naing Aye, MIT licence")

# Windows [s] of the test run. The first three are the README's; the steady ones (ours) leave
# out the start transient (the sensor reads about -122 at t = 0, far off the loop) and the
# amplitude ramps, at full +-20 um amplitude. Inspecting the run second by second shows that
# the README's 'intermediate' 28-47 s is uncompensated up to 37 s and then driven by the same
# feedforward as 58-70 s (identical command-vs-desired map), hence the name 'mixed'.
TEST_SEGMENTS = {
    "uncompensated": (0.0, 16.0),
    "mixed": (28.0, 47.0),
    "feedforward": (58.0, 70.0),
    "uncompensated_steady": (1.0, 15.0),
    "feedforward_steady": (60.0, 70.0),
}
# Rows 3152..3351 (1-based), the one cycle the author identifies the model from.
ID_SEGMENTS = {"author_cycle": (3151 / FS, 3351 / FS)}

INFO_VARIANTS = (
    VariantInfo("identification", 8027, FS, "identification",
                "Model_Vi_Do.dat: 1 Hz sine drive 0-3.6 V, about 40 cycles, 40.1 s"),
    VariantInfo("test", 14154, FS, "test",
                "Test_Vi_Do_Di.dat: desired +-20 um 1 Hz sine; 0-16 s drive linear in the "
                "desired displacement (uncompensated), 58-70 s through the author's inverse "
                "(DBO) feedforward; channel desired_displacement"),
)


FOLDER = "piezo_micromanipulator_capsensor"
_FILES = {"identification": "Model_Vi_Do.dat", "test": "Test_Vi_Do_Di.dat"}


def _source(variant: str) -> Provenance:
    return Provenance(
        repository="github.com/yan9a/DiscreteBacklashOperator", commit=_COMMIT,
        paths=(f"{_REPO_DIR}/{_FILES[variant]}",), licence="MIT",
        licence_file="LICENSE_MIT_yan9a.txt", credit=_CREDIT,
        files=(f"{FOLDER}/{_FILES[variant]}",))


def _read(folder: Path, variant: str) -> Dataset:
    if variant == "identification":
        path = folder / _FILES[variant]
        table = read_table(path, 7, usecols=[0, 4])
        u, y, channels, lag = table[:, 0], table[:, 1], {}, 0
        segments, units = ID_SEGMENTS, {}
        description = ("Identification run: 1 Hz sine drive 0-3.6 V (DAC, 101 levels), "
                       "capacitive sensor output; the author fits one cycle (segment "
                       "author_cycle).")
    else:
        path = folder / _FILES[variant]
        table = read_table(path, 11, usecols=[0, 4, 8])
        lag = 1
        u, y = table[:-lag, 0], table[lag:, 1]
        channels = {"desired_displacement": table[:-lag, 2]}
        units = {"desired_displacement": "um"}
        segments = TEST_SEGMENTS
        description = ("Test run: desired displacement +-20 um 1 Hz sine. 0-16 s "
                       "uncompensated (drive = 1.83 V + 0.0797 V/um x desired), 58-70 s "
                       "with the author's inverse-hysteresis feedforward on the hardware.")
    time = np.arange(u.size) / FS
    notes = [(f"output aligned with {lag} sample(s) lag as the author does (output row k+"
             f"{lag} belongs to input row k){'; last input row dropped' if lag else ''}"),
             "sensor offset is arbitrary (the author plots output minus its mean)"]
    return Dataset(
        name=NAME, variant=variant, time=time, input=u, output=y,
        input_name="actuator command", input_unit="V",
        output_name="capacitive sensor displacement", output_unit="um",
        description=description,
        provenance=_source(variant),
        time_note=f"no time column: row index / {FS:g} Hz (the author's Fs)",
        segments=segments, channels=channels, channel_units=units, notes=tuple(notes))


INFO = DatasetInfo(
    name=NAME, folder=FOLDER,
    what="piezo flexure micromanipulator, capacitive sensor, 1 Hz sine; identification run "
         "+ test run with the author's hardware feedforward",
    input_name="actuator command", input_unit="V",
    output_name="capacitive sensor displacement", output_unit="um", licence="MIT",
    variants=INFO_VARIANTS, default_variant="identification", reader=_read, source=_source)


def load_piezo_micromanipulator(variant: str = "identification", *,
                                root: str | os.PathLike[str] | None = None) -> Dataset:
    """Load a run of the piezo micromanipulator data set.

    Parameters
    ----------
    variant : {"identification", "test"}
        The test run carries the channel ``desired_displacement`` [um] and the segments
        ``uncompensated`` (0-16 s), ``feedforward`` (58-70 s), ``mixed`` (28-47 s) and their
        ``*_steady`` full-amplitude parts.
    root : path-like, optional
        Shared data root (default: ``$HYSTKIT_SHARED_DATA`` or a ``shared/data`` found above).

    Returns
    -------
    Dataset
        input = actuator command [V], output = sensor displacement [um, arbitrary offset],
        200 Hz.
    """
    return INFO.read(variant, root)
