"""The Bode figure's title says what ``hystkit control`` says of the closed loop: a mode growing
more slowly than a slow cell decays is marginal, a faster one UNSTABLE."""

from __future__ import annotations

import numpy as np
import pytest

from hystkit.control import LoopMargins
from hystkit.control._plots import plot_bode


def _margins(**fields) -> LoopMargins:
    return LoopMargins(crossover_hz=2.0, phase_margin_deg=40.0, gain_margin_db=8.0,
                       phase_crossover_hz=9.0, **fields)


@pytest.mark.parametrize(("fields", "expected", "absent"), [
    ({"closed_loop_stable": True, "max_pole_radius": 0.99}, "gain margin 8.0 dB", "closed loop"),
    ({"closed_loop_stable": False, "max_pole_radius": 1 + 6.2e-10, "growth_time_s": 8.1e5,
      "slow_cell": "compensator", "slow_cell_s": 1e4},
     "closed loop marginal, from a slow cell of the compensator: e-fold in 8.1e+05 s",
     "UNSTABLE"),
    ({"closed_loop_stable": False, "max_pole_radius": 1.02, "growth_time_s": 25.0},
     "closed loop UNSTABLE: e-fold growth in 25 s", "marginal"),
])
def test_the_title_names_the_loop_as_control_does(fields, expected, absent):
    f = np.logspace(-1, 1, 5)
    fig = plot_bode(f, np.zeros(5), -90 * np.ones(5), _margins(**fields))
    title = fig.axes[0].get_title()
    assert expected in title
    assert absent not in title
