"""The mpl-poly run kernel fuses a * b + c (numba's fastmath "contract", issue 29 item 2): its
outputs stay within 1e-12 relative of the readable reference, which rounds every product and
sum, on the paper's steep two-cell model and on the family's random parameter sets."""

import numpy as np

from hystkit.models import get_family
from hystkit.models import mpl_poly as mp

FAMILY = get_family("mpl-poly")
DT = 0.025
REL = 1e-12  # issue 29: fastmath only where results stay within 1e-12 relative


def _input(n: int = 4000) -> np.ndarray:
    t = np.arange(n) * DT
    noise = np.random.default_rng(2).standard_normal(n)
    return np.sin(np.pi * t) * np.exp(-t / 80) + 0.3 * np.sin(2.3 * t) + 0.05 * noise


def _relative_gap(structure, params, u) -> tuple[float, float]:
    y, x_end = mp.simulate(structure, params, u)
    y_ref, x_ref = mp.simulate_reference(structure, params, u)
    scale = max(float(np.max(np.abs(y_ref))), 1e-300)
    state_scale = max(float(np.max(np.abs(x_ref))), 1e-300)
    return (float(np.max(np.abs(y - y_ref))) / scale,
            float(np.max(np.abs(x_end - x_ref))) / state_scale)


def test_steep_cells_on_both_branches_stay_within_1e_12():
    structure = mp.MplPolyStructure(n_cells=2, dt=DT)
    # cell 2 is steep (knees at about +-0.2): the run crosses its straight continuations
    params = mp.MplPolyParams(f=[[0.05, 1.5, 0.4, 2.0], [-0.1, 8.0, 1.0, 300.0]],
                              g=[0.02, 0.9, 0.05, 0.1], w=[1.2, -0.4, -0.3], v_b=0.03)
    u = _input()
    x = u[0] - mp.rest_voltages(structure, params)
    knees, beyond = mp.knee_points(structure, params), 0
    for u_n in u:
        v = u_n - x
        beyond += int(np.any((v >= knees[:, 1]) | (v <= knees[:, 0])))
        x = mp.step(structure, params, x, u_n)[1]
    assert beyond > 0 and beyond < u.size  # both the cubic and the straight line are used
    gap_y, gap_x = _relative_gap(structure, params, u)
    assert gap_y <= REL and gap_x <= REL


def test_random_params_stay_within_1e_12(random_draws, bounded_input):
    structure = mp.MplPolyStructure(n_cells=2, dt=DT)  # limited: random cubics stay bounded
    gaps = [_relative_gap(structure, p, bounded_input)
            for p in random_draws(FAMILY, structure, n=20, seed=7)]
    worst = np.max(gaps, axis=0)
    assert worst[0] <= REL and worst[1] <= REL
