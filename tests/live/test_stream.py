"""The streaming compensator gives exactly the offline causal estimate, chunk by chunk."""

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose, assert_array_equal

from hystkit.compensation import Compensator, LinearBaseline, Scaling, save_compensator
from hystkit.errors import FitDivergedError, InputError
from hystkit.io import Recording
from hystkit.live import Stream, StreamState, advance
from hystkit.live._stream import initial_state
from hystkit.models import FAMILIES

DT = 0.01
N = 600
CENTERS = ("fit", "tare", "track")
CASES = [(name, mode) for name in sorted(FAMILIES) for mode in ("direct", "inverse")
         if mode == "direct" or FAMILIES[name].has_inverse]


def make_compensator(name: str, mode: str, center: str, size: int = 3) -> Compensator:
    """A compensator of family ``name`` with drawn (not fitted) parameters and made-up but
    non-trivial conventions: offsets, scales, flipped polarity, short tare and track windows."""
    family = FAMILIES[name]
    structure = family.make_structure(DT, min(size, family.max_size))
    params = family.random_params(structure, np.random.default_rng(2))
    return Compensator(structure, params, mode, center, Scaling(1190.0, 250.0, 3.0, 2.5),
                       LinearBaseline(1.0, 0.0), model=name, training_range=(-0.9, 0.9),
                       polarity=-1.0, tare_seconds=0.5, track_seconds=1.5,
                       sensor_reference=1195.0, position_range=(-1.0, 7.0))


def sensor_for(comp: Compensator, seed: int = 1) -> np.ndarray:
    """Raw sensor samples [sensor units] the compensator can follow: for an inverse, the
    forward model's own output (an inverse of a drawn model need not track any signal)."""
    rng = np.random.default_rng(seed)
    t = np.arange(N) * DT
    u = 0.8 * np.sin(2 * np.pi * 0.7 * t) * np.exp(-t / 4) + 0.05 * rng.standard_normal(N)
    if comp.mode == "inverse":
        u, _ = comp.family.simulate(comp.structure, comp.params, u)
    u = u / np.max(np.abs(u))
    return -(u * 250.0) + 1200.0 + 2.0 * t  # polarity -1 and a drift for tare / track


def offline(comp: Compensator, sensor: np.ndarray) -> np.ndarray:
    return comp.estimate(Recording(time=np.arange(sensor.size) * DT, sensor=sensor))


def chunked(comp: Compensator, sensor: np.ndarray, sizes: list[int]) -> np.ndarray:
    stream, out, k, i = Stream(comp), [], 0, 0
    while k < sensor.size:
        out.append(stream.process(sensor[k:k + sizes[i % len(sizes)]]))
        k += sizes[i % len(sizes)]
        i += 1
    return np.concatenate(out)


@pytest.mark.parametrize("center", CENTERS)
@pytest.mark.parametrize("case", CASES, ids=lambda c: f"{c[0]}-{c[1]}")
def test_chunks_of_any_fixed_size_give_the_offline_estimate(case, center):
    comp = make_compensator(*case, center)
    sensor = sensor_for(comp)
    want = offline(comp, sensor)
    for size in (1, 7, 64, N):
        assert_array_equal(chunked(comp, sensor, [size]), want)


@pytest.mark.parametrize("center", CENTERS)
@pytest.mark.parametrize("case", CASES, ids=lambda c: f"{c[0]}-{c[1]}")
def test_step_by_step_equals_process(case, center):
    comp = make_compensator(*case, center)
    comp = dataclasses.replace(comp, tare_seconds=0.8)  # the window ends inside the run
    sensor = sensor_for(comp)[:150]
    # normalised about -1.5 whatever the centring: flagged, bounded (polarity -1, scale 250)
    sensor[100:110] = np.broadcast_to(comp.sensor_offset(sensor), sensor.shape)[100] + 375.0
    stream = Stream(comp)
    stepped = [stream.step_flagged(v) for v in sensor]
    whole = Stream(comp).process_flagged(sensor)
    assert_array_equal([o.estimate for o in stepped], whole.estimate)
    for k, name in ((1, "sensor_outside"), (2, "estimate_outside")):
        flags = np.array([o[k] for o in stepped])
        assert_array_equal(flags, getattr(whole, name))
    assert np.any([o.sensor_outside for o in stepped])
    assert stream.state.n_samples == sensor.size


@pytest.mark.parametrize("name", ["ladder", "bobbio", "mpl"])
def test_steps_and_chunks_mixed_give_the_offline_estimate(name):
    """Steps reuse the previous step's start (direct mode); a chunk in between resets that."""
    comp = make_compensator(name, "direct", "track")
    sensor = sensor_for(comp)
    stream, out, k = Stream(comp), [], 0
    for n_steps, chunk in [(5, 7), (3, 1), (9, 64), (1, 2), (40, 0)] * 4:  # 528 of 600
        out += [stream.step(v) for v in sensor[k:k + n_steps]]
        out += list(stream.process(sensor[k + n_steps:k + n_steps + chunk]))
        k += n_steps + chunk
    out += list(stream.process(sensor[k:]))
    assert_array_equal(np.array(out), offline(comp, sensor))


@settings(max_examples=25, deadline=None)
@given(sizes=st.lists(st.integers(1, 90), min_size=1, max_size=12),
       case=st.sampled_from(CASES), center=st.sampled_from(CENTERS))
def test_chunks_of_any_sizes_give_the_offline_estimate(sizes, case, center):
    comp = make_compensator(*case, center)
    sensor = sensor_for(comp)
    assert_array_equal(chunked(comp, sensor, sizes), offline(comp, sensor))


