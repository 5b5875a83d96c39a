"""Quasi-static B(H) loops of soft magnetic materials (Szewczyk, JAmodel).

Folder ``magnetic_bh_loops_ja``: per material ``<material>_H.mat`` (variable ``HmeasT``, A/m)
and ``<material>_B.mat`` (``BmeasT``, T), one loop per column at one field amplitude, points
ordered along the loop. There is no time axis and no rate information: time is a nominal
sample index x 1 s so that the runs satisfy `Recording`; it must not be read as a rate. (For
the ferrites the points are nearly equally spaced in H, i.e. a triangular sweep at a constant
nominal rate.)
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..errors import InputError
from ._dataset import Dataset, DatasetInfo, Provenance, VariantInfo
from ._files import read_mat_matrix

__all__ = ["INFO", "load_bh_loops"]

NAME = "bh_loops"
FOLDER = "magnetic_bh_loops_ja"
NOMINAL_DT = 1.0  # s per point; quasi-static data have no time axis
_COMMIT = "4bbe905d420ce27c66ee93d8b25ef44b553f9175"
# material -> (original path stem and suffix in the repository, description, field
# amplitudes [A/m] of the columns as the README lists them, points per loop)
_MATERIALS = {
    "MnZn_ferrite": ("1_isotropic/Characterisitcs_isotropic_mat/{}_MnZn_ferrite.mat",
                     "MnZn ferrite", (8, 16, 40, 80), 129),
    "MnZn_HP_ferrite": ("11_TwoStepSolver/Characteristics_isotropic_mat/{}_MnZn_HP_ferrite.mat",
                        "MnZn HP ferrite", (6, 9.5, 20, 80), 129),
    "amorphous_perp_aniso": ("2_anisotropic/Characterisitcs_anisotropic_mat/{}_amorf.mat",
                             ("amorphous alloy with perpendicular anisotropy (M-680 core); "
                             "nearly anhysteretic, sheared"), (800,), 322),
    "M130-27s_GO_steel": ("10_APPA/anisotropic/Characterisitcs_anisotropic_mat/{}_M130_27s.mat",
                          "M130-27s grain-oriented electrical steel, easy axis",
                          (17.6, 65.7, 218.8), 256),
}
_VARIANTS = {f"{m}_H{amp:g}": (m, j) for m, (_, _, amps, _) in _MATERIALS.items()
             for j, amp in enumerate(amps)}


def _source(variant: str) -> Provenance:
    material = _VARIANTS[variant][0]
    repo_path = _MATERIALS[material][0]
    return Provenance(
        repository="github.com/romanszewczyk/JAmodel", commit=_COMMIT,
        paths=(repo_path.format("H"), repo_path.format("B")), licence="MIT",
        licence_file="LICENSE_MIT_JAmodel.txt",
        credit="R. Szewczyk, JAmodel (Jiles-Atherton model identification, "
               "github.com/romanszewczyk/JAmodel); data (c) 2016 Roman Szewczyk, MIT licence",
        files=(f"{FOLDER}/{material}_H.mat", f"{FOLDER}/{material}_B.mat"))


def _read(folder: Path, variant: str) -> Dataset:
    material, column = _VARIANTS[variant]
    _, what, amplitudes, _ = _MATERIALS[material]
    h_file, b_file = f"{material}_H.mat", f"{material}_B.mat"
    h = read_mat_matrix(folder / h_file, "HmeasT")
    b = read_mat_matrix(folder / b_file, "BmeasT")
    if h.shape != b.shape or h.shape[1] != len(amplitudes):
        raise InputError(f"{folder / h_file}: HmeasT {h.shape} and BmeasT {b.shape} must both "
                         f"have {len(amplitudes)} column(s), one per loop")
    return Dataset(
        name=NAME, variant=variant, time=np.arange(h.shape[0]) * NOMINAL_DT,
        input=h[:, column], output=b[:, column], input_name="magnetic field H",
        input_unit="A/m", output_name="flux density B", output_unit="T",
        description=f"Quasi-static B(H) loop of {what}, field amplitude "
                    f"{amplitudes[column]:g} A/m (one averaged loop).",
        provenance=_source(variant),
        time_note=f"no time axis (quasi-static): nominal point index x {NOMINAL_DT:g} s, "
                  "no rate information",
        conditions={"H_amplitude_A_per_m": float(amplitudes[column])},
        notes=("concentric symmetric loops, processed (one averaged loop per amplitude)",))


INFO = DatasetInfo(
    name=NAME, folder=FOLDER,
    what="quasi-static B(H) loops, 4 soft magnetic materials at several field amplitudes",
    input_name="magnetic field H", input_unit="A/m", output_name="flux density B",
    output_unit="T", licence="MIT",
    variants=tuple(VariantInfo(v, _MATERIALS[m][3], None, "",
                               f"{_MATERIALS[m][1].split(';')[0]}, "
                               f"H amplitude {_MATERIALS[m][2][j]:g} A/m")
                   for v, (m, j) in _VARIANTS.items()),
    default_variant="MnZn_ferrite_H80", reader=_read, source=_source)


def load_bh_loops(variant: str = "MnZn_ferrite_H80", *,
                  root: str | os.PathLike[str] | None = None) -> Dataset:
    """Load one B(H) loop.

    Parameters
    ----------
    variant : str
        ``"<material>_H<amplitude>"``: ``MnZn_ferrite_H8/16/40/80``,
        ``MnZn_HP_ferrite_H6/9.5/20/80``, ``amorphous_perp_aniso_H800``,
        ``M130-27s_GO_steel_H17.6/65.7/218.8`` (amplitudes in A/m).
    root : path-like, optional
        Shared data root (default: ``$HYSTKIT_SHARED_DATA`` or a ``shared/data`` found above).

    Returns
    -------
    Dataset
        input = H [A/m], output = B [T]; time is nominal (1 s per point, no rate).
    """
    return INFO.read(variant, root)
