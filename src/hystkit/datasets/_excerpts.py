"""Small excerpts of the public data shipped inside the package, for tests and examples.

Each excerpt is a time window of a registered run, stored as ``<variant>.csv`` (columns time,
input, output and the run's channels, floats in shortest round-trip form, so the values are
the loader's bit for bit) and ``<variant>.json`` (the `Dataset` metadata). Every excerpt
folder keeps the source's licence text and a README.txt crediting it. They are rebuilt from
the shared data by :func:`build_excerpts` (command in each excerpt's README.txt); a test
checks that they still equal the corresponding windows of the full data.
"""

from __future__ import annotations

import json
import os
import shutil
from dataclasses import dataclass, replace
from pathlib import Path

import pandas as pd

from ..errors import InputError
from ._dataset import Dataset, Provenance
from ._files import data_folder
from ._registry import dataset_info, load

__all__ = ["EXCERPTS", "EXCERPT_DIR", "ExcerptSpec", "list_excerpts", "load_excerpt"]

EXCERPT_DIR = Path(__file__).resolve().parent / "excerpts"


@dataclass(frozen=True)
class ExcerptSpec:
    """Excerpt `variant` of data set `name`: times [t0, t1) s of run `source_variant`.

    Parameters
    ----------
    name : str
        Data set name in the registry.
    variant : str
        Name of the excerpt.
    source_variant : str
        Run of the data set it is cut from.
    t0, t1 : float
        Start (included) and end (excluded) time [s].
    """

    name: str
    variant: str
    source_variant: str
    t0: float
    t1: float


# The identification window holds the author's cycle (15.755-16.755 s); the two test windows
# are full-amplitude cycles of the uncompensated and the feedforward parts (4 cycles each).
EXCERPTS = (
    ExcerptSpec("piezo_micromanipulator", "identification", "identification", 13.0, 19.0),
    ExcerptSpec("piezo_micromanipulator", "test_uncompensated", "test", 2.0, 6.0),
    ExcerptSpec("piezo_micromanipulator", "test_feedforward", "test", 62.0, 66.0),
)


def list_excerpts() -> tuple[ExcerptSpec, ...]:
    """The shipped excerpts.

    Returns
    -------
    tuple of ExcerptSpec
        Every shipped excerpt, in a fixed order.
    """
    return EXCERPTS


def _spec(name: str, variant: str | None) -> ExcerptSpec:
    specs = [s for s in EXCERPTS if s.name == name]
    if not specs:
        shipped = sorted({s.name for s in EXCERPTS})
        raise InputError(f"no shipped excerpt of dataset {name!r}; excerpts exist for: "
                         f"{', '.join(shipped)}")
    variant = specs[0].variant if variant is None else variant
    for spec in specs:
        if spec.variant == variant:
            return spec
    raise InputError(f"dataset {name!r}: no shipped excerpt {variant!r}; excerpts: "
                     f"{', '.join(s.variant for s in specs)}")


def load_excerpt(name: str, variant: str | None = None) -> Dataset:
    """Load a shipped excerpt (always available, no shared data needed).

    Parameters
    ----------
    name : str
        Registered data set name (``"piezo_micromanipulator"``).
    variant : str, optional
        Excerpt name (see :data:`EXCERPTS`); default the first of that data set.

    Returns
    -------
    Dataset
        Same structure, units and provenance as the full run; ``notes`` say which window
        of which run it is.
    """
    spec = _spec(name, variant)
    folder = EXCERPT_DIR / spec.name
    meta_path, csv_path = folder / f"{spec.variant}.json", folder / f"{spec.variant}.csv"
    for path in (meta_path, csv_path):
        if not path.is_file():
            raise InputError(f"{path}: shipped excerpt missing (broken installation?)")
    meta = json.loads(meta_path.read_text(encoding="utf-8"))
    frame = pd.read_csv(csv_path, dtype=float)
    prov = meta["provenance"]
    return Dataset(
        name=meta["name"], variant=meta["variant"], time=frame["time"].to_numpy(),
        input=frame["input"].to_numpy(), output=frame["output"].to_numpy(),
        input_name=meta["input_name"], input_unit=meta["input_unit"],
        output_name=meta["output_name"], output_unit=meta["output_unit"],
        description=meta["description"],
        provenance=Provenance(**{k: tuple(v) if isinstance(v, list) else v
                                 for k, v in prov.items()}),
        time_note=meta["time_note"],
        segments={k: tuple(v) for k, v in meta["segments"].items()},
        channels={k: frame[k].to_numpy() for k in meta["channel_units"]},
        channel_units=meta["channel_units"], conditions=meta["conditions"],
        notes=tuple(meta["notes"]))


def excerpt_of(spec: ExcerptSpec, root: str | os.PathLike[str] | None = None) -> Dataset:
    """The excerpt cut from the full shared data (what the shipped files must equal)."""
    full = load(spec.name, spec.source_variant, root=root)
    cut = full.window(spec.t0, spec.t1, label=f"excerpt of run {spec.source_variant!r}")
    return replace(cut, variant=spec.variant)  # the excerpt is a run of its own


def _write(dataset: Dataset, folder: Path) -> None:
    columns = {"time": dataset.time, "input": dataset.input, "output": dataset.output}
    pd.DataFrame(columns | dict(dataset.channels)).to_csv(
        folder / f"{dataset.variant}.csv", index=False)  # repr floats: exact round trip
    meta = dataset.metadata()
    (folder / f"{dataset.variant}.json").write_text(json.dumps(meta, indent=1) + "\n",
                                                    encoding="utf-8")


def build_excerpts(root: str | os.PathLike[str] | None = None,
                   out: str | os.PathLike[str] = EXCERPT_DIR) -> list[Path]:
    """Rewrite every shipped excerpt, its licence copy and README from the shared data."""
    out = Path(out)
    written = []
    for name in sorted({s.name for s in EXCERPTS}):
        folder = out / name
        folder.mkdir(parents=True, exist_ok=True)
        specs = [s for s in EXCERPTS if s.name == name]
        cuts = [excerpt_of(s, root) for s in specs]
        for cut in cuts:
            _write(cut, folder)
        prov = cuts[0].provenance
        source_folder = data_folder(dataset_info(name).folder, root)
        shutil.copyfile(source_folder / prov.licence_file, folder / prov.licence_file)
        lines = [(f"Excerpts of the public data set '{name}' (shared data folder "
                 f"{source_folder.name}),"),
                 "shipped so that hystkit's tests and examples run without the shared data.",
                 "", f"Credit  : {prov.credit}", f"Origin  : {prov.repository} @ {prov.commit}",
                 (f"Licence : {prov.licence} (full text in {prov.licence_file}, kept with "
                 "these files as the licence requires)"), "", ("Files (values unchanged; time "
                 "built from the documented sample rate):")]
        for spec, cut in zip(specs, cuts, strict=True):
            lines.append(f"  {spec.variant}.csv/.json : {spec.t0:g}-{spec.t1:g} s of run "
                         f"'{spec.source_variant}' ({', '.join(cut.provenance.paths)}), "
                         f"{cut.n_samples} samples; columns time [s], input "
                         f"[{cut.input_unit}], output [{cut.output_unit}]"
                         + "".join(f", {k} [{u}]" for k, u in cut.channel_units.items()))
        lines += ["", "Loader alignment and caveats are in each .json ('notes').",
                  ("Rebuild (needs the shared data): python -c 'from hystkit.datasets._excerpts "
                  "import build_excerpts; build_excerpts()'")]
        (folder / "README.txt").write_text("\n".join(lines) + "\n", encoding="utf-8")
        written.append(folder)
    return written

