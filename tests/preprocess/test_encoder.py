"""Encoder decoding (sec. 4.2.1, 4.3.1): levels, debounce, quadrature state machine."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_array_equal

from hystkit.preprocess import (
    EncoderSettings,
    LevelSurvey,
    ab_to_code,
    code_to_ab,
    count_to_code,
    decode,
    decode_flush,
    decode_reference,
    decode_step,
    encoder_init,
    parse_states,
)
from hystkit.sensors import ScopeSettings, merged_levels

LEVELS = merged_levels(ScopeSettings())  # 1 kOhm / 2 kOhm divider: about 0.1, 1.7, 3.2, 4.8 V


def _merged(counts: np.ndarray, noise: float = 0.0, seed: int = 0) -> np.ndarray:
    """Ideal merged signal [V] of an encoder at `counts`, plus white noise."""
    x = LEVELS[count_to_code(counts)]
    return x + noise * np.random.default_rng(seed).standard_normal(x.size)


def _walk(n_steps: int, hold: int, seed: int = 0) -> np.ndarray:
    """Counts of a random walk of +-1 steps, each position held `hold` samples."""
    steps = np.random.default_rng(seed).choice([-1, 1], n_steps)
    return np.repeat(np.concatenate([[0], np.cumsum(steps)]), hold)


def test_a_leading_b_counts_up():
    # A leads B by a quarter period: (A, B) = 00, 10, 11, 01, 00, ... is positive motion.
    a = np.tile(np.repeat([0, 1, 1, 0], 10), 5)
    b = np.tile(np.repeat([0, 0, 1, 1], 10), 5)
    counts, state = decode(ab_to_code(a, b, 0.5, 0.5), np.arange(4.0),
                           EncoderSettings(states=(0, 1, 2, 3), track_block=0))
    assert counts[-1] == 19 and state.n_illegal == 0
    assert np.all(np.diff(counts) >= 0)
    back, _ = decode(ab_to_code(a[::-1], b[::-1], 0.5, 0.5), np.arange(4.0),
                     EncoderSettings(states=(0, 1, 2, 3), track_block=0))
    assert back[-1] == -19
    assert_array_equal(code_to_ab(count_to_code(np.arange(4))), ([0, 1, 1, 0], [0, 0, 1, 1]))


def test_default_level_order_is_the_divider_order():
    # A through 1 kOhm weighs twice B through 2 kOhm: 00 < 01 < 10 < 11.
    assert np.all(np.diff(LEVELS) > 0)
    assert parse_states("00,01,10,11") == (0, 1, 2, 3)
    assert parse_states(["11", "10", "01", "00"]) == (3, 2, 1, 0)
    for bad in ("00,01,10", "00,01,10,10", "00,01,10,12"):
        with pytest.raises(ValueError, match="encoder states"):
            parse_states(bad)


def test_clean_walk_is_decoded_exactly():
    truth = _walk(2000, hold=7)
    counts, state = decode(_merged(truth, noise=0.05), LEVELS)
    assert_array_equal(counts, truth)
    assert (state.n_illegal, state.n_rejected) == (0, 0)
    assert state.n_edges == np.count_nonzero(np.diff(truth))


def test_sample_caught_mid_edge_is_not_a_double_transition():
    # 01 -> 11 on the merged signal passes the 10 level: one sample there is mid-edge.
    x = np.concatenate([np.full(10, LEVELS[1]), [LEVELS[2]], np.full(10, LEVELS[3])])
    counts, state = decode(x, LEVELS)
    assert (state.n_illegal, state.n_edges) == (0, 1)
    assert counts[-1] == -1  # 01 -> 11 is a backward step (phase 3 -> 2)
    assert counts[10] == 0  # the mid-edge sample keeps the old count
    wrong, naive = decode(x, LEVELS, EncoderSettings(dwell=1))  # no debounce:
    assert naive.n_illegal == 1 and wrong[-1] == 1  # 01 -> 10 illegal, 10 -> 11 forward


def test_missed_state_is_counted_and_policy_applied():
    # 00 -> 10 -> (11 missed) -> 01: the last step changes A and B at once.
    x = np.concatenate([np.full(20, LEVELS[0]), np.full(20, LEVELS[2]), np.full(20, LEVELS[1])])
    counts, state = decode(x, LEVELS)
    assert (state.n_illegal, state.first_illegal) == (1, 40 + 4 - 1)  # confirmed after dwell 4
    assert counts[-1] == 3  # +1, then +2 in the direction of travel: the missed state counted
    held, state = decode(x, LEVELS, EncoderSettings(illegal="hold"))
    assert held[-1] == 1 and state.n_illegal == 1


def test_short_spikes_are_rejected_and_counted():
    truth = np.zeros(200, dtype=int)
    x = _merged(truth)
    x[[50, 120, 121]] = LEVELS[3]  # one 1-sample and one 2-sample spike (dwell 4)
    counts, state = decode(x, LEVELS)
    assert_array_equal(counts, truth)
    assert (state.n_rejected, state.n_edges) == (2, 0)


def test_level_tracking_follows_a_drifting_supply():
    truth = _walk(4000, hold=50, seed=3)
    scale = np.linspace(1.0, 1.25, truth.size)  # logic supply drifts up 25 %
    x = LEVELS[count_to_code(truth)] * scale
    counts, state = decode(x, LEVELS, EncoderSettings(track_block=4096))
    assert_array_equal(counts, truth)
    np.testing.assert_allclose(state.levels, LEVELS * 1.25, rtol=0.01)
    _, fixed = decode(x, LEVELS, EncoderSettings(track_block=0))
    assert fixed.n_illegal > 0  # without tracking the top levels are misread


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10_000), noise=st.floats(0.0, 0.5), dwell=st.integers(1, 6),
       policy=st.sampled_from(["continue", "hold"]))
def test_kernel_agrees_with_reference(seed, noise, dwell, policy):
    """Random walks with fast steps (some shorter than the dwell), noise and spikes."""
    rng = np.random.default_rng(seed)
    truth = np.repeat(np.cumsum(rng.choice([-1, 0, 1], 300)), rng.integers(1, 9, 300))
    x = _merged(truth, noise, seed)
    x[rng.integers(0, x.size, 10)] = rng.choice(LEVELS, 10)
    cfg = EncoderSettings(dwell=dwell, illegal=policy, track_block=0)
    counts, state = decode(x, LEVELS, cfg)
    ref, report = decode_reference(x, LEVELS, cfg)
    assert_array_equal(counts, ref)
    assert report == {"n_edges": state.n_edges, "n_illegal": state.n_illegal,
                      "n_rejected": state.n_rejected, "first_illegal": state.first_illegal}


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10_000), cuts=st.lists(st.integers(0, 3000), max_size=6))
def test_split_run_equals_whole_run(seed, cuts):
    rng = np.random.default_rng(seed)
    truth = np.repeat(np.cumsum(rng.choice([-1, 0, 1], 400)), rng.integers(1, 12, 400))
    x = _merged(truth, 0.3, seed) * np.linspace(1, 1.1, truth.size)
    cfg = EncoderSettings(dwell=3, track_block=97)  # level updates fall inside pieces too
    whole, end = decode(x, LEVELS, cfg)
    state, parts = encoder_init(LEVELS), []
    for piece in np.split(x, sorted(set(cuts))):
        pending = state.n_pending
        counts, state = decode_step(cfg, state, piece)
        assert counts.size == pending + piece.size - state.n_pending  # emitted in order
        parts.append(counts)
    parts.append(decode_flush(state))
    assert_array_equal(np.concatenate(parts), whole)
    assert_array_equal(state.levels, end.levels)
    assert (state.n_edges, state.n_illegal, state.n_rejected) == (
        end.n_edges, end.n_illegal, end.n_rejected)


def test_level_survey_finds_four_levels_and_a_flat_channel():
    truth = _walk(3000, hold=20, seed=1)
    x = _merged(truth, noise=0.03)
    # 1 % stray samples anywhere (edges, spikes) make no level
    x[::97] = np.random.default_rng(2).uniform(0, 5, x[::97].size)
    survey = LevelSurvey().add(x[:20000]).add(x[20000:])
    assert survey.n_levels == 4
    np.testing.assert_allclose(survey.centres, LEVELS, atol=0.01)
    flat = LevelSurvey().add(1.2 + 0.01 * np.random.default_rng(0).standard_normal(10_000))
    assert flat.n_levels == 1
