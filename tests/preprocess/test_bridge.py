"""Half-bridge readout (eq. 4.2-4.5, table 3.1): formulas, golden values, the fused kernel."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from hystkit.preprocess import (
    bridge_kernel,
    bridge_resistance,
    bridge_voltage,
    clipped_channels,
    first_invalid_bridge_sample,
    gauge_symmetry,
    relative_change,
)


@pytest.mark.parametrize("r_bridge, v_supply, r_s, v_m", [
    # sec. 4.3.1 set-up (10 kOhm, 2 V) with paper 9.1's top gauge, 22.4 kOhm: 2 * 10 / 32.4
    (10e3, 2.0, 22.4e3, 2.0 * 10.0 / 32.4),
    # sec. 4.3.2 set-up (560 Ohm, 1 V) with a settled 15.7 kOhm bottom gauge
    (560.0, 1.0, 15.7e3, 560.0 / 16260.0),
    (1.0, 1.0, 1.0, 0.5),  # equal arms halve the supply
])
def test_bridge_golden_values(r_bridge, v_supply, r_s, v_m):
    assert bridge_voltage(r_s, r_bridge, v_supply) == pytest.approx(v_m, rel=1e-15)  # eq. 4.2
    assert bridge_resistance(v_m, r_bridge, v_supply) == pytest.approx(r_s, rel=1e-12)  # eq. 4.3


@settings(max_examples=50, deadline=None)
@given(r_s=st.floats(1.0, 1e7), r_bridge=st.floats(1.0, 1e6), v_supply=st.floats(0.1, 10.0))
def test_eq_4_3_inverts_eq_4_2(r_s, r_bridge, v_supply):
    v_m = bridge_voltage(r_s, r_bridge, v_supply)
    assert 0 < v_m < v_supply
    # relative error grows with R_S / R_br through V0 / V_m - 1; 1e-9 covers ratios up to 1e7
    assert_allclose(bridge_resistance(v_m, r_bridge, v_supply), r_s, rtol=1e-9)


def test_invalid_bridge_voltages_are_found():
    v = np.array([0.5, 0.7, 1.0, 0.2])
    assert first_invalid_bridge_sample(v, 2.0) == -1
    assert first_invalid_bridge_sample(v, 1.0) == 2  # V_m = V0: R_S = 0 is not a gauge
    assert first_invalid_bridge_sample(np.array([0.3, 0.0]), 1.0) == 1  # V_m = 0: R_S infinite
    assert first_invalid_bridge_sample(np.array([-0.1, 0.3]), 1.0) == 0


def test_relative_change_is_eq_4_5():
    r = np.array([90.0, 100.0, 110.0, 100.0])
    assert_allclose(relative_change(r), [-0.1, 0.0, 0.1, 0.0], atol=1e-15)
    rows = np.vstack([r, 2 * r])  # per row, scale-free
    assert_allclose(relative_change(rows), np.vstack([relative_change(r)] * 2), atol=1e-15)


def test_gauge_symmetry_of_paper_9_1_sensor():
    # 22.4 and 15.7 kOhm (paper 9.1): 2 * 6.7 / 38.1
    assert gauge_symmetry(22.4e3, 15.7e3) == pytest.approx(2 * 6.7 / 38.1, rel=1e-12)
    assert gauge_symmetry(np.full(3, 5.0), np.full(3, 5.0)) == 0.0


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_fused_kernel_matches_the_formula_and_counts_extremes(dtype):
    rng = np.random.default_rng(0)
    v1 = (0.6 + 0.01 * rng.standard_normal(10_000)).astype(dtype)
    v2 = np.minimum(0.5 + 0.02 * rng.standard_normal(10_000), 0.51).astype(dtype)  # clipped
    ext = np.array([-np.inf, 0, np.inf, 0] * 2)
    r, bad, ext = bridge_kernel(v1, v2, 1e4, 2.0, ext)
    assert bad.tolist() == [-1, -1]
    for row, v in zip(r, (v1, v2)):
        assert_allclose(row, bridge_resistance(v.astype(float), 1e4, 2.0), rtol=1e-14)
    n_clipped = int(np.count_nonzero(v2 == v2.max()))
    assert n_clipped > 2000  # a third of the samples sit on the 0.51 V limit
    assert clipped_channels(ext, v1.size) == {"v2_max": (n_clipped, float(v2.max()))}
    # split in two, the statistics carry over
    ext2 = np.array([-np.inf, 0, np.inf, 0] * 2)
    for part in (slice(0, 3333), slice(3333, None)):
        _, _, ext2 = bridge_kernel(v1[part], v2[part], 1e4, 2.0, ext2)
    assert_allclose(ext2, ext)


def test_fused_kernel_reports_the_first_invalid_sample_per_channel():
    v1 = np.array([0.5, 0.5, 2.0, -1.0])
    v2 = np.array([0.5, -0.1, 0.5, 0.5])
    _, bad, _ = bridge_kernel(v1, v2, 1e4, 2.0, np.array([-np.inf, 0, np.inf, 0] * 2))
    assert bad.tolist() == [2, 1]
