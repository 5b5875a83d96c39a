"""``stream --adapt`` fed one absurd reference among good ones (issue 25.6).

Before: a reference of 1e20 set the gain to ~1e17 and every later estimate to ~1e19 mm with exit
0, and 40 good references never recovered it; 1e200 ended the stream with an internal
OverflowError (exit 70) for ``gain``, ``weights`` and ``full``. Now it is rejected before it
moves anything, counted in the summary, and the estimates are those of the stream without it.
"""

from __future__ import annotations

import numpy as np
import pytest

from hystkit.io import read_recording

EVERY = 40  # one reference per second at 40 Hz


def _stream_input(good, folder, absurd: float | None):
    rec = read_recording(good["val"])
    lines = ["time,sensor,reference"]
    n_refs = 0
    for k, (t, s, p) in enumerate(zip(rec.time, rec.sensor, rec.position, strict=True)):
        r = ""
        if k % EVERY == 5:
            r = repr(absurd) if (absurd is not None and n_refs == 0) else repr(float(p))
            n_refs += 1
        lines.append(f"{float(t)!r},{float(s)!r},{r}")
    path = folder / f"in_{absurd}.csv"
    path.write_text("\n".join(lines) + "\n")
    return path, n_refs


def _estimates(out: str) -> np.ndarray:
    return np.array([float(line.split(",")[1]) for line in out.splitlines()[1:]])


@pytest.mark.parametrize("adapt", ["gain", "weights", "full"])
@pytest.mark.parametrize("absurd", [1e20, 1e200])
def test_one_absurd_reference_is_rejected_and_reported(cli, good, tmp_path, adapt, absurd):
    options = ["--refit-every", "50"] if adapt == "full" else []
    bad, n_refs = _stream_input(good, tmp_path, absurd)
    run = cli("stream", good["model"], "--in", bad, "--adapt", adapt, *options)
    run.clean()
    assert run.code == 0, run.err
    estimates = _estimates(run.out)
    assert estimates.size == 8000 and np.max(np.abs(estimates)) < 10.0  # mm; ±3 mm device
    assert f"{n_refs - 1} references used" in run.err
    assert "1 rejected as implausible" in run.err
    if adapt != "full":  # the stream without that reference, bit for bit
        clean, _ = _stream_input(good, tmp_path, None)
        text = clean.read_text().splitlines()
        text[1 + 5] = text[1 + 5].rsplit(",", 1)[0] + ","  # its first reference left out
        clean.write_text("\n".join(text) + "\n")
        without = cli("stream", good["model"], "--in", clean, "--adapt", adapt)
        assert without.out == run.out
