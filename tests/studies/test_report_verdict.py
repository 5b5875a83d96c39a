"""The HTML report gives each scored recording the shared verdict of `evaluate` (issue 24)."""

from __future__ import annotations

from hystkit.compensation import fit_compensator
from hystkit.sensors import simulate_experiment
from hystkit.studies._report_model import compensator_sections


def test_a_recording_the_model_loses_to_its_line_on_is_flagged():
    """A 3-cell mPL fitted on a sine: fine on another sine, below its straight line on the
    noise run (R² 0.57 against 0.88)."""
    comp = fit_compensator(simulate_experiment("sine", 1), 3, diagnose=False)
    content = compensator_sections(comp, {"sine": simulate_experiment("sine", 2),
                                          "noise": simulate_experiment("noise", 2)})
    scores = next(s for s in content.sections if s.title == "Scores").to_html()
    assert "noise: worse than line: deployable R² 0.5" in scores
    assert "do not use the mpl compensator on data like these" in scores
    assert "sine: worse than line" not in scores and "sine: no signal" not in scores


def test_the_structure_is_written_for_people():
    """A 50 Hz recording's sample time came out as dt = 0.019999999999999574 (issue 27.4)."""
    from hystkit.io import Recording

    rec = simulate_experiment("sine", 1)
    t = (rec.time / 0.025 * 0.02)[:2000]  # 50 Hz: float rounding in the time column
    fifty = Recording(time=t, sensor=rec.sensor[:2000], position=rec.position[:2000])
    comp = fit_compensator(fifty, diagnose=False)
    assert comp.structure.dt != 0.02  # what the time column gives, rounding included
    text = compensator_sections(comp, {"run": fifty}).sections[0].to_html()
    assert "dt = 0.02," in text and "0.0199999" not in text
