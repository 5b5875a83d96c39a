"""``hystkit stream`` reads its input in chunks (issue 29, item 4): what each read holds, cut
into lines exactly as reading line by line cut them, and compensated in one compiled call per
chunk with the same results, warnings and line numbers as sample by sample."""

from __future__ import annotations

import io
import random

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from hystkit.cli import _stream_chunks, _stream_read
from hystkit.compensation import fit_compensator, save_compensator
from hystkit.io import Recording
from hystkit.sensors import simulate_experiment

from ..cli_support import run_cli

MAX = _stream_read.MAX_LINE


def _by_lines(text: str) -> list[str]:
    """The lines as read one by one (``readline``, a line too long given as the marker)."""
    return list(_stream_read.bounded(io.StringIO(text).readline))


def _in_reads(text: str, cuts: list[int]) -> list[str]:
    """The lines of `text` delivered in reads ending at `cuts`, through line_chunks."""
    pieces = iter([text[a:b] for a, b in zip([0, *cuts], [*cuts, len(text)], strict=True)])
    chunks = list(_stream_read.line_chunks(lambda: next(pieces, "")))
    assert all(chunks)
    return [line for chunk in chunks for line in _stream_read.lines_of(chunk)]


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("last", ["", "0.5,12", "9" * (MAX + 3)], ids=["ended", "cut", "long"])
def test_lines_cut_from_reads_are_the_lines_read_one_by_one(seed, last):
    rng = random.Random(seed)
    lengths = [0, 5, MAX - 2, MAX - 1, MAX, MAX + 1, 3 * MAX + 7, 20, 1]
    text = "".join("7" * rng.choice(lengths) + "\n" for _ in range(40)) + last
    cuts = sorted(rng.sample(range(1, len(text)), rng.randint(1, 60)))
    want = _by_lines(text)
    assert _in_reads(text, cuts) == want
    assert _in_reads(text, []) == want
    assert (_stream_read.TOO_LONG in want) and any(len(w) == MAX for w in want)


def test_reads_are_decoded_across_their_boundaries():
    """A character of two bytes and a CR LF line end split between reads: UTF-8, line ends
    as a text file reads them."""
    data = "0.0,1\r\n0.025,2 µ\r\n0.05,3\rx\n".encode()
    for cut in range(1, len(data)):
        pieces = iter([data[:cut], data[cut:], b""])
        read = _stream_read.decoded(lambda size, pieces=pieces: next(pieces))
        got = ""
        while text := read():
            got += text
        assert got == "0.0,1\n0.025,2 µ\n0.05,3\nx\n", cut


@pytest.fixture(scope="module")
def model(tmp_path_factory):
    folder = tmp_path_factory.mktemp("chunks")
    comp = fit_compensator(simulate_experiment("noise", 1), 1, center="track", diagnose=False)
    return comp, save_compensator(comp, folder / "noise.json")


def _offline(comp, sensor: np.ndarray) -> np.ndarray:
    return comp.estimate(Recording(time=np.arange(sensor.size) * comp.structure.dt,
                                   sensor=sensor))


def test_a_file_of_many_chunks_is_the_offline_estimate(model, tmp_path, capsys):
    comp, path = model
    rec = simulate_experiment("decay", 2)
    data = tmp_path / "in.csv"
    data.write_text("time,sensor\n" + "".join(
        f"{t!r},{s!r}\n" for t, s in zip(rec.time.tolist(), rec.sensor.tolist(), strict=True)))
    assert data.stat().st_size > 3 * _stream_read.CHUNK_BYTES  # lines cut between reads
    code, out, err = run_cli(capsys, "stream", path, "--in", data)
    assert code == 0, err
    rows = [row.split(",") for row in out.splitlines()[1:]]
    assert_array_equal([float(r[1]) for r in rows], _offline(comp, rec.sensor))
    assert [r[0] for r in rows] == [repr(t) for t in rec.time.tolist()]
    assert "warning" not in err
    assert f"hystkit stream: {rec.n_samples} samples; latency per sample median" in err


def test_after_a_runaway_the_next_lines_are_checked_from_the_time_before_it(model, tmp_path,
                                                                          capsys):
    """The line after a skipped runaway repeats its time: against the last sample taken it
    advances by one dt, so it is compensated, not 'time not advancing' (line by line it was
    so; a chunk checks its times before it knows of the runaway, and checks them again)."""
    comp, path = model
    rec = simulate_experiment("decay", 2)
    t, s = rec.time[:40].tolist(), rec.sensor[:40].tolist()
    lines = [f"{a!r},{b!r}\n" for a, b in zip(t, s, strict=True)]
    lines[10] = f"{t[10]!r},1e300\n"  # runs away
    lines.insert(11, f"{t[10]!r},{s[10]!r}\n")  # its time again, its own sensor value
    lines[25] = f"{t[23]!r},{s[24]!r}\n"  # a time going back (line 26): skipped
    data = tmp_path / "in.csv"
    data.write_text("".join(lines))
    code, out, err = run_cli(capsys, "stream", path, "--in", data)
    assert code == 0, err
    estimate = [float(row.split(",")[1]) for row in out.splitlines()[1:]]
    assert_array_equal(estimate, _offline(comp, np.delete(rec.sensor[:40], 24)))
    warnings = sorted(line for line in err.splitlines() if "warning" in line)
    assert warnings == sorted([
        f"hystkit: warning: {data}: 1 line(s) estimate ran away (skipped; first at line 11)",
        f"hystkit: warning: {data}: 1 line(s) time not advancing (skipped; first at line 26)",
        (f"hystkit: warning: {data}: 1 line(s) irregular step (compensated, but the step "
         f"differs from the model's dt = {comp.structure.dt:g} s by more than 1%; first at "
         f"line 27)")])


