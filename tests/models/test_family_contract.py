"""The family protocol's contract, checked on every registered family alike.

Each family gets a fitted example (its default size, direct mode: sensor -> position on the
virtual sensor's noise run, normalised as the compensator does) and must then honour the
invariants every generic piece relies on. Family-specific property tests stay with the family
(``tests/models/<family>/``).
"""

from __future__ import annotations

import dataclasses
import functools
import importlib
import json

import numpy as np
import pytest
from numpy.testing import assert_allclose

from hystkit.identification import LOSSES
from hystkit.models import (
    ALL_LOSSES,
    FAMILIES,
    Capabilities,
    Family,
    get_family,
    numerical_linearisation,
)
from hystkit.sensors import simulate_experiment

NAMES = sorted(FAMILIES)
STAIRCASES = ("preisach", "gpreisach")  # Everett staircase state (see the linearisation test)
# families whose output is read out of the run's states by one matrix product over all samples
# (bobbio: y = c_1 u + F c + b): its last bit depends on where a run is split
BLAS_READ_OUT = ("bobbio",)
N_FIT = 1600  # 40 s at 40 Hz: enough to excite every family, short enough for a quick fit


@functools.cache
def _data() -> tuple[float, np.ndarray, np.ndarray]:
    rec = simulate_experiment("noise", 1)
    s = rec.sensor[:N_FIT] - rec.sensor[:N_FIT].mean()
    p = rec.position[:N_FIT] - rec.position[:N_FIT].mean()
    return rec.dt, s / np.max(np.abs(s)), p / np.max(np.abs(p))


@functools.cache
def _example(name: str, factor: int = 1):
    """A fitted (structure, params) of the family at ``factor`` times its default size (a
    second size catches a kernel that only works for one cell, one operator, ...)."""
    family = get_family(name)
    dt, s, p = _data()
    structure = family.make_structure(dt, factor * family.default_size)
    return structure, family.fit(s, p, structure).params, s


def _probe(n: int = 300, seed: int = 0) -> np.ndarray:
    """A smooth random input inside the training range, with reversals."""
    rng = np.random.default_rng(seed)
    return 0.8 * np.sin(np.cumsum(rng.uniform(0.0, 0.15, n)) + 0.3) * np.linspace(1, 0.5, n)


@pytest.mark.parametrize("name", NAMES)
def test_family_declares_the_protocol(name):
    family = get_family(name)
    assert isinstance(family, Family) and family.name == name
    assert family.title and family.size_help and family.default_size >= 1
    assert (family.invert is None) == bool(family.no_inverse_reason)
    assert (family.invert is None) == (family.invert_step is None)


@pytest.mark.parametrize("name", NAMES)
def test_every_size_up_to_max_size_makes_a_valid_structure(name):
    # the CLI offers sizes up to max_size: the structure's own limits must accept all of them
    family = get_family(name)
    assert 1 <= family.default_size <= family.max_size
    for size in (family.default_size, family.max_size):
        family.make_structure(0.025, size)


@pytest.mark.parametrize("name", NAMES)
def test_params_and_structure_round_trip_through_json(name):
    family = get_family(name)
    structure, params, _ = _example(name)
    again = family.Params.from_dict(json.loads(json.dumps(params.to_dict())))
    assert again == params and again == params
    assert family.Structure.from_dict(json.loads(json.dumps(structure.to_dict()))) == structure


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("factor", [1, 2])
def test_split_run_equals_whole_run(name, factor):
    family = get_family(name)
    structure, params, _ = _example(name, factor)
    u = _probe()
    y, x_end = family.simulate(structure, params, u)
    y1, x_mid = family.simulate(structure, params, u[:137])
    y2, x_end2 = family.simulate(structure, params, u[137:], x_mid)
    # bit-identical: the state carries all the memory
    np.testing.assert_array_equal(np.r_[y1, y2], y)
    np.testing.assert_array_equal(x_end2, x_end)
    if family.has_inverse:  # the inverse too (PI converts its state: a few ulps)
        u_hat, xi_end = family.invert(structure, params, y)
        u1, xi_mid = family.invert(structure, params, y[:137])
        u2, xi_end2 = family.invert(structure, params, y[137:], xi_mid)
        assert_allclose(np.r_[u1, u2], u_hat, rtol=0, atol=1e-12)
        assert_allclose(xi_end2, xi_end, rtol=0, atol=1e-12)


