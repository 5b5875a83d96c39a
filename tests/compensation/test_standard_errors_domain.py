"""Standard errors near the edge of a family's domain: a step that would leave it is taken
the other way, never an internal error (found on the MR damper's 0.75 A sines with PI: two
dead-zone thresholds 4e-7 apart, a forward step swapped their order)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from hystkit.compensation import fit_compensator
from hystkit.compensation._chunked_errors import chunked_standard_errors
from hystkit.compensation._diagnostics import error_steps, step_within_domain
from hystkit.compensation._param_vector import flatten_params
from hystkit.sensors import simulate_experiment


@pytest.fixture(scope="module")
def crowded():
    """A PI fit whose two top dead-zone thresholds are moved 1e-7 apart."""
    rec = simulate_experiment("noise", 1)
    comp = fit_compensator(rec, model="pi", diagnose=False)
    d_s = np.array(comp.params.d_s, dtype=float)
    d_s[-1] = d_s[-2] + 1e-7
    return comp, replace(comp.params, d_s=d_s), rec


def test_a_forward_step_out_of_the_domain_is_taken_backwards(crowded):
    _, params, _ = crowded
    theta, rebuild = flatten_params(params)
    j = int(np.flatnonzero(theta == params.d_s[-2])[0])  # the lower of the two thresholds
    h = error_steps(theta)[j]
    assert h > 1e-7  # the forward step passes the upper threshold
    with pytest.raises(ValueError):
        rebuild(theta + h * np.eye(theta.size)[j])
    moved, step = step_within_domain(rebuild, theta, np.eye(theta.size)[j], h)
    assert step == -h and moved.d_s[-2] == pytest.approx(params.d_s[-2] - h)


def test_standard_errors_of_crowded_thresholds_are_computed(crowded):
    """One entry per parameter, as for the thresholds apart (a PI's are mostly undetermined
    either way: its condition number is ~1e21); before: ValueError from the family."""
    comp, params, rec = crowded
    s = comp.normalised_sensor(rec.sensor)
    p = (rec.position - comp.scaling.position_offset) / comp.scaling.position_scale
    apart = chunked_standard_errors(comp.family, comp.structure, comp.params, [s], [p])
    errors = chunked_standard_errors(comp.family, comp.structure, params, [s], [p])
    assert len(errors["standard_errors"]) == len(apart["standard_errors"]) == \
        flatten_params(params)[0].size
