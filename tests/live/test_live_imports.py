"""hystkit.live reads compensation only through its public names: the band's per-sample pieces
and the runaway guard that the stream's compiled kernel shares are exported by
``hystkit.compensation`` (issue 28), not taken from its private modules."""

from pathlib import Path

import pytest

import hystkit.compensation
import hystkit.live
from tests.cli.test_public_imports import _private_imports_across_packages

LIVE = sorted(Path(hystkit.live.__file__).parent.glob("*.py"))


@pytest.mark.parametrize("path", LIVE, ids=lambda p: p.name)
def test_live_imports_no_private_module_of_another_package(path):
    assert _private_imports_across_packages(path) == []


def test_the_shared_band_and_guard_are_public_and_the_same_objects():
    from hystkit.compensation import _band, _runaway

    for name in ("band_features", "feature_decay", "feature_range", "feature_step",
                 "half_width", "position_width"):
        assert name in hystkit.compensation.__all__
        assert getattr(hystkit.compensation, name) is getattr(_band, name)
    for name in ("MAX_NORMALISED", "runaway_kind", "runaway_samples"):
        assert getattr(hystkit.compensation, name) is getattr(_runaway, name)
