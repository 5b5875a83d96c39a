"""
Which centring should be the default? Deployable R² of every mode on held-out data
==================================================================================

Not run when the site is built: about 50 s of fitting on two cores, and its real cases need the
shared data. Its table is in :doc:`/centring`.

For each case a compensator (mPL, 3 cells, direct mode) is fitted on training data only and
scored on held-out data with each centring: ``fit``, ``tare``, ``track`` (deployable) and
``recording`` (the paper's protocol, an oracle). Run: ``python examples/centring_evidence.py``
(needs the shared data for the real cases, ``hystkit datasets show NAME`` says where each comes
from and where it goes; virtual-sensor cases always run, and without the data one line on
stderr says which were skipped and why). Output is the table in docs/centring.md.
"""

from __future__ import annotations

import sys

import numpy as np

from hystkit.compensation import evaluate, fit_compensator
from hystkit.datasets import load
from hystkit.errors import HystkitError
from hystkit.io import Recording
from hystkit.sensors import simulate_experiment

CENTERS = ("fit", "tare", "track", "recording")


def _window(rec: Recording, t0: float, t1: float) -> Recording:
    keep = (rec.time >= t0) & (rec.time < t1)
    return Recording(time=rec.time[keep] - rec.time[keep][0], sensor=rec.sensor[keep],
                     position=rec.position[keep], source=f"{rec.source}[{t0:g}-{t1:g} s]")


def cases():
    """(name, training recordings, held-out recording)."""
    for name in ("sine", "decay", "chirp", "noise"):
        yield f"virtual {name}", [simulate_experiment(name, 1)], simulate_experiment(name, 2)
    yield ("virtual noise -> sine", [simulate_experiment("noise", 1)],
           simulate_experiment("sine", 2))
    yield from real_cases()


def real_cases():
    """(name, training recordings, a separate run) of every shared real data set that has
    one; none (and a note on stderr) where the shared data are not found."""
    try:
        ident = load("piezo_micromanipulator", "identification").to_recording()
        test = load("piezo_micromanipulator", "test")
        yield ("micromanipulator ident -> test uncompensated", [ident],
               test.segment("uncompensated").to_recording())
        actuator = load("piezo_actuator", "150V_1Hz").to_recording()
        yield ("piezo actuator 0-6.6 s -> 6.6-10 s", [_window(actuator, 0, 6.6)],
               _window(actuator, 6.6, 10.01))
        mr = [load("mr_damper", v).to_recording() for v in ("5mm_3Hz_1A", "10mm_1Hz_1A")]
        yield "MR damper 1 A sines -> earthquake", mr, load("mr_damper",
                                                           "earthquake_1A").to_recording()
        yield ("B(H) MnZn ferrite H80 -> H40",
               [load("bh_loops", "MnZn_ferrite_H80").to_recording()],
               load("bh_loops", "MnZn_ferrite_H40").to_recording())
        yield ("Bouc-Wen val multisine -> sine sweep (forward)",
               [load("boucwen", "val_multisine").to_recording(role="forward")],
               load("boucwen", "val_sinesweep").to_recording(role="forward"))
    except HystkitError as exc:
        print(f"(real data skipped: {exc})", file=sys.stderr)


def main() -> None:
    print("| case | " + " | ".join(f"R² {c}" + (" (oracle)" if c == "recording" else "")
                                  for c in CENTERS) + " | line R² (fit) |")
    print("|---|" + "---|" * (len(CENTERS) + 1))
    for name, train, test in cases():
        row, line = [], None
        for center in CENTERS:
            try:
                comp = fit_compensator(train, 3, center=center, diagnose=False)
                scores = evaluate(comp, test)
                row.append(f"{scores['r2']:.4f}")
                line = scores["linear_r2"] if center == "fit" else line
            except HystkitError as exc:
                row.append(f"fails ({str(exc)[:40]})")
        line_text = "-" if line is None else f"{line:.4f}"
        print(f"| {name} | " + " | ".join(row) + f" | {line_text} |", flush=True)
    print(f"\n(numpy {np.__version__})")


if __name__ == "__main__":
    main()
