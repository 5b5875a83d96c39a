"""`Dataset`: one run of a public hysteresis data set with its units and provenance.

A data set is a hysteretic *system* with a physical input and output (drive voltage ->
displacement, displacement -> force, field H -> flux density B, force -> displacement).
Every loader returns the same structure, so fitting and evaluation code need not know where a
run came from; :meth:`Dataset.to_recording` turns it into the hystkit `Recording`.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from ..errors import HystkitError, InputError
from ..io import Recording, Sampled
from ._files import DataNotFoundError, data_folder

__all__ = ["ROLES", "Dataset", "DatasetInfo", "MissingDependencyError", "Provenance",
           "VariantInfo"]

ROLES = ("inverse", "forward")
_MAX_STEP_DEVIATION = 0.01  # the tolerance of Recording: loaders must deliver uniform time


class MissingDependencyError(HystkitError, ImportError):
    """An optional package needed to read one file format is not installed."""


@dataclass(frozen=True)
class Provenance:
    """Where a run comes from, as its ``README.txt`` in the shared data states it.

    Parameters
    ----------
    repository : str
        Public repository the files were copied from (``github.com/owner/name``).
    commit : str
        Commit the files were copied at.
    paths : tuple of str
        Paths of the files in that repository.
    licence : str
        Licence of the data (``"MIT"``, with any caveat stated).
    licence_file : str
        Name of the licence text kept beside the data.
    credit : str
        Whom to credit and what to cite.
    files : tuple of str
        The local files read, relative to the shared data root (or to the excerpt folder).
    """

    repository: str
    commit: str
    paths: tuple[str, ...]
    licence: str
    licence_file: str
    credit: str
    files: tuple[str, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-ready dictionary (tuples become lists)."""
        return {k: list(v) if isinstance(v, tuple) else v for k, v in vars(self).items()}


