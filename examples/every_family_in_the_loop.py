"""
Every registered model family in the document's closed loop (ch. 7), as a new user would run it
===============================================================================================

Not run when the site is built: about a minute of fits and loops on two cores. Its table is in
:doc:`/control` ("Any family in any slot").

For each family: ``hystkit fit`` on the virtual sensor's sine recording (seed 2, direct mode,
the family's default size; 3 cells for the mPL as in ch. 7), then ``hystkit control --scheme
direct --experiment sine --compensator FILE`` (the family as the compensator, S_r the default
3-cell mPL fitted on the noise run) and ``--scheme weighting --model-file FILE`` (the family as
S_m, run position -> sensor through its inverse). Prints a Markdown table of the plant error
e_p,max on the 3 mm, 0.5 Hz sine, or the one-line reason a slot cannot be filled.

Run:  python examples/every_family_in_the_loop.py      (about two minutes)
"""

from __future__ import annotations

import contextlib
import io
import json
import tempfile
from pathlib import Path

from hystkit.cli import main
from hystkit.io import write_recording
from hystkit.models import FAMILIES
from hystkit.sensors import simulate_experiment


def _run(*args) -> tuple[int, str]:
    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        code = main([str(a) for a in args])
    return code, err.getvalue().strip()


def _loop(scheme: str, slot: str, model: Path, out: Path) -> str:
    code, err = _run("control", "--scheme", scheme, "--experiment", "sine", slot, model,
                     "--out", out)
    if code != 0:
        return f"refused: {err.removeprefix('hystkit: error: ')}"
    m = json.loads((out / "metrics.json").read_text())
    return f"{m['e_p_max']:.3g}" if m["bounded"] else f"unbounded at {m['stop_time']:.2f} s"


def main_table() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        data = folder / "sine.csv"
        write_recording(simulate_experiment("sine", 2), data)
        print("| family | fit status | direct: e_p,max [m] | weighting (as S_m): e_p,max [m] |")
        print("|---|---|---|---|")
        for name in sorted(FAMILIES):
            model = folder / f"{name}.json"
            size = ["--size", "3"] if name == "mpl" else []
            code, err = _run("fit", data, "--model", name, *size, "--out", model)
            status = "ok" if code == 0 else (err.splitlines()[-1] if err else f"exit {code}")
            if not model.exists():
                print(f"| {name} | {status} | - | - |")
                continue
            direct = _loop("direct", "--compensator", model, folder / f"{name}-a")
            weighting = _loop("weighting", "--model-file", model, folder / f"{name}-b")
            print(f"| {name} | {status} | {direct} | {weighting} |")


if __name__ == "__main__":
    main_table()