def _plain_lines(rec, n: int, scale: float = 1.0) -> list[str]:
    return [f"{t * scale!r},{s!r}\n" for t, s in zip(rec.time[:n].tolist(),
                                                      rec.sensor[:n].tolist(), strict=True)]


def _edited(kind: str, rec) -> tuple[list[str], list[str]]:
    """Lines of plain numbers with what the two paths must treat alike; options."""
    lines = _plain_lines(rec, 3000, 1e3 if kind == "ms" else 1.0)
    if kind == "dropped":
        del lines[100], lines[1500:1503]  # irregular steps
    elif kind == "runaway":
        for k in (7, 2100, 2101):
            lines[k] = lines[k].split(",")[0] + ",1e300\n"
        del lines[2500]
    elif kind == "first runs away":
        lines[0] = lines[0].split(",")[0] + ",-1e300\n"
    return ["time,sensor\n", *lines], (["--time-unit", "ms"] if kind == "ms" else [])


@pytest.mark.parametrize("kind", ["dropped", "runaway", "first runs away", "ms"])
def test_plain_chunks_and_line_by_line_give_the_same_output(kind, model, tmp_path, capsys,
                                                            monkeypatch):
    _, path = model
    lines, options = _edited(kind, simulate_experiment("decay", 2))
    data = tmp_path / "in.csv"
    data.write_text("".join(lines))
    plain = run_cli(capsys, "stream", path, "--in", data, *options)
    monkeypatch.setattr(_stream_chunks, "plain_chunk", lambda *args: None)
    by_line = run_cli(capsys, "stream", path, "--in", data, *options)
    assert plain[0] == by_line[0] == 0, plain[2]
    assert plain[1] == by_line[1]
    assert plain[2].splitlines()[:-1] == by_line[2].splitlines()[:-1]  # all but the latency
    assert ("ran away" in plain[2]) == ("runs away" in kind or kind == "runaway")


def test_plain_lines_take_the_plain_path(model, tmp_path, capsys, monkeypatch):
    _, path = model
    data = tmp_path / "in.csv"
    data.write_text("time,sensor\n" + "".join(_plain_lines(simulate_experiment("decay", 2),
                                                             3000)))
    seen = []
    any_chunk = _stream_chunks.any_chunk
    monkeypatch.setattr(_stream_chunks, "any_chunk",
                        lambda stream, chunk, *args: seen.extend(chunk) or any_chunk(
                            stream, chunk, *args))
    code, out, err = run_cli(capsys, "stream", path, "--in", data)
    assert code == 0, err
    assert seen == ["time,sensor\n"] and len(out.splitlines()) == 3001


def test_a_file_past_its_header_is_read_as_its_lines_rewritten_one_by_one(model, tmp_path,
                                                                          capsys, monkeypatch):
    """After the header a file in stream's own form passes unrewritten (faster); what the
    parser makes of its odd lines is what it made of them rewritten."""
    from hystkit.cli import _stream_input

    _, path = model
    lines = _plain_lines(simulate_experiment("decay", 2), 200)
    lines[10] = lines[10].replace(",", " ,  ")  # spaces
    lines[20] = lines[20].rstrip("\n") + ",21.5,x\n"  # more columns
    lines[30:31] = ["# a comment\n", "\n", "0.5\n", lines[30].rstrip("\n") + ",\n"]
    data = tmp_path / "in.csv"
    data.write_text("\ufefftime,sensor,temperature\n" + "".join(lines), encoding="utf-8")
    passed = run_cli(capsys, "stream", path, "--in", data)
    monkeypatch.setattr(_stream_input.Rewriter, "chunk",
                        lambda self, text: "".join(self(line)
                                                   for line in _stream_read.lines_of(text)))
    rewritten = run_cli(capsys, "stream", path, "--in", data)
    assert passed[0] == rewritten[0] == 0, passed[2]
    assert passed[1] == rewritten[1] and len(passed[1].splitlines()) == 201
    assert passed[2].splitlines()[:-1] == rewritten[2].splitlines()[:-1]
    assert "2 line(s) missing field" in passed[2]
