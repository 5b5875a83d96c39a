"""A signal that arrives inside compiled code stops the batch; it is no sensor's failure
(issue 25.8).

Python runs a signal handler at the next bytecode; while a numba kernel runs, the handler's
KeyboardInterrupt (Ctrl-C) or `Terminated` (SIGTERM, the CLI's handler) surfaces as
``SystemError: CPUDispatcher(...) returned a result with an exception set`` caused by it, which
the batch's per-sensor ``except Exception`` recorded as the sensor's failure. The subprocess
test with real signals is ``tests/hostile/test_batch_signals.py``; here the same chain is
raised by a stand-in fit, so that it happens every time.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import hystkit.batch._run as batch_run
from hystkit.batch import SensorJob, run_batch
from hystkit.errors import Terminated
from hystkit.io import write_recording
from hystkit.sensors import simulate_experiment


def _signal_in_a_kernel(interrupt: type[BaseException]):
    """A fit that fails as numba's dispatcher does when a signal handler raised inside it
    (SystemError caused by SystemError caused by the interrupt, as measured)."""

    def fit(*args, **kwargs):
        try:
            try:
                raise interrupt
            except BaseException as exc:
                raise SystemError("<function _numba_unpickle> returned a result with an "
                                  "exception set") from exc
        except SystemError as exc:
            raise SystemError("CPUDispatcher(<function theta_normal_equations>) returned a "
                              "result with an exception set") from exc

    return fit


@pytest.fixture(scope="module")
def job(tmp_path_factory: pytest.TempPathFactory) -> SensorJob:
    folder = tmp_path_factory.mktemp("one")
    rec = simulate_experiment("sine", 3)
    write_recording(rec, folder / "fit.csv")
    return SensorJob("s0", (folder / "fit.csv",), (), split=True, size=1)


@pytest.mark.parametrize("interrupt", [KeyboardInterrupt, Terminated])
def test_a_signal_inside_a_kernel_stops_the_sensor_fit(monkeypatch, job, interrupt):
    monkeypatch.setattr(batch_run, "fit_compensator", _signal_in_a_kernel(interrupt))
    with pytest.raises(interrupt):
        batch_run.fit_sensor(job)


@pytest.mark.parametrize("interrupt", [KeyboardInterrupt, Terminated])
def test_a_signal_inside_a_kernel_stops_the_batch_and_records_nothing(monkeypatch, job,
                                                                      tmp_path: Path,
                                                                      interrupt):
    monkeypatch.setattr(batch_run, "fit_compensator", _signal_in_a_kernel(interrupt))
    with pytest.raises(interrupt):
        run_batch([job, job.__class__("s1", job.fit, (), split=True, size=1)], tmp_path / "B")
    assert sorted(p.name for p in (tmp_path / "B").iterdir()) == ["batch.json"]


def test_an_ordinary_error_is_still_the_sensor_failure(monkeypatch, job):
    def fit(*args, **kwargs):
        raise SystemError("a real bug") from ValueError("inner")

    monkeypatch.setattr(batch_run, "fit_compensator", fit)
    row = batch_run.fit_sensor(job)["row"]
    assert row["status"] == "failed"
    assert row["error"] == "SystemError: a real bug"
