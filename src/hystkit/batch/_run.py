"""Fit a fleet of sensors: one model file per sensor, one results table, resumable.

The batch folder ``OUT`` holds ``batch.json`` (what made it), ``models/<id>.json`` (each
sensor's compensator, as ``hystkit fit`` writes it), ``sensors/<id>.json`` (each finished
sensor's row, full scores and the job it answers) and ``results.parquet`` / ``results.csv``
(one row per sensor, in the manifest's order). A sensor's record is written after its model
file, so a record proves the sensor finished: a rerun skips sensors whose record matches their
job (same options, same recordings: path, size and modification time) and fits the others,
sensors that failed included. The results table is rebuilt from the records on every run, so
an interrupted batch, rerun, gives the table of an uninterrupted one.
"""

from __future__ import annotations

import json
import os
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict
from pathlib import Path

import pandas as pd

from .. import __version__
from ..compensation import (
    DEFAULT_CENTER,
    evaluate,
    fit_compensator,
    pooled_verdict,
    save_compensator,
    with_band,
)
from ..errors import InputError, OutputError
from ..io import (
    ReadOptions,
    Recording,
    atomic_outputs,
    check_output_path,
    options_for,
    read_recording,
    remember_reading,
    training_units,
    write_json,
)
from ..models import get_family
from ..parallel import Executor, SerialExecutor
from ._manifest import SensorJob

__all__ = ["RESULT_COLUMNS", "fit_sensor", "pending", "run_batch"]

#: Columns of ``results.parquet`` / ``results.csv``. Scores are on the validation recordings
#: (the mean over several): deployable (the model's own centring) and oracle (the paper's
#: protocol, each recording's own means: not available in use); the prediction band's coverage
#: and median width [mm] are deployable (its nominal level is the model file's, 0.90).
RESULT_COLUMNS = ("sensor", "status", "model", "size", "mode", "center", "r2_deployable",
                  "e_rms_pct_deployable", "r2_oracle", "linear_r2_deployable", "band_coverage",
                  "band_width_median", "fit_seconds", "seconds", "guards", "error",
                  "model_file")
MARKER = "batch.json"
#: How a batch reads its recordings: one `ReadOptions` for every file; a mapping from a file
#: (as ``str(path)``) to its options; or None. A file not in the mapping, and every file with
#: None, is read as ``hystkit fit`` and ``hk.read`` read it: with its settings file beside it
#: (`hystkit.io.options_for`).
Reading = ReadOptions | Mapping[str, ReadOptions] | None


def fit_sensor(job: SensorJob, *, read_options: Reading = None) -> dict:
    """Read, fit and score one sensor (one piece of a batch; never raises for the sensor's own
    failure: it is the row's ``error``).

    Parameters
    ----------
    job : SensorJob
        The sensor's recordings and model options.
    read_options : ReadOptions or mapping, optional
        How to read the recordings (column names, time unit, ...; `Reading`); None: each
        with its settings file, as ``hystkit fit`` reads it.

    Returns
    -------
    dict
        ``row`` (the results-table row), ``scores`` (evaluate's dict per validation
        recording) and ``compensator`` (None if the sensor failed).
    """
    t0 = time.perf_counter()
    row = {key: None for key in RESULT_COLUMNS}
    row.update(sensor=job.sensor, model=job.model, mode=job.mode,
               size=get_family(job.model).default_size if job.size is None else job.size,
               center=DEFAULT_CENTER if job.center is None else job.center)
    try:
        fit_recs, val_recs = _recordings(job, read_options)
        units = training_units(fit_recs)  # recordings in different units fail the sensor
        options = {} if job.center is None else {"center": job.center}
        comp = fit_compensator(fit_recs, job.size, model=job.model, mode=job.mode, **options)
        if comp.fit_info["status"] == "ok":  # a band for a model that may be used
            options.pop("center", None)
            comp = with_band(comp, fit_recs, row["size"], options)
        # the model file remembers how the fit files were read, as ``hystkit fit``'s does
        comp, _ = remember_reading(comp, units, [_options(p, read_options) for p in job.fit],
                                   job.fit)
        scores = [evaluate(comp, rec) for rec in val_recs]
    except Exception as exc:  # noqa: BLE001  (one sensor never stops the batch)
        _raise_interrupt(exc)
        row.update(status="failed", error=f"{type(exc).__name__}: {exc}",
                   seconds=time.perf_counter() - t0)
        return {"row": row, "scores": [], "compensator": None}
    info = comp.fit_info
    status, message = info["status"], info["status_message"]
    if status == "ok" and scores:
        # a fit that passed its guards is judged, as `evaluate` would, on the validation runs
        status, message = pooled_verdict(scores, "validation (deployable)")
        status = "ok" if status == "undetermined" else status
    row.update(status=status,
               r2_deployable=_mean(scores, "r2"), e_rms_pct_deployable=_mean(scores, "e_rms_pct"),
               r2_oracle=_mean(scores, "r2_oracle"),
               linear_r2_deployable=_mean(scores, "linear_r2"),
               band_coverage=_mean(scores, "band_coverage"),
               band_width_median=_mean(scores, "band_width_median"),
               fit_seconds=info["fit_seconds"], seconds=time.perf_counter() - t0,
               guards=None if status == "ok" else message,
               model_file=f"models/{job.sensor}.json")
    return {"row": row, "scores": scores, "compensator": comp}


