"""The compiled stream (issue 29, item 4): one kernel per sample or chunk, the offline bits.

``Stream`` runs its samples through the family's compiled block when that block gives the
offline run's bits on a probe signal, else through the readable Python path; either way the
estimates, flags and band are the offline ones (test_stream.py checks every family and
centring sample by sample and in chunks). Here: which path a stream takes and why, that the
compiled one is really taken, that a block that is not exact is caught, and ``step_many``.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from hystkit.errors import FitDivergedError
from hystkit.io import Recording
from hystkit.live import Stream
from hystkit.live import _stream as stream_module
from hystkit.models import Block

from .test_stream import CASES, CENTERS, DT, N, make_compensator, offline, sensor_for


def _block_is_exact(comp) -> bool:
    """Whether the family's block, sample by sample from the offline run's own state after
    a few samples, gives that run's outputs and end state bit for bit (on the test signal)."""
    s = comp.normalised_sensor(sensor_for(comp))
    run = comp.family.invert if comp.mode == "inverse" else comp.family.simulate
    _, x = run(comp.structure, comp.params, s[:8])
    want, want_end = run(comp.structure, comp.params, s[8:], x)
    block = comp.family.block(comp.structure, comp.params, comp.mode == "inverse")
    a, b = np.array(x, dtype=float), np.empty(block.n_state)
    got = np.empty(s.size - 8)
    for k, v in enumerate(s[8:]):
        b[:] = a
        got[k] = block.step(block.body, a, b, 0, v)
        a, b = b, a
    return bool(np.array_equal(got, want) and np.array_equal(a, want_end))


@pytest.mark.parametrize("case", CASES, ids=lambda c: f"{c[0]}-{c[1]}")
def test_a_stream_is_compiled_exactly_when_the_block_is_exact(case):
    """A stream runs compiled exactly when its family's block, looped, gives the offline run's
    bits, and gives the offline bits either way (a block that is not exact:
    test_a_block_that_is_not_exact_is_caught_by_the_probe)."""
    comp = make_compensator(*case, "track")
    exact = _block_is_exact(comp)
    stream = Stream(comp)
    assert stream.compiled == exact
    sensor = sensor_for(comp)
    assert_array_equal([stream.step(v) for v in sensor], offline(comp, sensor))


@pytest.mark.parametrize("case", CASES, ids=lambda c: f"{c[0]}-{c[1]}")
def test_every_family_runs_compiled(case):
    """Every offline run sums in its block's order: bobbio and gpreisach direct (compiled
    forward passes, no numpy product after the kernel), pi's inverse (its run carries the
    forward plays and forms the inverse plays from them each sample, as the block does)."""
    assert Stream(make_compensator(*case, "fit")).compiled


def test_a_block_that_is_not_exact_is_caught_by_the_probe(monkeypatch):
    """A block one ulp off the offline run (its bias nudged) is not used; the stream takes the
    Python path and gives the offline bits."""
    comp = make_compensator("mpl", "direct", "fit")
    family = type(comp.family)
    block = family.block

    def nudged(self, structure, params, inverse=False):
        found = block(self, structure, params, inverse)
        body = found.body.copy()
        body[1] = np.nextafter(body[1], np.inf)  # V_b
        return Block(found.step, body, found.n_state)

    monkeypatch.setattr(family, "block", nudged)
    stream = Stream(comp)
    assert not stream.compiled
    sensor = sensor_for(comp)
    assert_array_equal([stream.step(v) for v in sensor], offline(comp, sensor))


@pytest.mark.parametrize("center", CENTERS)
def test_compiled_steps_do_not_touch_the_python_path(center, monkeypatch):
    """After the first sample (a stream at rest has no model state before it) every step and
    chunk runs in the kernel."""
    comp = make_compensator("mpl", "inverse", center)
    sensor = sensor_for(comp)
    stream = Stream(comp)
    first = stream.step(sensor[0])

    def refuse(*args, **kwargs):
        raise AssertionError("the Python path was taken")

    monkeypatch.setattr(stream_module, "_advance_one", refuse)
    monkeypatch.setattr(stream_module, "_advance", refuse)
    got = [first] + [stream.step(v) for v in sensor[1:300]]
    got += list(stream.process(sensor[300:450])) + list(stream.step_many(sensor[450:]).estimate)
    assert_array_equal(got, offline(comp, sensor))


def test_state_reads_and_resumes_between_compiled_steps():
    comp = make_compensator("mpl-poly", "direct", "tare")
    comp = dataclasses.replace(comp, tare_seconds=0.8)
    sensor = sensor_for(comp)
    stream = Stream(comp)
    head = [stream.step(v) for v in sensor[:100]]
    saved = stream.state
    assert saved.n_samples == 100 and saved is stream.state  # made once, then kept
    more = [stream.step(v) for v in sensor[100:200]]
    assert saved.n_samples == 100  # immutable: the stream moved on without it
    resumed = Stream.from_state(comp, saved)
    assert_array_equal(resumed.process(sensor[100:200]), more)
    tail = resumed.process(sensor[200:])
    assert_array_equal(np.concatenate([head, more, tail]), offline(comp, sensor))


