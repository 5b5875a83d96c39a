"""The chunked standard errors (R factor by TSQR) against the dense SVD route they replace."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from hystkit.compensation._chunked_errors import chunked_standard_errors
from hystkit.compensation._diagnostics import fixed_mask, standard_errors
from hystkit.compensation._param_vector import simulate_segments
from hystkit.models import get_family


def _problem(model: str, size: int, n: int, seed: int):
    """A model's own output plus noise on a two-tone input: the SEs are those of a fit."""
    family = get_family(model)
    structure = family.make_structure(0.025, size)
    params = family.random_params(structure, np.random.default_rng(seed))
    t = np.arange(n) * 0.025
    inputs = [0.8 * np.sin(2 * np.pi * 0.3 * t) * np.cos(2 * np.pi * 0.05 * t),
              0.6 * np.sin(2 * np.pi * 0.7 * t[: n // 2])]
    rng = np.random.default_rng(seed + 1)
    targets = [family.simulate(structure, params, u)[0] + 1e-3 * rng.standard_normal(u.size)
               for u in inputs]
    return family, structure, params, inputs, targets


def _dense(family, structure, params, inputs, targets) -> dict:
    target = np.concatenate(targets)
    return standard_errors(
        lambda q: simulate_segments(family.simulate, structure, q, inputs) - target,
        params, target.size, fixed_mask(family, structure, params))


@pytest.mark.parametrize(("model", "size"), [("mpl", 2), ("bobbio", 3), ("ladder", 2), ("preisach", 4)])
@pytest.mark.parametrize("chunk", [97, 1000, 100_000])
def test_chunked_equals_dense(model: str, size: int, chunk: int) -> None:
    problem = _problem(model, size, 3000, seed=3)
    dense = _dense(*problem)
    chunked = chunked_standard_errors(*problem, chunk=chunk)
    assert chunked["values"] == dense["values"]
    assert [s is None for s in chunked["standard_errors"]] == \
        [s is None for s in dense["standard_errors"]]
    finite = [i for i, s in enumerate(dense["standard_errors"]) if s is not None]
    assert finite, "the test problem determines no parameter"
    # Same Jacobian rows; R and J share singular values up to ~cond * eps
    assert_allclose([chunked["standard_errors"][i] for i in finite],
                    [dense["standard_errors"][i] for i in finite], rtol=1e-8)
    assert_allclose(chunked["condition_number"], dense["condition_number"], rtol=1e-6)


@pytest.mark.parametrize(("model", "size"), [("pi", 4), ("chua", 2), ("mpl-poly", 2)])
def test_unidentifiable_parameters_are_reported_by_both_routes(model: str, size: int) -> None:
    # Random draws of these families leave some parameters undetermined by the data (dead
    # play operators, saturated cells): both routes must name the same ones.
    problem = _problem(model, size, 2000, seed=3)
    blind_dense = [s is None for s in _dense(*problem)["standard_errors"]]
    chunked = chunked_standard_errors(*problem, chunk=333)
    assert any(blind_dense)
    assert [s is None for s in chunked["standard_errors"]] == blind_dense
