"""
Real piezo micromanipulator: hystkit's mPL inverse next to the author's hardware feedforward
============================================================================================

Run when the site is built with ``--excerpt`` (the shipped excerpts, seconds): the output below
shows that the pipeline runs, not the result, which needs the full runs.

Data: ``piezo_micromanipulator`` (Aye & Ang 2018, MIT; see docs/real_data.md). The author
identified an inverse-hysteresis (DBO) model on the identification run and ran it as a
feedforward on the hardware: segment 58-70 s of the test run (desired displacement -> drive
voltage -> micromanipulator -> sensor). Segment 0-16 s of the same run drives the hardware with
a voltage proportional to the desired displacement, i.e. uncompensated.

What is compared (apples to apples). The author's feedforward *is* an inverse model, output
-> input (wanted displacement -> voltage). hystkit fits the same map: an mPL compensator with
``sensor`` = measured displacement and ``position`` = drive voltage on the identification run
(``Dataset.to_recording()``, direct mode). We cannot run it on the hardware, so it is applied
offline to the measured displacement of the uncompensated segment. There the drive was
1.83 V + 0.0797 V/um x desired, so an exact inverse would return a straight line in the
desired displacement. The author's number is the measured output under his feedforward against
the same desired displacement.

Two scores, the deployable one first:

* **deployable** (hystkit only): the compensator's drive estimate, centring ``fit`` (the
  identification run's offsets; nothing from the test run), minus the drive that was applied,
  in um of desired displacement through the hardware's drive map (drive = 1.83 V + 0.0797 V/um
  x desired, exact to 5e-7 V). Nothing is fitted on the test segment.
* **calibrated on the segment (oracle)**: least-squares line z = a d + b of the signal z
  against the desired displacement d, residual (z - b) / a - d in um of desired displacement:
  gain and offset are fitted on the very segment that is scored. This is the only protocol
  the hardware rows allow (the sensor's offset is arbitrary) and the one the author's number
  uses; hystkit's number under it is an oracle, shown for the like-for-like comparison.

For an exact inverse of a hysteresis operator the pre-inverse (feedforward) and the
post-inverse (compensating the output) are the same identity, so the calibrated numbers measure
the inverse model's error; what the offline number cannot show is how the hardware would
respond to a voltage it never saw.

Run: ``python examples/piezo_micromanipulator.py`` (needs the shared data: the two files of
github.com/yan9a/DiscreteBacklashOperator that ``hystkit datasets show piezo_micromanipulator``
names, in ``piezo_micromanipulator_capsensor/`` of the shared data root) or with ``--excerpt``
(shipped 4-6 s excerpts; only shows that the pipeline runs). Without the data it ends in one
line saying where they come from and where they go.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from hystkit.compensation import Compensator, center_label, evaluate, fit_compensator
from hystkit.datasets import DataNotFoundError, Dataset, load, load_excerpt

NAME = "piezo_micromanipulator"
# Full-amplitude steady windows [s] inside the two segments: no start transient, no ramps.
STEADY = {"uncompensated": (1.0, 15.0), "feedforward": (60.0, 70.0)}
Window = tuple[float, float]
DEPLOYABLE = "deployable"
CALIBRATED = "calibrated on the segment (oracle)"
AUTHOR = "calibrated on the segment (the author's protocol)"  # hardware rows: measured output


@dataclass(frozen=True)
class Row:
    """One line of the comparison table; errors in um of desired displacement."""

    method: str
    protocol: str  # DEPLOYABLE, CALIBRATED or AUTHOR
    segment: str
    n_samples: int
    e_rms: float
    e_max: float
    span: float  # range of the desired displacement in the segment [um]

    @property
    def e_rms_pct(self) -> float:
        return 100.0 * self.e_rms / self.span

    @property
    def e_max_pct(self) -> float:
        return 100.0 * self.e_max / self.span


def straightness_residual(z: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Residual of `z` against the desired displacement `d` [um], in um of `d`.

    Fits z = a d + b by least squares and returns (z - b) / a - d: the error of the chain
    desired -> ... -> z once its gain and offset are calibrated out.
    """
    a, b = np.polyfit(d, z, 1)
    return (z - b) / a - d