@pytest.mark.parametrize("compiled", [True, False], ids=["compiled", "python"])
@pytest.mark.parametrize("name", ["mpl", "bobbio"])
def test_step_many_stops_before_a_runaway_and_goes_on_after_it(name, compiled, monkeypatch):
    """As the command line runs it: the samples before the refused one are taken, the state
    stays that before it, step_flagged says why, and the rest continues as if it never came
    (the offline estimate of the signal without it). Every family runs compiled, so the
    Python path is taken by refusing the engine."""
    if not compiled:
        monkeypatch.setattr(stream_module, "compiled_engine", lambda path: None)
    comp = make_compensator(name, "direct", "track")
    sensor = sensor_for(comp)
    sensor[205] = 1e12  # normalised |s| ~ 4e9: the estimate leaves MAX_NORMALISED
    stream = Stream(comp)
    assert stream.compiled == compiled
    head = stream.step_many(sensor[:300])
    assert head.estimate.size == 205 and stream.state.n_samples == 205
    assert head.sensor_outside.size == head.estimate_outside.size == 205
    with pytest.raises(FitDivergedError, match="stream: sample 205:"):
        stream.step_flagged(sensor[205])
    assert stream.state.n_samples == 205
    tail = stream.step_many(sensor[206:])
    assert tail.estimate.size == N - 206
    want = offline(comp, np.delete(sensor, 205))
    assert_array_equal(np.concatenate([head.estimate, tail.estimate]), want)


def test_a_refused_chunk_leaves_the_state_as_it_was():
    comp = make_compensator("mpl", "direct", "tare")
    sensor = sensor_for(comp)
    stream = Stream(comp)
    stream.process(sensor[:200])
    before = stream.state
    bad = sensor[200:260].copy()
    bad[30] = 1e12
    with pytest.raises(FitDivergedError, match="sample 230:"):
        stream.process(bad)
    assert stream.state is before
    assert_array_equal(stream.process(sensor[200:]), offline(comp, sensor)[200:])


def test_flags_of_compiled_steps_are_those_of_compensate():
    comp = make_compensator("pl", "direct", "fit")
    sensor = sensor_for(comp)
    sensor[100:110] += 400.0  # well outside the training range
    rec = Recording(time=np.arange(N) * DT, sensor=sensor)
    stream = Stream(comp)
    assert stream.compiled
    stepped = [stream.step_flagged(v) for v in sensor]
    assert_array_equal([o.sensor_outside for o in stepped], comp.sensor_outside(rec))
    assert_array_equal([o.estimate_outside for o in stepped],
                       comp.estimate_outside(comp.estimate(rec)))
    assert all(type(o.sensor_outside) is bool for o in stepped)
    assert any(o.sensor_outside for o in stepped)


def test_the_band_of_compiled_steps_is_the_offline_band():
    from hystkit.compensation import fit_compensator, with_band
    from hystkit.sensors import simulate_experiment

    train = simulate_experiment("noise", 1)
    comp = with_band(fit_compensator(train, 1, center="track", diagnose=False), [train], 1)
    test = simulate_experiment("sine", 2)
    want = comp.estimate_with_band(test, 0.8)
    stream = Stream(comp, level=0.8)
    assert stream.compiled
    steps = [stream.step_flagged(v) for v in test.sensor[:300]]
    rest = stream.step_many(test.sensor[300:])
    for name in ("estimate", "lower", "upper"):
        got = np.concatenate([[getattr(s, name) for s in steps], getattr(rest, name)])
        assert_array_equal(got, getattr(want, name))


def test_a_tracking_stream_does_not_load_scipy(tmp_path):
    """The tracker's readable path repeats lfilter's operations: neither a compiled stream
    nor the readable chunk path (advance) nor an adapting stream loads scipy.signal (~0.7 s
    to import)."""
    import subprocess
    import sys

    from hystkit.compensation import save_compensator

    comp = make_compensator("mpl", "direct", "track")
    path = save_compensator(comp, tmp_path / "m.json")
    probe = ("import sys\nfrom hystkit.live import Stream\n"
             f"stream = Stream.from_file({str(path)!r})\n"
             "assert stream.compiled\n"
             "[stream.step(1200.0 + k) for k in range(50)]\n"
             "from hystkit.live import AdaptiveStream, StreamState, advance\n"
             "import numpy as np\n"
             "advance(stream.compensator, StreamState(None), 1200.0 + np.arange(50.0))\n"
             "AdaptiveStream(stream.compensator).step(1200.0, 0.1)\n"
             "print('scipy.signal' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         check=True, timeout=300).stdout
    assert out.strip() == "False"
