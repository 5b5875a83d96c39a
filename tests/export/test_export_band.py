"""The exported prediction band (issue 26.3): C (gcc) and MATLAB (Octave) give, per sample,
the lower and upper bound of ``Compensator.estimate_with_band``, its features (rate running
mean, remembered range excursion) carried in the exported state.

Tolerance (issue 26): 1e-6 of the training position range, double C and MATLAB, on a
recording that leaves the training range (the excursion term) and is driven faster than any
training rate (the rate term). A float build's estimate has its own tolerance
(test_export_c.py); its band's half-width is held to the same 1e-6 of the range.
"""

from __future__ import annotations

import subprocess
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from hystkit.compensation import fit_compensator, with_band
from hystkit.compensation._band import band_features
from hystkit.errors import InputError
from hystkit.export import c_files, export_compensator, make_plan, matlab_files
from hystkit.live._stream import Stream

from .export_support import compile_c, need

# (label, family, size, mode, centring): mpl and pi, direct and inverse (the mpl inverse fitted
# on the sine diverges on the noise recording, so the inverse is pi's), every causal centring.
BAND_CASES = [("mpl1", "mpl", 1, "direct", "fit"), ("mpl3", "mpl", 3, "direct", "track"),
              ("pi", "pi", 6, "direct", "track"), ("pi-inverse", "pi", 6, "inverse", "tare")]
TOLERANCE = 1e-6  # of the training position range (issue 26)

_HARNESS = """#include <stdio.h>
#include <stdlib.h>
#include "comp.h"
/* init at the first value (or sync), then step every value; print estimate, band, flags */
int main(void)
{
    char line[128];
    comp_state st;
    int started = 0;
    while (fgets(line, sizeof line, stdin) != NULL) {
        comp_real v = (comp_real)strtod(line, NULL);
        comp_real e;
        if (!started) { START; started = 1; }
        e = comp_step(&st, v);
        printf("%.17g %.17g %.17g %u\\n", (double)e, (double)st.lower, (double)st.upper,
               st.flags);
    }
    return 0;
}
"""


@pytest.fixture(scope="module")
def stretched(recordings):
    """The validation noise with samples 3000-4999 stretched 1.6 times about its mean: beyond
    the sine's training range, and faster than its fastest rate."""
    _, val = recordings
    sensor = val.sensor.copy()
    mean = float(np.mean(sensor))
    sensor[3000:5000] = mean + 1.6 * (sensor[3000:5000] - mean)
    return replace(val, sensor=sensor, source="<stretched noise>")


@pytest.fixture(scope="module")
def banded(recordings):
    """label -> compensator with its band, fitted as the issue says."""
    train, _ = recordings
    cache: dict = {}

    def get(label: str):
        if label not in cache:
            _, model, size, mode, center = next(c for c in BAND_CASES if c[0] == label)
            comp = fit_compensator(train, size, model=model, mode=mode, center=center,
                                   diagnose=False)
            cache[label] = with_band(comp, [train], size)
            assert cache[label].band is not None, cache[label].fit_info["band"]
        return cache[label]

    return get


def _span(comp) -> float:
    lo, hi = comp.position_range
    return hi - lo


def _build(folder: Path, comp, double: bool, start: str = "comp_init(&st, v)", **plan) -> Path:
    folder.mkdir()
    for name, text in c_files(make_plan(comp, "comp", **plan), double).items():
        if name != "example_main.c":
            (folder / name).write_text(text)
    (folder / "harness.c").write_text(_HARNESS.replace("START", start))
    return compile_c(folder)


def _run(binary: Path, sensor: np.ndarray) -> np.ndarray:
    """Columns estimate, lower, upper, flags."""
    text = "\n".join(repr(float(v)) for v in sensor) + "\n"
    out = subprocess.run([str(binary)], input=text, capture_output=True, text=True,
                         check=True, timeout=120).stdout
    return np.array(out.split(), dtype=float).reshape(-1, 4)


