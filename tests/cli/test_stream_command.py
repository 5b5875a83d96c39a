"""``hystkit stream``: the real command through pipes and a pseudo-terminal, as on a bench."""

import io
import json
import os
import select
import signal
import subprocess
import sys

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from hystkit.cli import main
from hystkit.compensation import fit_compensator, save_compensator
from hystkit.io import Recording
from hystkit.live import Stream
from hystkit.sensors import simulate_experiment

WAIT = 180  # seconds: a cold interpreter imports numpy, scipy and numba on a shared machine


@pytest.fixture(scope="module")
def model(tmp_path_factory):
    folder = tmp_path_factory.mktemp("stream")
    comp = fit_compensator(simulate_experiment("noise", 1), 1, center="track", diagnose=False)
    return comp, save_compensator(comp, folder / "noise.json")


@pytest.fixture(scope="module")
def validation():
    return simulate_experiment("decay", 2)  # 2 mm decay: some samples inside, some outside


def lines_of(rec: Recording, n: int) -> list[str]:
    return [f"{t!r},{s!r}\n" for t, s in zip(rec.time[:n].tolist(), rec.sensor[:n].tolist(),
                                              strict=True)]


# A background job (CI) starts with SIGINT ignored, and an ignored signal stays ignored across
# exec: the child gets Python's own Ctrl-C handler back first, as in a terminal. (Not
# preexec_fn: the test session may run threads, e.g. a Dask cluster.)
WITH_CTRL_C = ("import signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler); "
               "from hystkit.cli import main; sys.exit(main())")


def command(*args: str, **popen) -> subprocess.Popen:
    """The real command; without PYTHONUNBUFFERED, so only its own flushes push lines out."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"}
    return subprocess.Popen([sys.executable, "-c", WITH_CTRL_C, "stream", *args], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, **popen)


def read_line(stream, timeout: float = WAIT) -> bytes:
    """One line from a raw pipe, failing (not hanging) if none comes in time."""
    line = b""
    while not line.endswith(b"\n"):
        ready, _, _ = select.select([stream], [], [], timeout)
        assert ready, f"no output line within {timeout} s (got {line!r})"
        byte = os.read(stream.fileno(), 1)
        assert byte, f"output ended within a line: {line!r}"
        line += byte
    return line


def parse_output(text: str) -> tuple[list[str], np.ndarray, np.ndarray]:
    rows = text.splitlines()
    assert rows[0] == "time,position_estimate,flags"
    fields = [row.split(",") for row in rows[1:]]
    return ([f[0] for f in fields], np.array([float(f[1]) for f in fields]),
            np.array([int(f[2]) for f in fields]))


def expected(comp, sensor: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Offline estimate and flag bits of the accepted samples (sensor 1, estimate 2)."""
    rec = Recording(time=np.arange(sensor.size) * comp.structure.dt, sensor=sensor)
    estimate = comp.estimate(rec)
    flags = comp.sensor_outside(rec) * 1 + comp.estimate_outside(estimate) * 2
    return estimate, flags


def test_piped_stream_is_the_offline_estimate_and_bad_lines_are_counted(model, validation):
    comp, path = model
    sensor = validation.sensor[:400].copy()
    sensor[300:310] += 3 * comp.scaling.sensor_scale  # a knock: flagged samples
    good = lines_of(Recording(time=validation.time[:400], sensor=sensor), 400)
    feed = ["time,sensor\n", *good[:9], "0.2250,abc\n", *good[9:19], "0.5\n", *good[19:29],
            "0.1,1234.5\n", *good[29:39], "nan,1.0\n", *good[39:]]
    # a dropped sample: its neighbours' step is two dt (compensated, counted)
    feed.remove(good[200])
    with command(str(path), stdin=subprocess.PIPE) as proc:
        out, err = proc.communicate("".join(feed).encode(), timeout=WAIT)
    out, err = out.decode(), err.decode()
    assert proc.returncode == 0, err
    times, estimate, flags = parse_output(out)
    sensor = np.delete(sensor, 200)
    want, want_flags = expected(comp, sensor)
    assert_array_equal(estimate, want)  # printed with repr: bit for bit
    assert_array_equal(flags, want_flags)
    assert 0 < np.count_nonzero(flags) < flags.size
    assert times[:3] == [g.split(",")[0] for g in good[:3]]
    warnings = [line for line in err.splitlines() if line.startswith("hystkit: warning:")]
    # file lines: header 1, good 2-10, 'abc' 11, good 12-21, '0.5' 22, good 23-32, backwards 33,
    # good 34-43, 'nan' 44; the dropped sample is good[200] at line 44 + 200 - 39 + 1 = 206
    assert sorted(warnings) == sorted([
        "hystkit: warning: <stdin>: 2 line(s) not a number (skipped; first at line 11)",
        "hystkit: warning: <stdin>: 1 line(s) missing field (skipped; first at line 22)",
        "hystkit: warning: <stdin>: 1 line(s) time not advancing (skipped; first at line 33)",
        (f"hystkit: warning: <stdin>: 1 line(s) irregular step (compensated, but the step "
         f"differs from the model's dt = {comp.structure.dt:g} s by more than 1%; first at "
         f"line 206)")])
    summary = err.splitlines()[-1]
    assert summary.startswith(f"hystkit stream: {sensor.size} samples; latency per sample "
                              f"median ")
    assert " µs, p99 " in summary and " µs, max " in summary