def _raise_interrupt(exc: BaseException) -> None:
    """Raise the Ctrl-C or SIGTERM (KeyboardInterrupt, `Terminated`) behind `exc`, if any.

    The signal handler's exception, raised while a numba kernel runs, comes out of the kernel
    as ``SystemError: CPUDispatcher(...) returned a result with an exception set`` caused by
    it: that stops the batch, it is not the sensor's failure (which was recorded, and the
    batch went on to fit the others and exit 3).
    """
    seen: set[int] = set()
    cause: BaseException | None = exc
    while cause is not None and id(cause) not in seen:
        if not isinstance(cause, Exception):
            raise cause
        seen.add(id(cause))
        cause = cause.__cause__ or cause.__context__


def _mean(scores: Sequence[dict], key: str) -> float | None:
    values = [s[key] for s in scores]
    return None if any(v is None for v in values) else float(sum(values) / len(values))


def _recordings(job: SensorJob, reading: Reading) -> tuple[list, list]:
    fit = [read_recording(p, options=_options(p, reading)) for p in job.fit]
    if not job.split:
        return fit, [read_recording(p, options=_options(p, reading)) for p in job.validate]
    return [_part(fit[0], 0, "first half")], [_part(fit[0], 1, "second half")]


def _options(path: Path, reading: Reading) -> ReadOptions:
    """The options to read `path` with (see `Reading`)."""
    if isinstance(reading, ReadOptions):
        return reading
    if reading is not None and str(path) in reading:
        return reading[str(path)]
    return options_for(path)[0]


def _reading_record(job: SensorJob, reading: Reading) -> list | None:
    """The options each recording of `job` is read with, as stored with its result (a rerun
    with other options, or an edited settings file, refits); None if they cannot be known
    (a settings file refused: the sensor fails, and is tried again)."""
    try:
        pairs = [[str(p), asdict(_options(p, reading))] for p in (*job.fit, *job.validate)]
    except InputError:
        return None
    return json.loads(json.dumps(pairs))  # as read back from the record


def _part(rec: Recording, half: int, label: str) -> Recording:
    if rec.n_samples < 4:
        raise InputError(f"{rec.source}: {rec.n_samples} samples cannot be split into a "
                         f"fitting and a validation half")
    mid = rec.n_samples // 2
    cut = slice(0, mid) if half == 0 else slice(mid, rec.n_samples)
    time_ = rec.time[cut] - rec.time[cut][0]
    return Recording(time=time_, sensor=rec.sensor[cut], position=rec.position[cut],
                     source=f"{rec.source} ({label})", units=rec.units)


def fingerprint(job: SensorJob) -> list:
    """The job's recordings as (path, size, modification time): a changed file is refit."""
    out = []
    for path in (*job.fit, *job.validate):
        try:
            st = os.stat(path)
            out.append([str(path), st.st_size, st.st_mtime_ns])
        except OSError:
            out.append([str(path), None, None])
    return out