def test_the_recording_reaches_every_term_of_the_band(banded, stretched):
    """Else agreement would not say much: beyond the training range and above its rates."""
    for label, *_ in BAND_CASES:
        comp = banded(label)
        s = comp.normalised_sensor(stretched.sensor)
        rate, outside, _ = band_features(s, comp.structure.dt, comp.band.tau,
                                         comp.training_range)
        assert np.mean(outside > 0) > 0.1, label
        assert np.mean(rate > comp.band.rate_high) > 0.1, label


@pytest.mark.parametrize("label", [c[0] for c in BAND_CASES])
def test_c_reproduces_the_python_band(label, banded, stretched, tmp_path):
    need("cc")
    comp = banded(label)
    ref = comp.estimate_with_band(stretched)
    span = _span(comp)
    got = _run(_build(tmp_path / "double", comp, True), stretched.sensor)
    errors = [np.max(np.abs(got[:, i] - r)) for i, r in
              enumerate((ref.estimate, ref.lower, ref.upper))]
    print(f"{label} C double: max |difference| / range {max(errors) / span:.2g}")
    assert max(errors) <= TOLERANCE * span
    got32 = _run(_build(tmp_path / "float", comp, False), stretched.sensor)
    half32, half = got32[:, 2] - got32[:, 0], ref.upper - ref.estimate
    print(f"{label} C float: half-width off by {np.max(np.abs(half32 - half)) / span:.2g}")
    assert np.max(np.abs(half32 - half)) <= TOLERANCE * span
    assert np.max(np.abs((got32[:, 0] - got32[:, 1]) - half)) <= TOLERANCE * span


def test_c_band_at_another_level_and_with_a_rate_share(banded, stretched, tmp_path):
    """--level bakes that level's quantile in; a band whose scale grows with the rate (the
    fitted ones here have share 0) runs the share term too."""
    need("cc")
    comp = banded("mpl3")
    comp = replace(comp, band=replace(comp.band, rate_share=0.5))
    ref = comp.estimate_with_band(stretched, level=0.5)
    nominal = comp.estimate_with_band(stretched)
    assert np.max(ref.upper - ref.lower) < np.max(nominal.upper - nominal.lower)
    got = _run(_build(tmp_path / "c", comp, True, level=0.5), stretched.sensor)
    assert np.max(np.abs(got[:, 1] - ref.lower)) <= TOLERANCE * _span(comp)
    assert np.max(np.abs(got[:, 2] - ref.upper)) <= TOLERANCE * _span(comp)
    header = c_files(make_plan(comp, level=0.5))["mpl.h"]
    assert "band         : prediction band at level 0.5, outputs lower/upper" in header
    assert "#define MPL_BAND_LEVEL 0.5" in header


def test_c_sync_start_matches_the_streams_band(banded, stretched, tmp_path):
    """NAME_sync starts the band's features afresh, as Stream(start="sync") does."""
    need("cc")
    from hystkit.live._sync import sync_excitation

    comp = banded("mpl3")
    binary = _build(tmp_path / "c", comp, True, start="comp_sync(&st)",
                    sync_state=sync_excitation(comp).state_after)
    got = _run(binary, stretched.sensor)
    ref = Stream(comp, start="sync").process_flagged(stretched.sensor)
    assert np.max(np.abs(got[:, 1] - ref.lower)) <= TOLERANCE * _span(comp)
    assert np.max(np.abs(got[:, 2] - ref.upper)) <= TOLERANCE * _span(comp)


def test_example_main_prints_the_band_on_request(banded, stretched, tmp_path):
    """./estimate: one estimate per line, as before; ./estimate --band: estimate lower upper."""
    comp = banded("pi")
    out = tmp_path / "out"
    export_compensator(comp, out, "c", double=True, name="tip")
    subprocess.run(["cc", "-O2", "-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror",
                    "tip.c", "example_main.c", "-lm", "-o", "estimate"], cwd=out, check=True,
                   timeout=120)
    text = "\n".join(repr(float(v)) for v in stretched.sensor[:2000]) + "\n"
    ref = comp.estimate_with_band(stretched)
    plain = subprocess.run([str(out / "estimate")], input=text, capture_output=True,
                           text=True, check=True, timeout=60).stdout
    np.testing.assert_allclose(np.array(plain.split(), dtype=float), ref.estimate[:2000],
                               rtol=0, atol=1e-9)  # mm, double as test_export_c
    band = subprocess.run([str(out / "estimate"), "--band"], input=text, capture_output=True,
                          text=True, check=True, timeout=60).stdout
    got = np.array(band.split(), dtype=float).reshape(-1, 3)
    for column, r in zip(got.T, (ref.estimate, ref.lower, ref.upper), strict=True):
        assert np.max(np.abs(column - r[:2000])) <= TOLERANCE * _span(comp)


