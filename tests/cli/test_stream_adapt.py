"""``hystkit stream --adapt``: the command gives the library's adapting stream, bit for bit."""

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from hystkit.cli import main
from hystkit.compensation import fit_compensator, save_compensator
from hystkit.live import Adaptation, AdaptiveStream, Stream
from hystkit.sensors import occasional_references, simulate_experiment, with_gain_drift

N = 400


@pytest.fixture(scope="module")
def model(tmp_path_factory):
    folder = tmp_path_factory.mktemp("adapt")
    comp = fit_compensator(simulate_experiment("noise", 1), 1, center="track", diagnose=False)
    return comp, save_compensator(comp, folder / "noise.json")


@pytest.fixture(scope="module")
def drifting():
    rec = with_gain_drift(simulate_experiment("sine", 2), -0.10)
    return rec.sensor[:N], occasional_references(rec, 0.5, seed=3)[:N]


def csv_lines(sensor, reference, header: str | None = "time,sensor,reference") -> str:
    rows = [] if header is None else [header]
    for k, (s, r) in enumerate(zip(sensor.tolist(), reference.tolist(), strict=True)):
        rows.append(f"{k * 0.025!r},{s!r},{'' if np.isnan(r) else repr(r)}")
    return "\n".join(rows) + "\n"


def estimates(out: str) -> np.ndarray:
    rows = out.splitlines()
    assert rows[0] == "time,position_estimate,flags"
    return np.array([float(row.split(",")[1]) for row in rows[1:]])


@pytest.mark.parametrize("adapt", ["gain", "weights"])
@pytest.mark.parametrize("header", ["time,sensor,reference", None])
def test_adapt_gives_the_library_stream(model, drifting, tmp_path, capsys, adapt, header):
    comp, path = model
    sensor, reference = drifting
    data = tmp_path / "in.csv"
    data.write_text(csv_lines(sensor, reference, header))
    assert main(["stream", str(path), "--in", str(data), "--adapt", adapt,
                 "--forgetting", "0.9", "--prior-gain", "0.2"]) == 0
    captured = capsys.readouterr()
    stream = AdaptiveStream(comp, Adaptation(adapt, 0.9, prior_gain=0.2))
    assert_array_equal(estimates(captured.out), stream.process(sensor, reference))
    n_ref = int(np.isfinite(reference).sum())
    assert f"adaptation ({adapt}, forgetting 0.9): {n_ref} references" in captured.err
    assert np.any(estimates(captured.out) != Stream(comp).process(sensor))


def test_without_adapt_the_reference_column_is_ignored(model, drifting, tmp_path, capsys):
    comp, path = model
    sensor, reference = drifting
    data = tmp_path / "in.csv"
    data.write_text(csv_lines(sensor, reference))
    assert main(["stream", str(path), "--in", str(data)]) == 0
    captured = capsys.readouterr()
    assert_array_equal(estimates(captured.out), Stream(comp).process(sensor))
    assert "adaptation" not in captured.err


def test_a_bad_reference_is_ignored_and_counted(model, drifting, tmp_path, capsys):
    comp, path = model
    sensor, reference = drifting
    rows = csv_lines(sensor, reference).splitlines()
    known = np.flatnonzero(np.isfinite(reference))
    rows[known[1] + 1] = rows[known[1] + 1].rsplit(",", 1)[0] + ",1.0mm"  # +1: the header
    rows[known[2] + 1] = rows[known[2] + 1].rsplit(",", 1)[0] + ",inf"
    data = tmp_path / "in.csv"
    data.write_text("\n".join(rows) + "\n")
    assert main(["stream", str(path), "--in", str(data), "--adapt", "gain"]) == 0
    captured = capsys.readouterr()
    ignored = reference.copy()
    ignored[known[1:3]] = np.nan
    assert_array_equal(estimates(captured.out), AdaptiveStream(comp).process(sensor, ignored))
    assert (f"hystkit: warning: {data}: 2 line(s) reference not a number (compensated; the "
            f"reference ignored; first at line {known[1] + 2})") in captured.err


