"""References are checked before they move anything (issue 25.6): an implausible one (beyond the
training positions, or too far from the estimate) is rejected and counted, an update that would
leave the output parameters' domain is refused and counted; the stream goes on unharmed."""

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from hystkit.compensation import Compensator, LinearBaseline, Scaling
from hystkit.live import Adaptation, AdaptiveStream, Stream
from hystkit.live._adaptive_records import MAX_INNOVATION, MAX_MULTIPLIER, REFERENCE_MARGIN
from hystkit.live._refit import Refit, RefittingStream
from hystkit.models import FAMILIES

DT = 0.01
N = 1200


def _signal() -> np.ndarray:
    t = np.arange(N) * DT
    return 0.8 * np.sin(2 * np.pi * 0.5 * t) * np.exp(-t / 8)


@pytest.fixture(scope="module")
def comp() -> Compensator:
    """A 1-cell mPL whose stored training positions are those its estimates span."""
    family = FAMILIES["mpl"]
    structure = family.make_structure(DT, 1)
    params = family.random_params(structure, np.random.default_rng(2))
    plain = Compensator(structure, params, "direct", "fit", Scaling(0.0, 1.0, 0.0, 2.0),
                        LinearBaseline(1.0, 0.0), model="mpl")
    p = Stream(plain).process(_signal())
    return Compensator(structure, params, "direct", "fit", Scaling(0.0, 1.0, 0.0, 2.0),
                       LinearBaseline(1.0, 0.0), model="mpl", training_range=(-1.0, 1.0),
                       position_range=(float(p.min()), float(p.max())))


def _references(comp: Compensator) -> np.ndarray:
    """Good references every 20 samples: the plain estimate 5 % larger, shifted 0.02 mm."""
    plain = Stream(comp).process(_signal())
    return np.where(np.arange(N) % 20 == 7, 1.05 * plain + 0.02, np.nan)


@pytest.mark.parametrize("parameters", ["gain", "weights"])
@pytest.mark.parametrize("absurd", [1e20, 1e200, -1e200])
def test_an_absurd_reference_moves_nothing(comp, parameters, absurd):
    """Before: a reference of 1e20 set the gain to 2.7e17 for good, one of 1e200 raised an
    OverflowError. Now the stream is the one without that reference, bit for bit."""
    good = _references(comp)
    bad = good.copy()
    bad[27] = absurd
    skipped = good.copy()
    skipped[27] = np.nan
    stream = AdaptiveStream(comp, Adaptation(parameters))
    got = stream.process(_signal(), bad)
    want = AdaptiveStream(comp, Adaptation(parameters)).process(_signal(), skipped)
    assert_array_equal(got, want)
    assert (stream.n_rejected, stream.n_refused) == (1, 0)
    assert stream.state.rls.n_updates == np.isfinite(good).sum() - 1
    # one by one, the same (the gain's fast step path checks too)
    one = AdaptiveStream(comp, Adaptation(parameters))
    assert_array_equal([one.step(s, r) for s, r in zip(_signal(), bad, strict=True)], got)
    assert one.n_rejected == 1


def test_the_range_and_innovation_gates(comp):
    lo, hi = comp.position_range
    extent = hi - lo
    stream = AdaptiveStream(comp)
    sensor = _signal()[0]
    estimate = Stream(comp).step(sensor)
    # in the widened range but further from the estimate than MAX_INNOVATION extents
    far = [r for r in (estimate - 1.01 * MAX_INNOVATION * extent,
                       estimate + 1.01 * MAX_INNOVATION * extent)
           if lo - REFERENCE_MARGIN * extent <= r <= hi + REFERENCE_MARGIN * extent]
    assert far
    stream.step(sensor, far[0])
    assert stream.n_rejected == 1
    # beyond the range widened by REFERENCE_MARGIN extents (close to the estimate: the first
    # estimate of a stream at rest can lie anywhere)
    stream.step(sensor, hi + 1.01 * REFERENCE_MARGIN * extent)
    assert stream.n_rejected == 2
    assert stream.parameters == {"gain": 1.0, "offset_mm": 0.0}  # nothing moved
    stream.step(sensor, estimate + 0.05 * extent)  # a plausible one is learnt
    assert stream.state.rls.n_updates == 1 and stream.n_rejected == 2


def test_an_update_leaving_the_domain_is_refused(comp):
    """A vague prior on the gain and a firm one on the offset: one plausible reference on the
    other side of zero from the estimate asks for a negative gain. That update is refused;
    the parameters stay."""
    lo, hi = comp.position_range
    extent = hi - lo
    estimate = Stream(comp).step(_signal()[0])
    assert abs(estimate) < 0.9 * extent
    reference = estimate - np.sign(estimate) * 0.9 * extent  # gain reference / estimate < 0
    stream = AdaptiveStream(comp, Adaptation("gain", 1.0, prior_gain=1e4, prior_offset=1e-6))
    stream.step(_signal()[0], reference)
    assert (stream.n_rejected, stream.n_refused) == (0, 1)
    assert stream.parameters == {"gain": 1.0, "offset_mm": 0.0}
    # the same with a gain MAX_MULTIPLIER allows is learnt
    stream.step(_signal()[0], 0.9 * estimate)
    assert stream.state.rls.n_updates == 1
    assert 1.0 / MAX_MULTIPLIER <= stream.parameters["gain"] <= MAX_MULTIPLIER


def test_full_adaptation_rejects_absurd_references(comp):
    """Before: a reference of 1e200 reached the window's fit and ended the stream with an
    OverflowError. Now it is rejected and counted; the refits run on the good ones."""
    reference = _references(comp)
    reference[27] = 1e200
    reference[67] = -1e20
    refit = Refit(window_seconds=6.0, every=20, max_nfev=5)
    stream = RefittingStream(comp, refit)
    out = stream.process(_signal(), reference)
    lo, hi = comp.position_range
    assert np.all(np.isfinite(out)) and np.all((out > 2 * lo - hi) & (out < 2 * hi - lo))
    report = stream.report
    assert (report.references, report.rejected) == (np.isfinite(reference).sum(), 2)
    assert stream.n_rejected == 2
    assert report.kept + report.refused + report.skipped == report.references // refit.every
