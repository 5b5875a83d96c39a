"""The spectral radius behind ``hystkit stability``: a triangular linearisation (a Preisach
staircase's memory is the identity) is read off its diagonal, any other by LAPACK; both are
the largest |eigenvalue|."""

from __future__ import annotations

import numpy as np
import pytest

from hystkit.models._stability import _radius


class _Linearised:
    """A stand-in family whose one step linearises to the matrix given."""

    def __init__(self, a: np.ndarray):
        self.a = a

    def linearise(self, structure, params, x, u, inverse):
        return self.a, None


@pytest.mark.parametrize("shape", ["upper", "lower", "diagonal", "full"])
def test_the_radius_is_the_largest_eigenvalue_modulus(shape):
    rng = np.random.default_rng(7)
    a = rng.normal(size=(12, 12))
    a = {"upper": np.triu(a), "lower": np.tril(a), "diagonal": np.diag(np.diag(a)),
         "full": a}[shape]
    expected = np.max(np.abs(np.linalg.eigvals(a)))
    assert _radius(_Linearised(a), None, None, None, 0.0, False) == pytest.approx(
        expected, rel=1e-12)


def test_a_one_state_and_a_stateless_step():
    assert _radius(_Linearised(np.array([[-0.5]])), None, None, None, 0.0, False) == 0.5
    assert _radius(_Linearised(np.zeros((0, 0))), None, None, None, 0.0, False) == 0.0