def score(method: str, segment: str, z: np.ndarray, d: np.ndarray,
          protocol: str = CALIBRATED) -> Row:
    """RMS and max |residual| of `z` against `d` (see `straightness_residual`): calibrated on
    the scored segment, so an oracle for a compensator's estimate; for a measured hardware
    output (``protocol=AUTHOR``) the author's way of scoring it."""
    e = straightness_residual(np.asarray(z, float), np.asarray(d, float))
    return _row(method, protocol, segment, e, d)


def drive_map(ds: Dataset) -> tuple[float, float]:
    """Gain [V/um] and offset [V] of the drive against the desired displacement.

    In the uncompensated segments the drive was generated from the desired displacement by a
    straight line, known to the operator before the run; the fit only reads it back and
    refuses if the drive is not that line.
    """
    d = ds.channels["desired_displacement"]
    gain, offset = np.polyfit(d, ds.input, 1)
    worst = float(np.max(np.abs(ds.input - gain * d - offset)))
    if worst > 1e-5:
        raise ValueError(f"the drive of {ds.label} is not a straight line in the desired "
                         f"displacement (off by up to {worst:.3g} V)")
    return float(gain), float(offset)


def score_deployable(method: str, segment: str, drive_estimate: np.ndarray,
                     drive: np.ndarray, d: np.ndarray, gain: float) -> Row:
    """Error of a deployable drive estimate against the applied drive, in um of desired
    displacement (``gain`` [V/um] of the drive map); nothing is fitted on the segment."""
    e = (np.asarray(drive_estimate, float) - np.asarray(drive, float)) / gain
    return _row(method, DEPLOYABLE, segment, e, d)


def _row(method: str, protocol: str, segment: str, e: np.ndarray, d: np.ndarray) -> Row:
    return Row(method, protocol, segment, int(d.size), float(np.sqrt(np.mean(e**2))),
               float(np.max(np.abs(e))), float(np.ptp(d)))


def fit(identification: Dataset, n_cells: int) -> Compensator:
    """mPL compensator measured displacement -> drive voltage, fitted on the identification run.

    ``center="fit"`` (deployable, the default): the identification run's offsets are used for
    every recording, so nothing from the test run enters the compensator.
    """
    return fit_compensator(identification.to_recording(), n_cells, mode="direct", center="fit")


def _mask(ds: Dataset, window: Window | None) -> np.ndarray:
    if window is None:
        return np.ones(ds.n_samples, bool)
    half = 0.5 * ds.dt
    return (ds.time >= window[0] - half) & (ds.time < window[1] - half)


def compare(identification: Dataset, uncompensated: Dataset, feedforward: Dataset, *,
            n_cells: Sequence[int] = (1, 3),
            windows: Sequence[tuple[Window, Window]] = (),
            ) -> tuple[list[Row], dict[int, Compensator]]:
    """The comparison table's rows and the fitted compensators (by cell count).

    Per case (whole segments, then each of `windows`): hystkit's deployable rows (one per cell
    count), then the calibrated rows: uncompensated hardware, the author's feedforward on the
    hardware, hystkit (oracle).

    Parameters
    ----------
    identification : Dataset
        Fitting run (input = drive [V], output = sensor [um]).
    uncompensated, feedforward : Dataset
        Test-run parts with the channel ``desired_displacement`` [um].
    n_cells : sequence of int
        mPL cell counts to fit (one row each).
    windows : sequence of (window, window)
        Extra rows for (window in `uncompensated`, window in `feedforward`) [s], scored on the
        estimate computed over the whole segment (so the model state is warmed up).
    """
    cases: list[tuple[Window | None, Window | None]] = [(None, None), *windows]
    comps = {n: fit(identification, n) for n in n_cells}
    estimates = {n: c.estimate(uncompensated.to_recording()) for n, c in comps.items()}
    gain, _ = drive_map(uncompensated)
    rows = []
    for w_unc, w_ff in cases:
        m_unc, m_ff = _mask(uncompensated, w_unc), _mask(feedforward, w_ff)
        d_unc = uncompensated.channels["desired_displacement"][m_unc]
        d_ff = feedforward.channels["desired_displacement"][m_ff]
        seg_unc = _span(uncompensated, m_unc)
        seg_ff = _span(feedforward, m_ff)
        for n, estimate in estimates.items():
            rows.append(score_deployable(_hystkit(n), seg_unc, estimate[m_unc],
                                         uncompensated.input[m_unc], d_unc, gain))
        rows.append(score("uncompensated: drive linear in desired (hardware, measured)", seg_unc,
                          uncompensated.output[m_unc], d_unc, AUTHOR))
        rows.append(score("author's DBO inverse as feedforward (hardware, measured)", seg_ff,
                          feedforward.output[m_ff], d_ff, AUTHOR))
        for n, estimate in estimates.items():
            rows.append(score(_hystkit(n), seg_unc, estimate[m_unc], d_unc))
    return rows, comps