def test_no_reference_at_all_says_so(model, drifting, tmp_path, capsys):
    comp, path = model
    sensor, _ = drifting
    data = tmp_path / "in.csv"
    rows = csv_lines(sensor[:50], np.full(50, np.nan)).splitlines()
    assert rows[5].endswith(",")
    rows[5] += "nan"  # an explicit unknown reference
    data.write_text("\n".join(rows) + "\n")
    assert main(["stream", str(path), "--in", str(data), "--adapt", "weights"]) == 0
    captured = capsys.readouterr()
    assert_array_equal(estimates(captured.out), Stream(comp).process(sensor[:50]))
    assert "no reference arrived; the estimates are the plain stream's" in captured.err
    assert "not a number" not in captured.err


def test_adapt_options_without_adapt_are_refused(model, capsys):
    _, path = model
    assert main(["stream", str(path), "--forgetting", "0.9", "--prior-offset", "1"]) == 2
    err = capsys.readouterr().err
    assert err.strip() == "hystkit: error: --forgetting, --prior-offset only apply with --adapt"


def test_a_forgetting_factor_outside_0_1_is_refused(model, capsys):
    _, path = model
    assert main(["stream", str(path), "--adapt", "gain", "--forgetting", "1.5"]) == 2
    assert capsys.readouterr().err.strip() == ("hystkit: error: argument --forgetting: must be "
                                               "<= 1, got 1.5 (see 'hystkit stream --help')")


def test_weights_on_an_inverse_model_is_one_error_line(tmp_path, capsys):
    comp = fit_compensator(simulate_experiment("noise", 1), 1, mode="inverse", center="track",
                           diagnose=False)
    path = save_compensator(comp, tmp_path / "inverse.json")
    assert main(["stream", str(path), "--adapt", "weights"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("hystkit: error: ") and "inverse" in err and "use 'gain'" in err
    assert len(err.splitlines()) == 1


def test_the_parser_constants_are_the_library_s():
    # the parser keeps its own copies so that building it imports no numpy
    from hystkit.cli import _stream_defaults
    from hystkit.live import ADAPT_PARAMETERS, Refit

    assert _stream_defaults.ADAPT_CHOICES == (*ADAPT_PARAMETERS, "full")
    assert _stream_defaults.DEFAULT_FORGETTING == Adaptation().forgetting
    assert _stream_defaults.DEFAULT_WINDOW == Refit().window_seconds
    assert _stream_defaults.DEFAULT_REFIT_EVERY == Refit().every


def test_adapt_full_gives_the_library_refitting_stream(model, tmp_path, capsys):
    from hystkit.live import Refit, RefittingStream

    comp, path = model
    rec = with_gain_drift(simulate_experiment("sine", 2), -0.10)
    n = 1200  # 30 s, one reference per 0.25 s: 120, and 40 in a 10 s window
    sensor, reference = rec.sensor[:n], occasional_references(rec, 0.25, seed=3)[:n]
    data = tmp_path / "in.csv"
    data.write_text(csv_lines(sensor, reference))
    assert main(["stream", str(path), "--in", str(data), "--adapt", "full", "--window", "10",
                 "--refit-every", "5"]) == 0
    captured = capsys.readouterr()
    stream = RefittingStream(comp, Refit(window_seconds=10.0, every=5))
    assert_array_equal(estimates(captured.out), stream.process(sensor, reference))
    report = stream.report
    assert report.kept > 0
    assert np.any(estimates(captured.out) != Stream(comp).process(sensor))
    assert ("adaptation (full, window 10 s, refit every 5 references): 120 references"
            in captured.err)
    assert (f"refits: {report.kept} kept, {report.refused} refused, {report.skipped} "
            f"skipped" in captured.err)
    assert report.skipped > 0  # the first due refits: fewer than 20 references in the window


@pytest.mark.parametrize(("argv", "message"), [
    (["--adapt", "full", "--forgetting", "0.9"],
     "--forgetting applies to --adapt gain or weights, not full"),
    (["--adapt", "gain", "--window", "30"], "--window only applies with --adapt full"),
    (["--refit-every", "3"], "--refit-every only applies with --adapt full"),
    (["--adapt", "full", "--window", "0.25"], ("a 0.25 s window holds 10 samples, fewer than "
                                              "the 20 references a refit needs")),
])
def test_refit_options_in_the_wrong_place_are_refused(model, capsys, argv, message):
    _, path = model
    assert main(["stream", str(path), *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("hystkit: error: ") and message in err and "\n" not in err