def test_every_line_is_answered_before_the_next_arrives_and_ctrl_c_exits_130(model, validation):
    comp, path = model
    with command(str(path), stdin=subprocess.PIPE, bufsize=0) as proc:
        assert read_line(proc.stdout) == b"time,position_estimate,flags\n"
        got = []
        for line in lines_of(validation, 5):
            proc.stdin.write(line.encode())  # the pipe stays open: only a flush answers
            got.append(float(read_line(proc.stdout).split(b",")[1]))
        proc.send_signal(signal.SIGINT)
        code = proc.wait(WAIT)
        err = proc.stderr.read().decode()
    assert code == 130, err
    assert_array_equal(got, expected(comp, validation.sensor[:5])[0])
    assert "hystkit stream: 5 samples; latency per sample median" in err
    assert err.rstrip().endswith("hystkit: interrupted")


def test_sigterm_also_prints_the_summary(model, validation):
    _, path = model
    with command(str(path), stdin=subprocess.PIPE, bufsize=0) as proc:
        assert read_line(proc.stdout) == b"time,position_estimate,flags\n"
        proc.stdin.write("".join(lines_of(validation, 3)).encode())
        for _ in range(3):
            read_line(proc.stdout)
        proc.send_signal(signal.SIGTERM)
        code = proc.wait(WAIT)
        err = proc.stderr.read().decode()
    assert code == 143, err
    assert "hystkit stream: 3 samples; latency per sample median" in err
    assert err.rstrip().endswith("hystkit: terminated (SIGTERM)")


def test_a_model_that_cannot_stream_fails_before_reading(tmp_path):
    oracle = fit_compensator(simulate_experiment("sine", 1), 1, center="recording",
                             diagnose=False)
    path = save_compensator(oracle, tmp_path / "oracle.json")
    with command(str(path), stdin=subprocess.PIPE) as proc:  # stdin open: reading would block
        code = proc.wait(WAIT)
        err, out = proc.stderr.read().decode(), proc.stdout.read()
    assert code == 2 and out == b""
    assert err.count("hystkit: error:") == 1 and "oracle" in err and "--center" in err


def test_an_unknown_family_is_an_error_before_reading(model, tmp_path, capsys, monkeypatch):
    _, path = model
    data = json.loads(path.read_text())
    data["model"] = "no-such-family"
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(data))
    monkeypatch.setattr(sys, "stdin", io.StringIO("0.0,1.0\n"))
    assert main(["stream", str(bad)]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and "no-such-family" in captured.err
    assert sys.stdin.read() == "0.0,1.0\n"  # nothing was read


def test_serial_port_through_a_pseudo_terminal(model, validation):
    comp, path = model
    master, slave = os.openpty()
    with command(str(path), "--serial", os.ttyname(slave), "--baud", "115200") as proc:
        try:
            assert read_line(proc.stdout) == b"time,position_estimate,flags\n"  # port open
            got = []
            for line in lines_of(validation, 50):
                os.write(master, line.encode())
                got.append(float(read_line(proc.stdout).split(b",")[1]))
        finally:
            os.close(slave)
            os.close(master)  # the device goes away: the stream ends with its summary
        code = proc.wait(WAIT)
        err = proc.stderr.read().decode()
    assert code == 0, err
    assert_array_equal(got, expected(comp, validation.sensor[:50])[0])
    assert "closed" in err and "50 samples; latency" in err


def test_serial_without_pyserial_names_the_extra(model):
    _, path = model
    probe = ("import sys; sys.modules['serial'] = None; from hystkit.cli import main; "
             f"sys.exit(main(['stream', {str(path)!r}, '--serial', '/dev/null']))")
    proc = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          timeout=WAIT, check=False, stdin=subprocess.DEVNULL)
    assert proc.returncode == 2 and proc.stdout == ""
    assert proc.stderr.strip() == ('hystkit: error: --serial needs the optional pyserial '
                                   'package: pip install "hystkit[serial]"')


