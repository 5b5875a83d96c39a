"""What the command-line tests share: one call of ``hystkit`` in this process."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from hystkit.cli import main


def run_cli(capsys: pytest.CaptureFixture[str], *argv: object) -> tuple[int, str, str]:
    """``main`` on the stringified arguments: ``(exit code, stdout, stderr)`` of this call
    only (whatever was printed before, e.g. by fixtures, is dropped first)."""
    capsys.readouterr()
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


# A lab's own layout of the virtual sine (tests of the remembered reading: hk.fit, batch)
LAB_COLUMNS = (("time", "t_ms"), ("position", "x_mm"), ("sensor", "R_ohm"))
LAB_SAID = ("as the model's training data were read: columns t_ms,x_mm,R_ohm, time in ms, "
            "a units line")


def write_lab_csv(path: Path, seed: int, n: int = 2400) -> None:
    """The virtual sine as a lab writes it: its own names, time in whole ms, a units line."""
    from hystkit.sensors import simulate_experiment

    rec = simulate_experiment("sine", seed)
    frame = pd.DataFrame({"t_ms": np.round(rec.time[:n] * 1e3), "x_mm": rec.position[:n],
                          "R_ohm": rec.sensor[:n]})
    with path.open("w", encoding="utf-8") as out:
        out.write("t_ms,x_mm,R_ohm\nms,mm,Ohm\n")
        frame.to_csv(out, index=False, header=False)

