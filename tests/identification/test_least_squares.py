"""fit_multistart: bound hits by name, and bounds that are model limits reported as notes."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from hystkit.compensation._diagnostics import BOUND_TOLERANCE, bound_flags, fit_status
from hystkit.identification import fit_multistart

TARGET = np.array([0.3, 5.0, -4.0])  # the unconstrained optimum of the toy cost


def _fit(**options):
    """Least squares towards TARGET in a box [-1, 1]^3: coordinates 1 and 2 end on a bound."""
    return fit_multistart(lambda th: th - TARGET, [np.zeros(3), np.full(3, 0.5)],
                          (np.full(3, -1.0), np.full(3, 1.0)), lambda th: th.copy(), None,
                          **options)


def test_bound_hits_are_named_with_their_side():
    result = _fit(names=["a", "b", "c"])
    assert_allclose(result.theta, [0.3, 1.0, -1.0], atol=1e-6)
    hits = result.bound_hits(BOUND_TOLERANCE)
    assert [(h.name, h.side, h.limit) for h in hits] == [("b", "upper", None),
                                                         ("c", "lower", None)]
    on_bounds, notes = bound_flags(result)
    assert on_bounds == ["b (upper)", "c (lower)"] and notes == []


def test_without_names_the_coordinate_is_named_by_index():
    assert bound_flags(_fit())[0] == ["theta[1] (upper)", "theta[2] (lower)"]


def test_a_model_limit_is_a_note_not_a_failed_guard():
    limits = ([None, None, None], [None, "b runs at its stability limit", None])
    result = _fit(names=["a", "b", "c"], limits=limits)
    on_bounds, notes = bound_flags(result)
    assert on_bounds == ["c (lower)"]
    assert notes == ["b runs at its stability limit"]
    # a limit on the other side of the same coordinate does not excuse this hit
    other_side = ([None, "b at its floor", None], [None, None, None])
    assert bound_flags(_fit(names=["a", "b", "c"], limits=other_side))[0] == ["b (upper)",
                                                                              "c (lower)"]
    # with every hit a model limit the fit is ok
    both = ([None, None, "c at its floor"], [None, "b at its cap", None])
    on_bounds, notes = bound_flags(_fit(names=["a", "b", "c"], limits=both))
    y = np.sin(np.linspace(0, 20, 400))
    assert on_bounds == [] and notes == ["b at its cap", "c at its floor"]
    assert fit_status(y, y, 0.9 * y, on_bounds, True)[0] == "ok"


def test_a_coordinate_the_output_ignores_is_not_held_by_its_bound():
    """The residual does not depend on theta[2]: the start puts it on a bound, where it stays."""
    result = fit_multistart(lambda th: th[:2] - TARGET[:2], [np.array([0.0, 0.0, 1.0])],
                            (np.full(3, -1.0), np.full(3, 1.0)), lambda th: th.copy(), None,
                            names=["a", "b", "c"])
    on_bounds, notes = bound_flags(result)
    assert on_bounds == ["b (upper)"]
    assert len(notes) == 1 and notes[0].startswith("c does not affect the model output")


def test_names_and_limits_need_one_entry_per_coordinate():
    with pytest.raises(ValueError, match="one entry per coordinate"):
        _fit(names=["a", "b"])
    with pytest.raises(ValueError, match="one entry per coordinate"):
        _fit(limits=([None] * 3, [None] * 2))


def test_an_unknown_solver_is_refused():
    with pytest.raises(ValueError, match="solver must be one of"):
        _fit(solver="newton")


@pytest.mark.parametrize("solver", ["tr", "lm", "trf"])
def test_every_solver_finds_the_box_optimum(solver):
    result = _fit(names=["a", "b", "c"], solver=solver)
    assert result.converged, result.message
    assert_allclose(result.theta, [0.3, 1.0, -1.0], atol=1e-6)
    # cost of the clipped target: (5 - 1)^2 + (-4 + 1)^2 = 25, to the bounds' margin
    assert_allclose(result.cost, 25.0, rtol=1e-6)
    assert_allclose(result.sensitivity, np.ones(3), rtol=1e-6)  # J = I