@dataclass(frozen=True, eq=False)  # eq=False: element-wise array comparison has no single truth
class Dataset(Sampled):
    """One uniformly sampled run of a hysteretic system.

    Parameters
    ----------
    name, variant : str
        Registry name of the data set and the run within it (see :func:`list_datasets`).
    time : array_like, shape (n,)
        Sample times [s], strictly increasing and uniform to within 1 %. Where a file has no
        time column it is built from the documented sample rate; ``time_note`` says how.
    input, output : array_like, shape (n,)
        The physical input and output of the hysteretic system, in ``input_unit`` and
        ``output_unit``.
    input_name, input_unit, output_name, output_unit : str
        What the signals are and their units (``"V"``, ``"um"``, ``"N"``, ``"A/m"``, ``"T"``).
    description : str
        One or two sentences on the run.
    provenance : Provenance
    time_note : str
        How the time axis was obtained (file column, documented rate, nominal).
    segments : mapping of str to (float, float)
        Named windows ``[t0, t1)`` [s] of this run (e.g. the uncompensated part of a test).
    channels : mapping of str to array, shape (n,)
        Further measured signals (a reference, a velocity), in ``channel_units``.
    channel_units : mapping of str to str
    conditions : mapping of str to float
        Settings the run was taken at (``current_A``, ``frequency_Hz``, ...).
    notes : tuple of str
        Processing applied by the loader (alignment, excerpting, windows) and caveats.

    Notes
    -----
    Arrays are stored as read-only float64 copies; invalid data raise `InputError`.
    """

    name: str
    variant: str
    time: np.ndarray
    input: np.ndarray
    output: np.ndarray
    input_name: str
    input_unit: str
    output_name: str
    output_unit: str
    description: str
    provenance: Provenance
    time_note: str
    segments: Mapping[str, tuple[float, float]] = field(default_factory=dict)
    channels: Mapping[str, np.ndarray] = field(default_factory=dict)
    channel_units: Mapping[str, str] = field(default_factory=dict)
    conditions: Mapping[str, float] = field(default_factory=dict)
    notes: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        where = f"dataset {self.label}"
        vectors = {"time": self.time, "input": self.input, "output": self.output}
        vectors |= {f"channel {k!r}": v for k, v in self.channels.items()}
        checked = {what: _vector(values, what, where) for what, values in vectors.items()}
        lengths = {what: v.size for what, v in checked.items()}
        if len(set(lengths.values())) > 1:
            raise InputError(f"{where}: signals have different lengths: {lengths}")
        _check_time(checked["time"], where)
        missing = set(self.channels) - set(self.channel_units)
        if missing:
            raise InputError(f"{where}: no unit given for channel(s) {sorted(missing)}")
        for key in ("time", "input", "output"):
            object.__setattr__(self, key, checked[key])
        channels = {k: checked[f"channel {k!r}"] for k in self.channels}
        object.__setattr__(self, "channels", MappingProxyType(channels))
        for key in ("segments", "channel_units", "conditions"):
            object.__setattr__(self, key, MappingProxyType(dict(getattr(self, key))))
        object.__setattr__(self, "notes", tuple(self.notes))

    @property
    def label(self) -> str:
        """``name/variant``, used in messages and as the recording's source."""
        return f"{self.name}/{self.variant}"

    def window(self, t0: float, t1: float, *, label: str = "window") -> Dataset:
        """The samples with ``t0 <= time < t1`` [s] (to within half a step), times unchanged.

        Segments lying wholly inside the window are kept; a note records the window.

        Raises
        ------
        InputError
            Fewer than 2 samples fall in the window.
        """
        half = 0.5 * self.dt  # a boundary on a sample instant belongs to the later window
        keep = (self.time >= t0 - half) & (self.time < t1 - half)
        n = int(np.count_nonzero(keep))
        if n < 2:
            raise InputError(f"dataset {self.label}: {label} {t0:g}-{t1:g} s holds {n} sample(s); "
                             f"the run spans {self.time[0]:g}-{self.time[-1]:g} s")
        inside = {k: (a, b) for k, (a, b) in self.segments.items()
                  if a >= t0 - half and b <= t1 + half}
        return replace(self, time=self.time[keep], input=self.input[keep],
                       output=self.output[keep],
                       channels={k: v[keep] for k, v in self.channels.items()},
                       segments=inside,
                       notes=(*self.notes, f"{label}: {t0:g}-{t1:g} s of the run, {n} samples"))

    def segment(self, name: str) -> Dataset:
        """The named segment (see ``segments``) as a dataset of its own."""
        if name not in self.segments:
            known = ", ".join(self.segments) or "none"
            raise InputError(f"dataset {self.label}: no segment {name!r}; segments: {known}")
        t0, t1 = self.segments[name]
        return self.window(t0, t1, label=f"segment {name!r}")

    def to_recording(self, role: str = "inverse") -> Recording:
        """The run as a hystkit `Recording` for fitting and evaluation.

        Parameters
        ----------
        role : {"inverse", "forward"}
            ``"inverse"`` (default): ``position`` = the system's physical input, ``sensor`` =
            its output. `~hystkit.compensation.fit_compensator` then learns output -> input:
            for a sensor that is the compensator (the measurand from the reading), for an
            actuator the inverse model a feedforward uses (drive from wanted output).
            ``"forward"``: ``position`` = output, ``sensor`` = input, so a direct-mode fit
            learns the system itself, input -> output (e.g. the Bouc-Wen benchmark's task).

        Notes
        -----
        The recording's columns carry this data set's units (``input_unit``,
        ``output_unit``), not the mm and ΔR/R of the lab sensor; ``source`` is
        ``"dataset name/variant"``.
        """
        if role not in ROLES:
            raise ValueError(f"role must be one of {ROLES}, got {role!r}")
        position, sensor = ((self.input, self.output) if role == "inverse"
                            else (self.output, self.input))
        return Recording(self.time, sensor=sensor, position=position,
                         source=f"dataset {self.label}")

    def columns(self, role: str = "inverse") -> dict[str, str]:
        """What each column of :meth:`to_recording` (and of its channels) holds, with units."""
        if role not in ROLES:
            raise ValueError(f"role must be one of {ROLES}, got {role!r}")
        inp = f"{self.input_name} [{self.input_unit}] (system input)"
        out = f"{self.output_name} [{self.output_unit}] (system output)"
        cols = {"time": "time [s]", "position": inp if role == "inverse" else out,
                "sensor": out if role == "inverse" else inp}
        return cols | {k: f"{k} [{self.channel_units[k]}]" for k in self.channels}

    def metadata(self) -> dict[str, Any]:
        """Everything but the arrays, JSON-ready (for sidecar files and excerpts)."""
        return {"name": self.name, "variant": self.variant, "n_samples": self.n_samples,
                "fs_hz": self.fs, "t_start_s": float(self.time[0]),
                "input_name": self.input_name, "input_unit": self.input_unit,
                "output_name": self.output_name, "output_unit": self.output_unit,
                "description": self.description, "time_note": self.time_note,
                "segments": {k: list(v) for k, v in self.segments.items()},
                "channel_units": dict(self.channel_units),
                "conditions": dict(self.conditions), "notes": list(self.notes),
                "provenance": self.provenance.to_dict()}


@dataclass(frozen=True)
class VariantInfo:
    """One run of a data set as the registry lists it, without reading any file.

    Parameters
    ----------
    name : str
    n_samples : int
        Samples the loader returns (checked against the files by the tests).
    fs : float or None
        Sampling rate [Hz]; None where the time axis is nominal (quasi-static loops).
    split : str
        ``"identification"``, ``"test"``, ``"train"``, ``"validation"`` or ``""``.
    description : str
    """

    name: str
    n_samples: int
    fs: float | None
    split: str
    description: str


