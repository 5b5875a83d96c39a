"""``hystkit datasets list|show|export``: the public hysteresis data sets (issue 4); ``show``
says where a data set's files come from and where they go (issue 27.8)."""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from pathlib import Path

from ..datasets import (
    DATASETS,
    ENV_VAR,
    Dataset,
    dataset_info,
    list_excerpts,
    load,
    load_excerpt,
    shared_data_status,
)
from ..io import (
    RECORDING_SUFFIXES,
    atomic_outputs,
    check_output_path,
    sidecar_path,
    units_settings_text,
    write_json,
    write_recording,
)
from ._common import stdout_for

__all__ = ["DatasetsExportOptions", "DatasetsOptions", "export_dataset", "list_datasets",
           "run_export", "run_list", "run_show", "show_dataset"]


@dataclass(frozen=True)
class DatasetsOptions:
    """``hystkit datasets list`` and ``show``'s options, as parsed: the data set (``list``:
    None for all of them) and the shared data root (None: the environment's or one found)."""

    name: str | None
    root: Path | None

    @classmethod
    def from_args(cls, args: argparse.Namespace) -> DatasetsOptions:
        """The options of a parsed ``datasets list`` or ``datasets show`` command line."""
        return cls(args.name, args.root)


@dataclass(frozen=True)
class DatasetsExportOptions:
    """``hystkit datasets export``'s options, as parsed: ``variant`` None for the data set's
    default; ``excerpt``: the excerpt shipped with hystkit instead of the shared data."""

    name: str
    variant: str | None
    segment: str | None
    role: str  # "inverse" or "forward"
    excerpt: bool
    root: Path | None
    out: Path
    force: bool

    @classmethod
    def from_args(cls, args: argparse.Namespace) -> DatasetsExportOptions:
        """The options of a parsed ``datasets export`` command line."""
        return cls(args.name, args.variant, args.segment, args.role, args.excerpt, args.root,
                   Path(args.out), args.force)


def _samples(counts: list[int]) -> str:
    low, high = min(counts), max(counts)
    return f"{low}" if low == high else f"{low}-{high}"


def _rates(rates: list[float | None]) -> str:
    known = sorted({r for r in rates if r is not None})
    if not known:
        return "no time axis"
    return "/".join(f"{r:g}" for r in known) + " Hz"


def run_list(args: argparse.Namespace) -> int:
    """``hystkit datasets list [NAME]``."""
    return list_datasets(DatasetsOptions.from_args(args))


def list_datasets(opts: DatasetsOptions) -> int:
    """The data sets (or the runs of ``opts.name``) and whether the shared data are here."""
    stdout_for("the list")
    root, how = shared_data_status(opts.root)
    print(f"shared data: {root} ({how})" if root is not None else how)
    if opts.name is not None:
        return _list_variants(opts.name, root)
    print(f"{'name':<24}{'runs':>5}  {'samples':<13}{'rate':<15}{'input -> output':<32}"
          f"{'here':<6}licence")
    for info in DATASETS.values():
        here = "yes" if root is not None and (root / info.folder).is_dir() else "no"
        io = f"{info.input_unit} -> {info.output_unit}"
        print(f"{info.name:<24}{len(info.variants):>5}  "
              f"{_samples([v.n_samples for v in info.variants]):<13}"
              f"{_rates([v.fs for v in info.variants]):<15}{io:<32}{here:<6}{info.licence}")
        print(f"{'':<4}{info.what}; {info.input_name} -> {info.output_name}"
              + (f" (needs {info.requires})" if info.requires else ""))
    shipped = {}
    for spec in list_excerpts():
        shipped.setdefault(spec.name, []).append(spec.variant)
    for name, variants in shipped.items():
        print(f"shipped excerpts (--excerpt, always available): {name}: {', '.join(variants)}")
    print("details of one data set: hystkit datasets list NAME")
    absent = [info.name for info in DATASETS.values()
              if root is None or not (root / info.folder).is_dir()]
    if absent:
        print(f"not here: {', '.join(absent)}; where each comes from and where to put it: "
              "hystkit datasets show NAME")
    return 0


def _list_variants(name: str, root: Path | None) -> int:
    info = dataset_info(name)
    print(f"{info.name}: {info.what}")
    print(f"  input {info.input_name} [{info.input_unit}] -> output {info.output_name} "
          f"[{info.output_unit}]; folder {info.folder}; licence {info.licence}")
    print(f"  source {info.provenance().repository}; the files and where they go: hystkit "
          f"datasets show {info.name}")
    print(f"{'variant':<24}{'split':<16}{'samples':>8}  {'rate':<14}description")
    for v in info.variants:
        mark = " (default)" if v.name == info.default_variant else ""
        rate = "nominal" if v.fs is None else f"{v.fs:g} Hz"
        print(f"{v.name:<24}{v.split or '-':<16}{v.n_samples:>8}  {rate:<14}{v.description}"
              f"{mark}")
    return 0