def _walk(n: int, seed: int) -> np.ndarray:
    """Reversals of every size, partly beyond [-1, 1] (the straight-line extensions, knees)."""
    rng = np.random.default_rng(seed)
    return 1.2 * np.sin(np.cumsum(rng.standard_normal(n)) * 0.4) * np.linspace(1, 0.3, n)


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("factor", [1, 2])
def test_split_run_equals_whole_run_across_the_documented_domain(name, factor):
    # the fitted example above, and parameters drawn from the domain the family documents,
    # on an input that leaves the training range: the state carries all the memory
    family = get_family(name)
    structure = family.make_structure(0.025, factor * family.default_size)
    rng = np.random.default_rng(factor)
    try:
        draws = [family.random_params(structure, rng) for _ in range(5)]
    except NotImplementedError as exc:
        pytest.skip(str(exc))
    u = _walk(1500, factor)
    for k, params in enumerate(draws):
        y, x_end = family.simulate(structure, params, u)
        y1, x_mid = family.simulate(structure, params, u[:613])
        y2, x_end2 = family.simulate(structure, params, u[613:], x_mid)
        np.testing.assert_array_equal(x_end2, x_end, err_msg=str(k))
        if name in BLAS_READ_OUT:  # a BLAS product sums in an order that depends on length
            assert_allclose(np.r_[y1, y2], y, rtol=4.5e-16, atol=0, err_msg=str(k))
        else:
            np.testing.assert_array_equal(np.r_[y1, y2], y, err_msg=str(k))


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("factor", [1, 2])
def test_compiled_run_equals_the_readable_steps_from_rest(name, factor):
    """Each compiled step, from the readable run's state, equals the readable step. Step by
    step, because over a whole run a model may amplify one rounding of its state: a Bouc-Wen
    fitted with loops sharper than the record resolves turns 1e-16 into 4e-11 within 100
    steps, in either implementation; the whole run then tests its conditioning, not the
    kernel (the split-run test above checks that the compiled state carries the run)."""
    family = get_family(name)
    structure, params, _ = _example(name, factor)
    u = _probe(200, seed=1)
    y, _ = family.simulate(structure, params, u[:1])
    x = family.rest_state(structure, params, float(u[0]))
    for k, u_k in enumerate(u):
        if k:
            y, _ = family.simulate(structure, params, u[k:k + 1], x)
        y_k, x = family.step(structure, params, x, u_k)
        # the same arithmetic; library calls and sums may differ in the last bits (<= 4.4e-16)
        assert y_k == pytest.approx(y[0], abs=1e-14), k


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("inverse", [False, True])
@pytest.mark.parametrize("factor", [1, 2])
def test_loop_block_equals_the_readable_step(name, inverse, factor):
    family = get_family(name)
    if inverse and not family.has_inverse:
        pytest.skip(f"{name} has no inverse: {family.no_inverse_reason}")
    structure, params, _ = _example(name, factor)
    block = family.block(structure, params, inverse)
    step = family.invert_step if inverse else family.step
    u = _probe(250, seed=2)
    if inverse:  # drive the inverse with outputs the model can produce
        u, _ = family.simulate(structure, params, u)
    x = family.rest_state(structure, params, float(u[0]), inverse)
    assert np.size(x) == block.n_state
    off = 3  # the block's slice sits anywhere in the loop state
    state = np.zeros(off + block.n_state + 2)
    state[off:off + block.n_state] = x
    for k, u_k in enumerate(u):
        nxt = state.copy()
        out = block.step(block.body, state, nxt, off, u_k)
        ref, x = step(structure, params, x, u_k)
        assert out == pytest.approx(ref, abs=1e-10), k
        assert_allclose(nxt[off:off + block.n_state], x, rtol=0, atol=1e-10)
        assert_allclose(np.r_[nxt[:off], nxt[off + block.n_state:]], 0.0)  # nothing else
        state = nxt


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("inverse", [False, True])
@pytest.mark.parametrize("factor", [1, 2])
def test_block_looped_gives_the_compiled_run_bit_for_bit(name, inverse, factor, drive):
    """What lets a stream run compiled and give the offline numbers (issue 29.4): the block,
    sample by sample from a run's end state, gives that run's continuation to the bit."""
    family = get_family(name)
    if inverse and not family.has_inverse:
        pytest.skip(f"{name} has no inverse: {family.no_inverse_reason}")
    structure, params, _ = _example(name, factor)
    run = family.invert if inverse else family.simulate
    u = _probe(400, seed=5)
    signal = family.simulate(structure, params, u)[0] if inverse else u
    _, x0 = run(structure, params, signal[:10])
    want, want_end = run(structure, params, signal[10:], x0)
    got, states = drive(family.block(structure, params, inverse), x0, signal[10:], off=0)
    np.testing.assert_array_equal(got, want)
    np.testing.assert_array_equal(states[-1], want_end)