@dataclass(frozen=True)
class DatasetInfo:
    """A registered data set: its folder in the shared data, signals, licence and runs.

    Parameters
    ----------
    name : str
        Registry name (``load(name, ...)``, ``hystkit datasets export NAME``).
    folder : str
        Its folder below the shared data root.
    what : str
        One line for listings.
    input_name, input_unit, output_name, output_unit : str
        The system's physical input and output and their units.
    licence : str
    variants : tuple of VariantInfo
        The runs, with documented sample counts and rates.
    default_variant : str
    reader : callable (folder, variant) -> Dataset
        Reads one run from the data set's folder.
    requires : str
        Optional packages some variants need, in words ("" when none).
    source : callable (variant) -> Provenance
        Where a run's files come from and where they go, known without reading them
        (`Provenance.files` relative to the shared data root); the reader gives the same.
    """

    name: str
    folder: str
    what: str
    input_name: str
    input_unit: str
    output_name: str
    output_unit: str
    licence: str
    variants: tuple[VariantInfo, ...]
    default_variant: str
    reader: Callable[[Path, str], Dataset] = field(repr=False, compare=False)
    requires: str = ""  # optional packages some variants need
    source: Callable[[str], Provenance] | None = field(default=None, repr=False, compare=False)

    def variant(self, name: str | None = None) -> VariantInfo:
        """The named run (default: `default_variant`); unknown names list the choices."""
        name = self.default_variant if name is None else name
        for info in self.variants:
            if info.name == name:
                return info
        raise InputError(f"dataset {self.name!r}: no variant {name!r}; variants: "
                         f"{', '.join(v.name for v in self.variants)}")

    def provenance(self, variant: str | None = None) -> Provenance:
        """Where the files of run `variant` (default: the default run) come from: repository,
        commit, paths there, licence and the local files, without reading any."""
        if self.source is None:
            raise InputError(f"dataset {self.name!r}: no source registered")
        return self.source(self.variant(variant).name)

    def files(self) -> tuple[str, ...]:
        """Every local file of every run (relative to the shared data root), in order."""
        found = dict.fromkeys(f for v in self.variants for f in self.provenance(v.name).files)
        return tuple(found)

    def where_from(self, variant: str | None = None) -> str:
        """One phrase: what to get from where, and where to put it."""
        source = self.provenance(variant)
        local = [f.removeprefix(f"{self.folder}/") for f in source.files]
        return (f"{self.name} comes from {source.repository} (commit {source.commit[:7]}, "
                f"{' and '.join(source.paths)}; licence {source.licence}): put "
                f"{' and '.join(local)} in {self.folder}/ of the shared data root ('hystkit "
                f"datasets show {self.name}' lists the files)")

    def read(self, variant: str | None = None,
             root: str | os.PathLike[str] | None = None) -> Dataset:
        """Read run `variant` from the shared data (`root`, see `find_root`).

        Raises
        ------
        DataNotFoundError
            The shared data, the folder or a file is absent: one line naming the path looked
            at, where the files come from and where they go (`where_from`).
        InputError
            An unknown variant, an unreadable file.
        """
        name = self.variant(variant).name
        try:
            return self.reader(data_folder(self.folder, root), name)
        except DataNotFoundError as exc:
            raise DataNotFoundError(f"{exc}; {self.where_from(name)}") from None


def _vector(values: Any, what: str, where: str) -> np.ndarray:
    array = np.asarray(values)
    if array.dtype.kind not in "iuf":
        raise InputError(f"{where}: {what} is not real numbers (dtype {array.dtype})")
    if array.ndim != 1:
        raise InputError(f"{where}: {what} must be 1-D, got shape {array.shape}")
    array = array.astype(np.float64, copy=True)
    bad = np.flatnonzero(~np.isfinite(array))
    if bad.size:
        raise InputError(f"{where}: {what}: non-finite value {array[bad[0]]} at sample "
                         f"{bad[0] + 1}")
    array.setflags(write=False)
    return array


def _check_time(time: np.ndarray, where: str) -> None:
    if time.size < 2:
        raise InputError(f"{where}: only {time.size} sample(s); a run needs at least 2")
    step = np.diff(time)
    if np.any(step <= 0):
        i = int(np.flatnonzero(step <= 0)[0]) + 1
        raise InputError(f"{where}: time is not strictly increasing at sample {i + 1}")
    median = float(np.median(step))
    bad = np.flatnonzero(np.abs(step - median) > _MAX_STEP_DEVIATION * median)
    if bad.size:  # a loader bug: every loader must deliver (or build) a uniform time axis
        i = int(bad[0]) + 1
        raise InputError(f"{where}: non-uniform sampling at sample {i + 1} (step "
                         f"{step[i - 1]:.6g} s, median {median:.6g} s)")