def _hystkit(n: int) -> str:
    return (f"hystkit mPL inverse, {n} cell(s), {3 * n + 2} params (offline, on the measured "
            f"output)")


def _span(ds: Dataset, mask: np.ndarray) -> str:
    t = ds.time[mask]
    return f"{t[0]:g}-{t[-1] + ds.dt:g} s"


def format_table(rows: Sequence[Row], unit: str = "um") -> str:
    """Markdown table of the rows."""
    lines = [(f"| method | score | segment | samples | e_rms [{unit}] | e_max [{unit}] "
              "| e_rms [% of range] | e_max [% of range] |"), "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r.method} | {r.protocol} | {r.segment} | {r.n_samples} | "
                     f"{r.e_rms:.3f} | {r.e_max:.3f} | {r.e_rms_pct:.2f} | {r.e_max_pct:.2f} |")
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").strip().partition("\n")[0])
    parser.add_argument("--excerpt", action="store_true",
                        help="use the shipped excerpts (pipeline check, not the result)")
    parser.add_argument("--root", help="shared data root (default: search, see hystkit.datasets)")
    parser.add_argument("--cells", type=int, nargs="+", default=[1, 3])
    args = parser.parse_args(argv)
    if args.excerpt:
        ident = load_excerpt(NAME, "identification")
        unc = load_excerpt(NAME, "test_uncompensated")
        ff = load_excerpt(NAME, "test_feedforward")
        windows = []
    else:
        ident = load(NAME, "identification", root=args.root)
        test = load(NAME, "test", root=args.root)
        unc, ff = test.segment("uncompensated"), test.segment("feedforward")
        windows = [(STEADY["uncompensated"], STEADY["feedforward"])]
    # The mPL model's Euler step is its sample time: fitting and test rates must agree
    # (Compensator.estimate refuses otherwise).
    print(f"sample rates: identification {ident.fs:.6g} Hz, test {unc.fs:.6g} Hz "
          f"(model dt = {1 / ident.fs:.6g} s)")
    rows, comps = compare(ident, unc, ff, n_cells=args.cells, windows=windows)
    gain, offset = drive_map(unc)
    print(f"drive map of the uncompensated segment: {offset:.4f} V + {gain:.5f} V/um x desired")
    for n, comp in comps.items():
        info = comp.fit_info
        scores = evaluate(comp, unc.to_recording())
        print(f"fitted mPL {n} cell(s) on {ident.label} ({ident.n_samples} samples): "
              f"{info['fit_seconds']:.2f} s, SSE {info['cost']:.4g} (normalised), fit status "
              f"{info['status']}; on the uncompensated segment R² {scores['r2']:.4f} "
              f"(deployable, centring {center_label(scores['center'])}), "
              f"{scores['r2_oracle']:.4f} (centring {center_label(scores['center_oracle'])})")
    # The data README quotes the linear-fit residual in sensor units (~2.5 and ~0.33).
    for label, ds in (("uncompensated", unc), ("feedforward", ff)):
        d = ds.channels["desired_displacement"]
        a, b = np.polyfit(d, ds.output, 1)
        rms = np.sqrt(np.mean((ds.output - a * d - b) ** 2))
        print(f"{label}: linear-fit residual rms of the sensor output {rms:.3f} "
              f"{ds.output_unit} (sensor units), slope {a:.4f}")
    print()
    print(format_table(rows))
    return 0


if __name__ == "__main__":
    try:
        code = main()
    except DataNotFoundError as exc:  # one line: where the data come from and where they go
        sys.exit(f"piezo_micromanipulator.py: {exc}")
    if code:  # no sys.exit(0): the docs build runs this file as __main__ in its own process
        sys.exit(code)
