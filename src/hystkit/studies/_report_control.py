"""The report of a ``hystkit control`` output folder: the loop, its stability, its figures.

The run's traces are not stored (only its metrics), so its figures are the PNG files the run
wrote, embedded as they are; they cannot be redrawn as SVG or PDF.
"""

from __future__ import annotations

import math
from pathlib import Path

from ..control import SLOW_GROWTH_S, TYPICAL_RUN_S, slow_cell_words
from ..errors import InputError
from ._html import Section, definition_list, note, table
from ._report_folders import read_json
from ._report_model import ReportContent

__all__ = ["control_figures", "control_report", "stability_verdict"]

_MARGINAL = ("closed loop marginally stable: a pole on the unit circle to within the rounding of "
             "its eigenvalue (a state the linearised loop neither corrects nor amplifies, e.g. a "
             "sticking element at rest or a double integrator)")
_CAPTIONS = {"response": "the closed-loop response", "cases": "every case side by side",
             "bode": "the linearised open loop at rest (Bode plot)"}


def control_figures(folder: Path) -> list[Path]:
    """The PNG files a control run wrote, in the order the page shows them."""
    order = {"response": 0, "cases": 1, "bode": 3}
    return sorted(folder.glob("*.png"), key=lambda p: (order.get(p.stem, 2), p.name))


def stability_verdict(linear: dict) -> tuple[str, str]:
    """``(text, kind)`` of the linearised loop's verdict, worded as ``hystkit control``
    prints it; kind is ``good``, ``note`` (marginal) or ``bad``."""
    if linear.get("closed_loop_stable"):
        return "closed loop stable (linearised at rest)", "good"
    if linear.get("marginal"):
        return (_MARGINAL, "note")
    growth = linear.get("growth_time_s")
    if growth is not None and linear.get("slow_cell") is not None:  # as `hystkit control`
        words = slow_cell_words(linear["max_pole_radius"], growth, linear["slow_cell"],
                                linear["slow_cell_s"], TYPICAL_RUN_S)
        return f"closed loop {words} (linearised at rest)", "note"
    if growth is not None and growth >= SLOW_GROWTH_S:  # as `hystkit control` words it
        return (f"closed loop unstable only over days (linearised at rest): max |pole| "
                f"{linear.get('max_pole_radius', float('nan')):.10f}, grows e-fold in "
                f"{growth:.3g} s, a factor {math.exp(TYPICAL_RUN_S / growth):.4f} over a "
                f"{TYPICAL_RUN_S / 60:g}-minute run"
                + (f"; {linear['cause']}" if linear.get("cause") else ""), "note")
    return (f"closed loop UNSTABLE (linearised at rest): max |pole| "
            f"{linear.get('max_pole_radius', float('nan')):.10f}"
            + (f", grows e-fold in {growth:.3g} s" if growth is not None else "")
            + (f"; {linear['cause']}" if linear.get("cause") else ""), "bad")


def _fmt(value: object, spec: str = ".3g") -> str:
    return "n/a" if value is None else format(value, spec)


def _build(folder: Path, content: ReportContent) -> None:
    config = read_json(folder / "config.json")
    metrics_path = folder / "metrics.json"
    metrics = read_json(metrics_path if metrics_path.is_file() else folder / "analysis.json")
    linear = metrics["linear"]
    section = Section(f"control: {folder}")
    pid = config["pid"]
    gains = (f"Kp = {pid['kp']:.4g}, Ti = {_fmt(pid['ti'], '.4g')} s, Td = {pid['td']:.4g} s, "
             f"Tf = {pid['tf']:.3g} s ({pid.get('source', 'not stored')})")
    section.add(definition_list([
        ("scheme", config["scheme"]),
        ("experiment", config.get("experiment") or "none (Bode only)"), ("PID", gains),
        ("disturbance observer", "off" if config.get("dob_f_q") is None
         else f"{config['dob_f_q']:.3g} Hz"),
        ("moving mass [kg]", config.get("mass")),
        ("force limit [N]", config.get("u_max") or "none"),
        ("sample time [s]", config.get("ts")),
        ("sensor S_r", config.get("models", {}).get("sensor_source", config.get("sensor"))),
        ("compensator and S_m", config.get("models", {}).get("training_source")),
        ("hystkit version", config.get("hystkit_version") or "not stored")]))
    text, kind = stability_verdict(linear)
    section.add(note(text, kind))
    section.add(table(("crossover [Hz]", "phase margin [deg]", "gain margin [dB]",
                       "max |pole|"),
                      [(_fmt(linear.get("crossover_hz")), _fmt(linear.get("phase_margin_deg")),
                        "inf" if linear.get("gain_margin_db") is None
                        else _fmt(linear["gain_margin_db"]),
                        _fmt(linear.get("max_pole_radius"), ".10f"))], text_columns=0))
    cases = metrics.get("cases", {})
    if cases:
        section.add(table(("case", "e_p,max [m]", "e_p,mean [m]", "e_p,rms [m]",
                           "tracking rms", "bounded", "stopped"),
                          [(label, _fmt(m.get("e_p_max")), _fmt(m.get("e_p_mean")),
                            _fmt(m.get("e_p_rms")), _fmt(m.get("tracking_rms")), m["bounded"],
                            "" if m["bounded"] else f"t = {m['stop_time']:.3f} s: "
                                                    f"{m['stop_reason']}")
                           for label, m in cases.items()]))
        unbounded = [label for label, m in cases.items() if not m["bounded"]]
        if unbounded:
            section.add(note(f"unbounded in simulation: {', '.join(unbounded)}", "bad"))
    if "document" in metrics:
        d = metrics["document"]
        section.add(note(f"document ({d['source']}): e_p,max {d['e_p_max']:.3g} m, e_p,mean "
                         f"{d['e_p_mean']:.4g} m"))
    content.sections.append(section)
    for path in control_figures(folder):
        png = path.read_bytes()
        caption = _CAPTIONS.get(path.stem, f"case {path.stem.removeprefix('case_')}")
        content.add_png(section, f"control_{path.stem}", png, f"{path.name}: {caption}")


def control_report(folder: Path, content: ReportContent) -> None:
    """Add a control run's section and figures to `content`; a file that is not what
    ``hystkit control`` writes is an InputError naming the folder."""
    try:
        _build(folder, content)
    except (KeyError, TypeError, AttributeError, IndexError, ValueError) as exc:
        if isinstance(exc, InputError):
            raise
        raise InputError(f"{folder}: its control result cannot be read ({type(exc).__name__}: "
                         f"{exc})") from None
