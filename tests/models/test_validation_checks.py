"""The shared argument checks of the model modules refuse hostile values with ValueError."""

from __future__ import annotations

import numpy as np
import pytest

from hystkit.errors import FitDivergedError
from hystkit.models._validation import check_finite_run, check_positive_int


@pytest.mark.parametrize("value", [float("inf"), float("nan"), "abc", None, 0, -3, 2.5, 1e-300])
def test_check_positive_int_refuses_with_value_error(value: object) -> None:
    with pytest.raises(ValueError, match="n must be a positive integer"):
        check_positive_int(value, "n")


@pytest.mark.parametrize("value", [1, 3.0, np.int64(4), 10**6])
def test_check_positive_int_accepts_whole_numbers(value: object) -> None:
    check_positive_int(value, "n")


def test_check_finite_run_names_the_first_bad_sample() -> None:
    y = np.array([0.0, 1.0, np.inf, np.nan])
    with pytest.raises(FitDivergedError, match="pl model's output .* sample 3 of 4"):
        check_finite_run(y, "pl")
    ok = np.array([0.0, 1e300])
    assert check_finite_run(ok, "pl") is ok