@pytest.mark.parametrize("label", [c[0] for c in BAND_CASES])
def test_matlab_reproduces_the_python_band(label, banded, stretched, tmp_path):
    """In two chunks (split inside the excursion: the state carries the band's memory) and
    one sample at a time through NAME_block."""
    octave = need("octave")
    comp = banded(label)
    ref = comp.estimate_with_band(stretched)
    for name, text in matlab_files(make_plan(comp, "comp")).items():
        (tmp_path / name).write_text(text)
    np.savetxt(tmp_path / "sensor.txt", stretched.sensor, fmt="%.17g")
    script = (f"cd('{tmp_path}'); s = load('sensor.txt');"
              "[e1, st, f1, l1, u1] = comp(s(1:3500));"
              "[e2, st, f2, l2, u2] = comp(s(3501:end), st);"
              "eb = zeros(300, 1); lb = eb; ub = eb;"
              "for i = 1:300, [eb(i), lb(i), ub(i)] = comp_block(s(i)); end;"
              "fid = fopen('out.txt', 'w');"
              "fprintf(fid, '%.17g\\n', [e1; e2; l1; l2; u1; u2; eb; lb; ub]); fclose(fid);")
    subprocess.run([octave, "--no-gui", "--quiet", "--no-window-system", "--eval", script],
                   check=True, capture_output=True, timeout=600)
    got = np.loadtxt(tmp_path / "out.txt")
    n = stretched.n_samples
    chunks, block = got[:3 * n].reshape(3, n), got[3 * n:].reshape(3, 300)
    refs = (ref.estimate, ref.lower, ref.upper)
    error = max(np.max(np.abs(c - r)) for c, r in zip(chunks, refs, strict=True))
    error = max(error, *(np.max(np.abs(b - r[:300])) for b, r in zip(block, refs, strict=True)))
    print(f"{label} MATLAB: max |difference| / range {error / _span(comp):.2g}")
    assert error <= TOLERANCE * _span(comp)


def test_without_a_band_the_export_says_so_and_has_no_band_outputs(compensators, recordings,
                                                                    tmp_path):
    """Exports as before (estimate only), the comments say there is no band; a level is
    refused rather than ignored."""
    _, val = recordings
    comp = compensators("mpl1", "direct", "fit")
    assert comp.band is None
    plan = make_plan(comp, "comp")
    assert plan.band is None
    files = c_files(plan, double=True)
    for name in ("comp.h", "comp.c"):
        assert "band         : none: the model file has no prediction band" in files[name]
    assert "#define COMP_HAS_BAND 0" in files["comp.h"]
    assert "st->lower" not in files["comp.h"] and "real lower;" not in files["comp.h"]
    assert "band_half" not in files["comp.c"]
    assert "No prediction band" in files["README"]
    for name, text in files.items():
        if name != "example_main.c":
            (tmp_path / name).write_text(text)
    (tmp_path / "harness.c").write_text(_HARNESS.replace("START", "comp_init(&st, v)").replace(
        "(double)st.lower, (double)st.upper", "0.0, 0.0"))
    got = _run(compile_c(tmp_path), val.sensor)
    assert np.max(np.abs(got[:, 0] - comp.estimate(val))) <= 1e-9  # mm, as test_export_c
    m_files = matlab_files(plan)
    assert "function [estimate, state, flags] = comp(sensor, state)" in m_files["comp.m"]
    assert "function estimate = comp_block(sensor)" in m_files["comp_block.m"]
    assert all("% band         : none" in text for text in m_files.values())
    with pytest.raises(InputError, match="--level: .* has no prediction band"):
        make_plan(comp, level=0.8)


def test_a_level_outside_0_1_is_refused(banded):
    with pytest.raises(InputError, match="--level: band level must lie strictly between"):
        make_plan(banded("mpl1"), level=1.0)