def run_batch(jobs: Sequence[SensorJob], out: Path, *, executor: Executor | None = None,
              read_options: Reading = None, refit: bool = False,
              source: str = "", progress: Callable[[str], None] = lambda _: None) -> list[dict]:
    """Fit every sensor not finished in `out` yet (all with `refit`); write the results table.

    Parameters
    ----------
    jobs : sequence of SensorJob
        The sensors, in the order of the results table.
    out : Path
        The batch folder (see the module docstring); created if missing.
    executor : Executor, optional
        Where the fits run; by default serially in this process.
    read_options : ReadOptions or mapping, optional
        How to read the recordings (`Reading`); None: each with its settings file, as
        ``hystkit fit`` reads it. A sensor finished with other options is fitted again.
    refit : bool
        Fit every sensor again, and accept a non-empty `out` that is not a batch folder.
    source : str
        What the jobs came from (manifest or folder), stored in ``batch.json``.
    progress : callable
        Called with one line of text at the start and as each sensor finishes.

    Returns
    -------
    list of dict
        The results rows (`RESULT_COLUMNS`), in the order of `jobs`.

    Raises
    ------
    OutputError
        `out` exists, is not empty and is not a batch folder (no ``batch.json``), unless
        `refit`.
    """
    out = Path(out)
    _claim(out, refit, source)
    rows = {job.sensor: record["row"] for job in jobs
            if (record := None if refit else _finished(out, job, read_options)) is not None}
    todo = [job for job in jobs if job.sensor not in rows]
    progress(f"{len(jobs)} sensors: {len(rows)} finished before, {len(todo)} to fit on "
             f"{(executor or SerialExecutor()).describe()}")

    def finished(i: int, result: dict) -> None:
        job = todo[i]
        _store(out, job, result, _reading_record(job, read_options))
        rows[job.sensor] = row = result["row"]
        progress(f"[{len(rows)}/{len(jobs)}] {_summary(row)}")

    (executor or SerialExecutor()).map(fit_sensor, todo, shared={"read_options": read_options},
                                       on_done=finished)
    table = [rows[job.sensor] for job in jobs]
    _write_table(out, table)
    return table


def _claim(out: Path, refit: bool, source: str) -> None:
    """Make `out` a batch folder, or check that it is one."""
    marker = out / MARKER
    if out.exists() and not out.is_dir():
        raise OutputError(f"{out} is a file, not a folder")
    if out.is_dir() and any(out.iterdir()) and not marker.exists() and not refit:
        raise OutputError(f"{out} is not empty and not a hystkit batch folder (no {MARKER}); "
                          f"choose another --out or pass --force")
    check_output_path(marker, force=True)  # the folder (or its nearest parent) is writable
    if not marker.exists() or refit:
        write_json({"hystkit": __version__, "source": source}, marker, force=True)


def pending(jobs: Sequence[SensorJob], out: Path, refit: bool = False,
            read_options: Reading = None) -> list[SensorJob]:
    """The jobs `run_batch` will fit (those not finished in `out`), e.g. to size a cluster.

    Parameters
    ----------
    jobs : sequence of SensorJob
        The batch's sensors.
    out : Path
        The batch folder.
    refit : bool
        True: every job (as `run_batch` with `refit`).
    read_options : ReadOptions or mapping, optional
        As given to `run_batch`.

    Returns
    -------
    list of SensorJob
        The jobs still to fit, in the order of `jobs`.
    """
    return [job for job in jobs if refit or _finished(Path(out), job, read_options) is None]


def _finished(out: Path, job: SensorJob, reading: Reading = None) -> dict | None:
    """The sensor's record if it finished this very job (options, recordings and how they
    are read unchanged; a record from before hystkit stored the latter is taken as it is)
    and its model file is there; failed sensors are tried again."""
    path = out / "sensors" / f"{job.sensor}.json"
    try:
        record = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if record.get("job") != job.describe() or record.get("inputs") != fingerprint(job):
        return None
    if "reading" in record and record["reading"] != _reading_record(job, reading):
        return None
    row = record.get("row") or {}
    if row.get("status") in (None, "failed") or not (out / "models" /
                                                    f"{job.sensor}.json").is_file():
        return None
    return record


def _store(out: Path, job: SensorJob, result: dict, reading: list | None = None) -> None:
    """The model file first, then the record that says the sensor is done."""
    model = out / "models" / f"{job.sensor}.json"
    if result["compensator"] is not None:
        save_compensator(result["compensator"], model, force=True)
    else:
        model.unlink(missing_ok=True)  # a model of an earlier run would contradict the row
    write_json({"job": job.describe(), "inputs": fingerprint(job), "reading": reading,
                "row": result["row"], "scores": result["scores"]},
               out / "sensors" / f"{job.sensor}.json", force=True)


def _summary(row: dict) -> str:
    if row["status"] == "failed":
        return f"{row['sensor']}: FAILED: {row['error']}"
    r2 = lambda v: "-" if v is None else f"{v:.4f}"
    note = "" if row["status"] == "ok" else f"; guard: {row['status']}: {row['guards']}"
    return (f"{row['sensor']}: {row['status']}, R² {r2(row['r2_deployable'])} (oracle "
            f"{r2(row['r2_oracle'])}), fit {row['fit_seconds']:.2f} s{note}")


def _write_table(out: Path, table: list[dict]) -> None:
    frame = pd.DataFrame(table, columns=list(RESULT_COLUMNS))
    # derived from the records: rebuilt (replaced) on every run of the batch
    with atomic_outputs([out / "results.parquet", out / "results.csv"], force=True) as (pq, cs):
        frame.to_parquet(pq, index=False)
        frame.to_csv(cs, index=False)