@pytest.mark.parametrize("name", NAMES)
def test_rest_state_is_a_fixed_point(name):
    family = get_family(name)
    structure, params, _ = _example(name)
    for value in (-0.5, 0.0, 0.7):
        x = family.rest_state(structure, params, value)
        _, x_next = family.step(structure, params, x, value)
        assert_allclose(x_next, x, rtol=0, atol=1e-9)


@pytest.mark.parametrize("name", NAMES)
def test_inverse_undoes_the_model(name):
    family = get_family(name)
    if not family.has_inverse:
        pytest.skip(f"{name} has no inverse: {family.no_inverse_reason}")
    structure, params, _ = _example(name)
    u = _probe(300, seed=3)
    y, _ = family.simulate(structure, params, u)
    u_hat, _ = family.invert(structure, params, y)
    assert_allclose(u_hat, u, rtol=0, atol=1e-6)


@pytest.mark.parametrize("name", NAMES)
def test_at_keeps_the_model_at_its_own_step_and_round_trips(name):
    family = get_family(name)
    structure, params, _ = _example(name)
    assert family.at(structure, structure.dt) == structure
    try:
        finer = family.at(structure, structure.dt / 8)
    except ValueError as exc:  # a clear refusal is allowed, with the reason
        assert str(exc)
        return
    assert finer.dt == pytest.approx(structure.dt / 8)
    assert family.at(finer, structure.dt) == structure
    y, _ = family.simulate(finer, params, np.repeat(_probe(100, seed=4), 8))
    assert np.all(np.isfinite(y))


def _one_sided(step, x, u, sign, h=1e-6):
    """``(A, B, C, D)`` by one-sided differences in direction ``sign`` (+1 or -1)."""
    x = np.asarray(x, dtype=float)
    y0, x0n = step(x, u)
    cols_a, cols_c = [], []
    for k in range(x.size):
        xp = x.copy()
        xp[k] += sign * h
        yp, xpn = step(xp, u)
        cols_a.append((np.asarray(xpn) - x0n) / (sign * h))
        cols_c.append((yp - y0) / (sign * h))
    yp, xpn = step(x, u + sign * h)
    return (np.array(cols_a).T.reshape(x.size, x.size), (np.asarray(xpn) - x0n) / (sign * h),
            np.array(cols_c), (yp - y0) / (sign * h))


def _close(a, b) -> bool:
    return bool(np.allclose(np.asarray(a, float), np.asarray(b, float), rtol=1e-4, atol=1e-6))