def test_bit_identity_holds_on_a_fitted_compensator():
    """The same on a real fit (mPL, virtual sensor) with every deployable centring."""
    from hystkit.compensation import fit_compensator
    from hystkit.sensors import simulate_experiment

    fit_rec, val_rec = simulate_experiment("noise", 1), simulate_experiment("noise", 2)
    for center in CENTERS:
        comp = fit_compensator(fit_rec, 1, center=center, diagnose=False)
        want = comp.estimate(val_rec)
        assert_array_equal(chunked(comp, val_rec.sensor, [64]), want)
        assert_array_equal(chunked(comp, val_rec.sensor, [1, 7, 300]), want)


def test_a_resumed_stream_continues_exactly():
    comp = make_compensator("mpl", "inverse", "tare")
    sensor = sensor_for(comp)
    first = Stream(comp)
    head = first.process(sensor[:123])
    saved = first.state
    tail = Stream.from_state(comp, saved).process(sensor[123:])
    assert_array_equal(np.concatenate([head, tail]), offline(comp, sensor))
    assert saved.n_samples == 123 and not saved.x.flags.writeable
    with pytest.raises(InputError, match="needs 3 finite numbers"):
        Stream.from_state(comp, StreamState(np.zeros(2), 5))
    with pytest.raises(InputError, match="no model state"):
        Stream.from_state(comp, StreamState(None, 5))


def test_a_tare_rest_position_moves_the_estimate_as_offline():
    comp = dataclasses.replace(make_compensator("mpl", "direct", "tare"), rest_position=2.0)
    sensor = sensor_for(comp)
    rec = Recording(time=np.arange(N) * DT, sensor=sensor)
    want = comp.estimate(rec, rest_position=3.5)
    stream = Stream(comp, rest_position=3.5)
    got = np.concatenate([stream.process(sensor[k:k + 50]) for k in range(0, N, 50)])
    assert_array_equal(got, want)
    # moved by 3.5 - 2.0 mm, up to the rounding of p * scale + offset
    assert_allclose(got - comp.estimate(rec), np.full(N, 1.5), rtol=0, atol=1e-12)


def test_advance_is_pure():
    comp = make_compensator("pl", "direct", "track")
    sensor = sensor_for(comp)
    state = Stream(comp).state
    a, after = advance(comp, state, sensor[:50])
    b, _ = advance(comp, state, sensor[:50])
    assert_array_equal(a.estimate, b.estimate)
    assert state.n_samples == 0 and after.n_samples == 50


def test_flags_are_those_of_compensate():
    comp = make_compensator("mpl", "direct", "fit")
    sensor = sensor_for(comp)
    sensor[100:110] += 400.0  # well outside the training range
    rec = Recording(time=np.arange(N) * DT, sensor=sensor)
    out = Stream(comp).process_flagged(sensor)
    assert_array_equal(out.sensor_outside, comp.sensor_outside(rec))
    assert_array_equal(out.estimate_outside, comp.estimate_outside(comp.estimate(rec)))
    assert out.sensor_outside[100:110].all()
    stream = Stream(comp)
    stepped = [stream.step_flagged(v) for v in sensor]
    assert_array_equal([o.estimate_outside for o in stepped], out.estimate_outside)
    assert_array_equal([o.sensor_outside for o in stepped], out.sensor_outside)


def test_a_given_start_state_is_used_and_checked():
    comp = make_compensator("mpl", "direct", "fit")
    sensor = sensor_for(comp)
    x0 = np.array([0.3, -0.2, 0.1])
    s = comp.normalised_sensor(sensor)
    want, _ = comp.family.simulate(comp.structure, comp.params, s, x0)
    got = Stream(comp, start=x0).process(sensor)
    assert_allclose(got, want * comp.scaling.position_scale + comp.scaling.position_offset,
                    rtol=0, atol=1e-12)
    with pytest.raises(InputError, match="needs 3 finite numbers"):
        Stream(comp, start=np.zeros(4))
    with pytest.raises(InputError, match="'rest', 'sync'"):
        Stream(comp, start="warm")


def test_the_oracle_centring_is_refused():
    comp = make_compensator("mpl", "direct", "recording")
    with pytest.raises(InputError, match="oracle"):
        Stream(comp)
    # nor can a state made for a causal compensator run it through the pure function
    causal = make_compensator("mpl", "direct", "track")
    state = initial_state(causal)
    with pytest.raises(InputError, match="oracle"):
        advance(comp, state, sensor_for(causal)[:10])


def test_a_runaway_estimate_names_the_stream_sample_and_keeps_the_state():
    comp = make_compensator("mpl", "direct", "fit")
    sensor = sensor_for(comp)
    sensor[205] = 1e12  # normalised |s| ~ 4e9: the estimate leaves MAX_NORMALISED
    with pytest.raises(FitDivergedError, match="sample 205:"):
        offline(comp, sensor)
    stream = Stream(comp)
    stream.process(sensor[:200])
    before = stream.state
    with pytest.raises(FitDivergedError, match="stream: sample 205: the mpl compensator"):
        stream.process(sensor[200:210])
    assert stream.state is before


def test_from_file(tmp_path):
    comp = make_compensator("ladder", "inverse", "track")
    path = save_compensator(comp, tmp_path / "m.json")
    sensor = sensor_for(comp)
    assert_array_equal(Stream.from_file(path).process(sensor), offline(comp, sensor))


def test_an_empty_chunk_changes_nothing():
    comp = make_compensator("mpl", "direct", "tare")
    stream = Stream(comp)
    assert stream.process(np.empty(0)).size == 0
    assert stream.state.n_samples == 0 and isinstance(stream.state, StreamState)
