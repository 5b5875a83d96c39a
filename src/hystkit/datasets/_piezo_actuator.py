"""Piezo actuator, +-150 V 1 Hz sine, 5 kHz (Chandra et al., Appl. Phys. Lett. 2023).

Folder ``piezo_actuator_150V_1Hz``, file ``hysteresis_v_150_1hz.csv``: an empty first column,
then time [s], displacement [um] and voltage [V], no header. The time column is uniform to
within 0.02 % of its 0.2 ms step and is used as it is. The magnetic moment loop in the same
folder is a different system and not loaded here.
"""

from __future__ import annotations

import os
from pathlib import Path

from ._dataset import Dataset, DatasetInfo, Provenance, VariantInfo
from ._files import read_table

__all__ = ["INFO", "load_piezo_actuator"]

NAME = "piezo_actuator"
FOLDER = "piezo_actuator_150V_1Hz"
_FILE = "hysteresis_v_150_1hz.csv"
# The drive is 0 V before 3.2572 s (sensor offset and noise at rest); the authors fit rows
# 35000:45000, i.e. 7-9 s (two periods).
SEGMENTS = {"rest": (0.0, 3.2572), "excited": (3.2572, 10.0002), "authors_fit": (7.0, 9.0)}


def _source(variant: str) -> Provenance:
    return Provenance(
        repository="github.com/chandratue/SmartHysteresis",
        commit="e7672dabcabbc75341e9ea965d073f68b27e5cda", paths=(f"Data/{_FILE}",),
        licence="MIT (licence file only in the repository's initial commit a09eb32)",
        licence_file="LICENSE_MIT_initial_commit_a09eb32.txt",
        credit="A. Chandra et al., 'Discovery of sparse hysteresis models for piezoelectric "
               "materials', Appl. Phys. Lett. (2023), doi:10.1063/5.0146134; data (c) 2023 "
               "chandratue, MIT licence",
        files=(f"{FOLDER}/{_FILE}",))


def _read(folder: Path, variant: str) -> Dataset:
    path = folder / _FILE
    table = read_table(path, 4, sep=",", usecols=[1, 2, 3])
    return Dataset(
        name=NAME, variant=variant, time=table[:, 0], input=table[:, 2], output=table[:, 1],
        input_name="drive voltage", input_unit="V", output_name="displacement",
        output_unit="um",
        description="Real piezo actuator: 1 Hz sine drive +-150 V from 3.26 s (0 V before), "
                    "displacement -19.7 ... 19.7 um; the paper's 'real piezo' experiment.",
        provenance=_source(variant),
        time_note="time column of the file (5 kHz, uniform to 0.02 %)",
        segments=SEGMENTS, conditions={"amplitude_V": 150.0, "frequency_Hz": 1.0})


INFO = DatasetInfo(
    name=NAME, folder=FOLDER,
    what="piezo actuator, +-150 V 1 Hz sine, 5 kHz; one clean loop (no validation record)",
    input_name="drive voltage", input_unit="V", output_name="displacement", output_unit="um",
    licence="MIT (see README: licence only in the initial commit)",
    variants=(VariantInfo("150V_1Hz", 50001, 5000.0, "",
                          "10 s: 3.26 s at rest, then 1 Hz sine +-150 V; segments rest, "
                          "excited, authors_fit (7-9 s)"),),
    default_variant="150V_1Hz", reader=_read, source=_source)


def load_piezo_actuator(variant: str = "150V_1Hz", *,
                        root: str | os.PathLike[str] | None = None) -> Dataset:
    """Load the piezo actuator run.

    Parameters
    ----------
    variant : {"150V_1Hz"}
    root : path-like, optional
        Shared data root (default: ``$HYSTKIT_SHARED_DATA`` or a ``shared/data`` found above).

    Returns
    -------
    Dataset
        input = drive voltage [V], output = displacement [um], 5 kHz, 50001 samples; segments
        ``rest``, ``excited`` and ``authors_fit`` (the paper's 2-period fitting window).
    """
    return INFO.read(variant, root)