def _columns(lin):
    """The derivative w.r.t. each state coordinate and the input: ``[A; C]`` columns, then
    ``[B; D]``."""
    a, b, c, d = (np.asarray(v, dtype=float) for v in lin)
    return [np.r_[a[:, k], c[k]] for k in range(c.size)] + [np.r_[b, d]]


def _kinked_match(got, right, left) -> bool:
    """On a kink, each entry of the derivative lies between its left and right one-sided
    differences (a generalised derivative: either side, the mean, or a sticking element's
    own choice)."""
    for g, r, le in zip(_columns(got), _columns(right), _columns(left), strict=True):
        lo, hi = np.minimum(r, le), np.maximum(r, le)
        slack = 1e-6 + 1e-4 * np.abs(hi)
        if not np.all((g >= lo - slack) & (g <= hi + slack)):
            return False
    return True


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("inverse", [False, True])
def test_linearisation_matches_the_numerical_one(name, inverse):
    """Where the step is smooth, ``linearise`` equals central differences; on a kink (a play
    or relay switching, a resistor knee, a sticking piston) it must lie between the one-sided
    derivatives."""
    family = get_family(name)
    if inverse and not family.has_inverse:
        pytest.skip(f"{name} has no inverse: {family.no_inverse_reason}")
    if name in STAIRCASES:
        pytest.skip("a staircase state is not a vector to differentiate (its first entry is "
                    "fixed at -1, its length is a count); tests/models/preisach checks the "
                    "one-sided branch slope instead")
    structure, params, _ = _example(name)
    step = family.invert_step if inverse else family.step
    run = lambda xx, uu: step(structure, params, xx, uu)
    u = _probe(120, seed=5)
    if inverse:
        u, _ = family.simulate(structure, params, u)
    x = family.rest_state(structure, params, float(u[0]), inverse)
    n_smooth = 0
    for k, u_k in enumerate(u):
        if k % 20 == 19:
            got = family.linearise(structure, params, x, u_k, inverse)
            right, left = _one_sided(run, x, u_k, +1), _one_sided(run, x, u_k, -1)
            central = numerical_linearisation(run, x, u_k)
            if all(_close(r, le) for r, le in zip(right, left, strict=True)):
                n_smooth += 1
                assert all(_close(g, c) for g, c in zip(got, central, strict=True)), k
            else:
                assert _kinked_match(got, right, left), k
        _, x = run(x, u_k)
    assert n_smooth > 0