def test_sync_start_from_a_file(model, validation, tmp_path, capsys):
    comp, path = model
    data = tmp_path / "in.csv"
    data.write_text("".join(lines_of(validation, 120)))
    assert main(["stream", str(path), "--in", str(data), "--start", "sync"]) == 0
    captured = capsys.readouterr()
    _, estimate, _ = parse_output(captured.out)
    assert_array_equal(estimate, Stream(comp, "sync").process(validation.sensor[:120]))
    assert "start-up e_sync" in captured.err and "drive the sensor to" in captured.err


def test_baud_without_serial_is_refused(model, capsys):
    _, path = model
    assert main(["stream", str(path), "--baud", "9600"]) == 2
    assert "--baud is for --serial" in capsys.readouterr().err


def test_a_runaway_sample_is_skipped_and_the_stream_goes_on(model, validation, tmp_path,
                                                            capsys):
    comp, path = model
    lines = lines_of(validation, 30)
    lines[10] = f"{float(validation.time[10])!r},1e300\n"  # the estimate runs away
    data = tmp_path / "in.csv"
    data.write_text("".join(lines))
    assert main(["stream", str(path), "--in", str(data)]) == 0
    captured = capsys.readouterr()
    _, estimate, _ = parse_output(captured.out)
    assert_array_equal(estimate, expected(comp, np.delete(validation.sensor[:30], 10))[0])
    assert ("hystkit: warning: " + str(data) + ": 1 line(s) estimate ran away (skipped; "
            "first at line 11)") in captured.err
    assert "irregular step" in captured.err  # the gap the skipped sample left


def test_a_missing_input_file_is_one_error_line(model, tmp_path, capsys):
    _, path = model
    assert main(["stream", str(path), "--in", str(tmp_path / "none.csv")]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err.startswith("hystkit: error: ")
    assert "none.csv: cannot read" in captured.err


def test_an_endless_line_is_skipped_in_bounded_memory(model, validation, tmp_path, capsys):
    comp, path = model
    lines = lines_of(validation, 20)
    lines.insert(5, "1" * 1_000_000 + ",2\n")  # no pair of numbers: a megabyte of noise
    data = tmp_path / "in.csv"
    data.write_text("".join(lines))
    assert main(["stream", str(path), "--in", str(data)]) == 0
    captured = capsys.readouterr()
    _, estimate, _ = parse_output(captured.out)
    assert_array_equal(estimate, expected(comp, validation.sensor[:20])[0])
    assert f"{data}: 1 line(s) line too long (skipped; first at line 6)" in captured.err


def test_a_header_with_other_columns_after_a_blank_line(model, validation, tmp_path, capsys):
    comp, path = model
    rows = [f"{s!r},7,{t!r}\n" for t, s in zip(validation.time[:30].tolist(),
                                                validation.sensor[:30].tolist(), strict=True)]
    data = tmp_path / "in.csv"
    data.write_text("\n\ufeffSensor,temperature,Time\n" + "".join(rows), encoding="utf-8")
    assert main(["stream", str(path), "--in", str(data)]) == 0
    captured = capsys.readouterr()
    times, estimate, _ = parse_output(captured.out)
    assert_array_equal(estimate, expected(comp, validation.sensor[:30])[0])
    assert times[1] == repr(float(validation.time[1]))
    assert "warning" not in captured.err
