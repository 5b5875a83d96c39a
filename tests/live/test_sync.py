"""e_sync (eq. 2.21-2.22): after it, the model state no longer depends on the history before."""

import dataclasses

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from hystkit.compensation import Compensator, LinearBaseline, Scaling
from hystkit.errors import InputError
from hystkit.live import Stream, SyncExcitation, sync_excitation
from hystkit.models import FAMILIES

DT = 0.01
CASES = [(name, mode) for name in sorted(FAMILIES) for mode in ("direct", "inverse")
         if mode == "direct" or FAMILIES[name].has_inverse]


def make_compensator(name: str, mode: str, seed: int = 2, size: int = 3) -> Compensator:
    family = FAMILIES[name]
    structure = family.make_structure(DT, min(size, family.max_size))
    params = family.random_params(structure, np.random.default_rng(seed))
    return Compensator(structure, params, mode, "fit", Scaling(1190.0, 250.0, 3.0, 2.5),
                       LinearBaseline(1.0, 0.0), model=name, training_range=(-0.9, 0.9),
                       polarity=-1.0, position_range=(-1.0, 7.0))


def other_histories(comp: Compensator) -> list[np.ndarray]:
    """Prior states from histories unlike the ones sync_excitation checks itself: a decaying
    sine, a ramp held at 0.9, seeded noise, a rest at -0.5."""
    family, st, params = comp.family, comp.structure, comp.params
    t = np.arange(700) * DT
    rng = np.random.default_rng(99)
    inputs = [0.95 * np.sin(2 * np.pi * 0.4 * t) * np.exp(-t / 3),
              np.minimum(t / 3, 0.9), np.clip(rng.normal(0, 0.5, t.size), -1, 1)]
    states = [family.simulate(st, params, u)[1] for u in inputs]
    return [*states, family.rest_state(st, params, -0.5)]


@pytest.mark.parametrize("case", CASES, ids=lambda c: f"{c[0]}-{c[1]}")
def test_after_sync_the_state_is_that_of_any_history_or_the_model_is_refused(case):
    comp = make_compensator(*case)
    family, st, params = comp.family, comp.structure, comp.params
    try:
        sync = sync_excitation(comp)
    except InputError as exc:
        # Refused: then a longest excitation really leaves history-dependent states.
        assert "still remembers its history" in str(exc)
        v = np.repeat([1.0, -1.0, 0.0], round(200 / DT))
        ends = [family.simulate(st, params, v, x0)[1] for x0 in other_histories(comp)]
        assert max(np.max(np.abs(e - ends[0])) for e in ends) > 1e-6
        return
    scale = max(1.0, np.max(np.abs(sync.state_after)))
    for x0 in other_histories(comp):
        _, x_end = family.simulate(st, params, sync.normalised, x0)
        assert_allclose(x_end, sync.state_after, rtol=0, atol=sync.tolerance * scale)
    assert sync.spread <= sync.tolerance * scale
    assert sync.duration == pytest.approx(len(sync.levels) * sync.hold_seconds)
    assert sync.normalised.size == sync.signal.size


@pytest.mark.parametrize("levels", [(1, -1), (-1, 1)], ids=["eq-2.21", "eq-2.22"])
def test_pl_cells_land_where_eq_2_21_says(levels):
    """u_k(t0+) = E0 -/+ (2N - k) V_T for every prior state; the discrete model adds one
    sample of creep at the threshold, dt I_T / (p - 1) (eq. 2.16 at |v| = k V_T)."""
    family = FAMILIES["pl"]
    structure = family.make_structure(DT, 4)
    params = dataclasses.replace(family.random_params(structure, np.random.default_rng(1)),
                                 i_t=1e-3, v_t=0.2)
    n_vt = structure.n_cells * params.v_t
    e0 = levels[0] * n_vt
    e1 = e0 + levels[1] * 2 * n_vt
    v = np.array([e0, e0, e1])
    k = np.arange(1, structure.n_cells + 1)
    creep = DT * params.i_t / (structure.power - 1)
    want = e0 - levels[0] * ((2 * structure.n_cells - k) * params.v_t + creep)
    rng = np.random.default_rng(5)
    for _ in range(5):
        _, x = family.simulate(structure, params, v, rng.uniform(-1, 1, structure.n_cells))
        assert_allclose(x, want, rtol=0, atol=1e-12)


def test_pl_uses_the_documents_step():
    comp = make_compensator("pl", "inverse")
    sync = sync_excitation(comp)
    n_vt = comp.structure.n_cells * comp.params.v_t
    assert sync.levels == (n_vt, -n_vt, 0.0)
    assert "eq. 2.21" in sync.rule


def test_signal_in_user_units():
    inverse = sync_excitation(make_compensator("preisach", "inverse"))
    assert inverse.quantity == "position" and inverse.unit == "mm"
    assert_allclose((inverse.signal - 3.0) / 2.5, inverse.normalised, rtol=0, atol=1e-15)
    direct = sync_excitation(make_compensator("preisach", "direct"))
    assert direct.quantity == "sensor"
    assert_allclose(-(direct.signal - 1190.0) / 250.0, direct.normalised, rtol=0, atol=1e-15)
    assert isinstance(direct, SyncExcitation) and not direct.signal.flags.writeable


def test_a_sync_start_continues_from_the_state_after():
    comp = make_compensator("preisach", "inverse")
    sync = sync_excitation(comp)
    stream = Stream(comp, start="sync")
    assert_array_equal(stream.state.x, sync.state_after)
    # the sensor the model predicts after the sync, in sensor units (polarity -1)
    p_true = 0.8 * np.sin(np.arange(300) * 0.05)
    s, _ = comp.family.simulate(comp.structure, comp.params, p_true, sync.state_after)
    sensor = 1190.0 - 250.0 * s
    p, _ = comp.family.invert(comp.structure, comp.params, comp.normalised_sensor(sensor),
                              sync.state_after)
    got = stream.process(sensor)
    assert_allclose(got, p * 2.5 + 3.0, rtol=0, atol=1e-12)
    # and the inverse started in sync recovers the position the model was driven with
    assert_allclose(got, p_true * 2.5 + 3.0, rtol=0, atol=1e-6)


@pytest.mark.parametrize("start", [-0.8, 0.0, 0.7])
def test_streaming_the_sync_itself_synchronises_a_direct_stream(start):
    """The bench recipe for a direct compensator: stream e_sync from an arbitrary rest."""
    comp = make_compensator("preisach", "direct")
    sync = sync_excitation(comp)
    stream = Stream(comp)
    stream.process(np.array([1190.0 - 250.0 * start]))
    stream.process(sync.signal)
    assert_allclose(stream.state.x, sync.state_after, rtol=0, atol=sync.tolerance)