def _bounded_probe(dt: float, n: int = 2000) -> np.ndarray:
    """|u| <= 1: a sine sweep, steps to the extremes and back, reversals."""
    t = np.arange(n) * dt
    u = 0.9 * np.sin(2 * np.pi * (0.05 + 0.5 * t / t[-1]) * t)
    u[n // 2:n // 2 + 100] = 1.0
    u[n // 2 + 100:n // 2 + 200] = -1.0
    return u


@pytest.mark.parametrize("name", NAMES)
def test_random_parameters_are_reproducible_and_accepted(name):
    family = get_family(name)
    structure = family.make_structure(0.025, family.default_size)
    try:
        first = family.random_params(structure, np.random.default_rng(7))
    except NotImplementedError as exc:
        pytest.skip(str(exc))
    assert family.random_params(structure, np.random.default_rng(7)) == first  # seeded
    assert family.random_params(structure, np.random.default_rng(8)) != first
    rng = np.random.default_rng(3)
    for _ in range(20):
        p = family.random_params(structure, rng)
        assert family.Params.from_dict(json.loads(json.dumps(p.to_dict()))) == p


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("factor", [1, 2])
def test_random_parameters_give_bounded_output(name, factor):
    """Parameters drawn from the family's documented domain (``random_params``) keep the
    output finite and far from a blow-up for any input in [-1, 1]. The family's own tests check
    its tighter, model-specific bound (tests/models/<family>/)."""
    family = get_family(name)
    dt, _, _ = _data()
    structure = family.make_structure(dt, factor * family.default_size)
    rng = np.random.default_rng(2026)
    try:
        params = [family.random_params(structure, rng) for _ in range(25)]
    except NotImplementedError as exc:
        pytest.skip(str(exc))
    u = _bounded_probe(dt)
    for k, p in enumerate(params):
        y, x_end = family.simulate(structure, p, u)
        assert np.all(np.isfinite(y)) and np.all(np.isfinite(x_end)), k
        assert np.max(np.abs(y)) < 1e9, (k, float(np.max(np.abs(y))))


# -- declared capabilities (what generic code reads instead of field names and fit constants) --


def test_all_losses_are_the_identification_losses():
    assert ALL_LOSSES == LOSSES


def test_a_family_that_declares_nothing_fits_the_plain_sse_only():
    plain = Capabilities()
    assert plain.losses == ("linear",) and plain.weight_sum_floor is None
    assert not plain.output_is_linear(None) and not plain.start_from_params
    assert plain.sync_amplitude is None and plain.fit_options == frozenset()


@pytest.mark.parametrize("name", NAMES)
def test_capabilities_agree_with_the_family_and_its_fit(name):
    family = get_family(name)
    caps = family.capabilities
    assert set(caps.losses) <= set(LOSSES) and "linear" in caps.losses
    assert caps.inverse == family.has_inverse
    assert family.fit_options == caps.fit_options
    # the fit module's own constants (read by name until every caller reads the record)
    fit = importlib.import_module(f"{type(family).__module__.rpartition('.')[0]}.fit")
    assert caps.losses == tuple(getattr(fit, "SUPPORTED_LOSSES", LOSSES))
    if caps.weight_sum_floor is not None:
        assert caps.weight_sum_floor == getattr(fit, "WEIGHT_SUM_FLOOR", 0.0)
    structure, params, _ = _example(name)
    if caps.start_from_params:
        assert family.start_options(structure, params).options["init"] == params
    else:
        with pytest.raises(NotImplementedError):
            family.start_options(structure, params)
    if caps.sync_amplitude is not None:
        assert caps.sync_amplitude(structure, params) > 0


def _linear_in_weights(family, structure, params) -> bool:
    """Whether the output is ``sum_k w_k y_k - v_b``, ``y_k`` the run with unit weight k."""
    u = _probe()
    whole = family.simulate(structure, params, u)[0]
    parts = sum(w_k * family.simulate(structure, dataclasses.replace(
        params, w=np.eye(params.w.size)[k], v_b=0.0), u)[0] for k, w_k in enumerate(params.w))
    return bool(np.allclose(parts - params.v_b, whole, rtol=1e-9,
                            atol=1e-9 * np.max(np.abs(whole))))


WEIGHTED = ("ladder", "mpl", "mpl-g", "mpl-poly", "pl")  # families with output weights w, v_b


@pytest.mark.parametrize("name", WEIGHTED)
@pytest.mark.parametrize("factor", [1, 2])
def test_linear_output_is_declared_exactly_where_the_output_is_linear_in_w(name, factor):
    # both directions: mpl, ladder and pl with one output segment declare it and are linear;
    # mpl-g and mpl-poly carry weights w and a bias v_b too, but behind a non-linear output
    # resistor (pl with more segments: the test below)
    family = get_family(name)
    structure, params, _ = _example(name, factor)
    declared = family.capabilities.output_is_linear(structure)
    assert declared == _linear_in_weights(family, structure, params)


def test_pl_output_is_linear_with_one_output_segment_only():
    family = get_family("pl")
    for n_basis, linear in ((1, True), (3, False)):
        structure = family.make_structure(0.025, 2, n_basis=n_basis)
        params = family.random_params(structure, np.random.default_rng(n_basis))
        assert family.capabilities.output_is_linear(structure) is linear
        assert _linear_in_weights(family, structure, params) is linear