def run_show(args: argparse.Namespace) -> int:
    """``hystkit datasets show NAME``."""
    return show_dataset(DatasetsOptions.from_args(args))


def show_dataset(opts: DatasetsOptions) -> int:
    """Where the files of data set ``opts.name`` come from and where they go."""
    stdout_for("the description")
    info = dataset_info(opts.name)
    root, how = shared_data_status(opts.root)
    sources = [info.provenance(v.name) for v in info.variants]
    first = sources[0]
    print(f"{info.name}: {info.what}")
    print(f"  source:  {first.repository}")
    print(f"  licence: {first.licence}; keep {first.licence_file} (the licence text) beside "
          "the files")
    print(f"  credit:  {first.credit}")
    print("  files: in the repository (commit) -> where hystkit reads them:")
    here, listed = 0, set()
    base = "SHARED_DATA" if root is None else str(root)
    for source in sources:
        for repo_path, local in zip(source.paths, source.files, strict=True):
            if local in listed:
                continue
            listed.add(local)
            found = root is not None and (root / local).is_file()
            here += found
            print(f"    {repo_path} ({source.commit[:7]})")
            print(f"      -> {base}/{local}{'' if found else '  (missing)'}")
    print(f"  here: {here} of {len(listed)} file(s)")
    if root is None:
        print(f"  shared data root: {how}")
    else:
        print(f"  shared data root: {root} ({how}); another: --root or ${_env_var()}")
    if info.requires:
        print(f"  needs {info.requires}")
    return 0


def _env_var() -> str:
    return ENV_VAR


def run_export(args: argparse.Namespace) -> int:
    """``hystkit datasets export NAME --out FILE``."""
    return export_dataset(DatasetsExportOptions.from_args(args))


def export_dataset(opts: DatasetsExportOptions) -> int:
    """Write one run of a data set as a recording, with its sidecar (and settings file)."""
    out = opts.out
    sidecar = out.with_name(out.name + ".json")
    # CSV keeps its units in the settings file beside it, which reading it picks up
    settings = sidecar_path(out) if out.suffix.lower() == ".csv" else None
    check_output_path(out, opts.force, formats=RECORDING_SUFFIXES, what="a recording")
    for path in (sidecar, settings):  # refuse before reading anything
        if path is not None:
            check_output_path(path, opts.force)
    ds: Dataset = (load_excerpt(opts.name, opts.variant) if opts.excerpt
                   else load(opts.name, opts.variant, root=opts.root))
    if opts.segment is not None:
        ds = ds.segment(opts.segment)
    rec = ds.to_recording(role=opts.role)
    units = _units(ds, opts.role)
    meta = {"exported_by": "hystkit datasets export", "role": opts.role,
            "segment": opts.segment, "excerpt": opts.excerpt, "columns": ds.columns(opts.role),
            "units": units, "dataset": ds.metadata()}
    # The recording and its sidecars appear together or not at all.
    paths = [out, sidecar] + ([settings] if settings is not None else [])
    with atomic_outputs(paths, opts.force) as temps:
        write_recording(rec, temps[0], extra=dict(ds.channels), units=units, force=True)
        write_json(meta, temps[1], force=True)
        if settings is not None:
            temps[2].write_text(units_settings_text(units), encoding="utf-8")
    cols = ds.columns(opts.role)
    print(f"wrote {out}: {ds.label}{f' segment {opts.segment}' if opts.segment else ''}, "
          f"{ds.n_samples} samples at {ds.fs:g} Hz")
    for column, meaning in cols.items():
        print(f"  {column:<22}{meaning}")
    print(f"wrote {sidecar} (units, provenance, licence: {ds.provenance.licence})")
    if settings is not None:
        print(f"wrote {settings} (units of the columns; read with {out})")
    return 0


def _units(ds, role: str) -> dict[str, str]:
    """Units of the exported columns: the data set's, not hystkit's lab units (mm, ΔR/R)."""
    position, sensor = ((ds.input_unit, ds.output_unit) if role == "inverse"
                        else (ds.output_unit, ds.input_unit))
    return {"position": position, "sensor": sensor, **dict(ds.channel_units)}
