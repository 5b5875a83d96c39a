"""Hostile options: every bad value is one error line naming the option, before any work.

Each case runs in-process in a scratch folder holding copies of the valid inputs and asserts
exit 2 (never the internal-error code 70), one ``hystkit: error:`` line naming the option,
no traceback, and the folder exactly as it was.
"""

from __future__ import annotations

import shutil
import time
from collections.abc import Callable
from pathlib import Path

import pytest

from .conftest import Run, entries, snapshot

# (argv with {fit}/{val}/{model} for the inputs and {out} for an output, fragments the error
# line must name). The first seven are the cases issue 10 lists.
CASES = {
    "preisach-size-512": ("fit {fit} --model preisach --size 512 --out {out}.json",
                          ["--cells 512", "preisach", "at most"]),
    "slope-cap-1e-300": ("fit {fit} --slope-cap 1e-300 --out {out}.json", ["--slope-cap"]),
    "cells-300": ("fit {fit} --cells 300 --out {out}.json", ["--cells 300", "mpl"]),
    "tune-0-45": ("control --scheme direct --bode --tune 0 45 --out {out}", ["--tune FC_HZ"]),
    "pid-0-inf-0": ("control --scheme direct --bode --pid 0 inf 0 --out {out}", ["--pid KP"]),
    "compare-size-superscript": ("compare {fit} {val} --size mpl=² --out {out}",
                                 ["--size", "mpl=²"]),
    "config-is-folder": (("preprocess {fit} --r-bridge 1e4 --v-supply 2 --config . --out "
                         "{out}.csv"), ["--config", "folder"]),
    "chunk-size-0": ("preprocess {fit} --chunk-size 0 --out {out}.csv", ["--chunk-size"]),
    "chunk-size-minus-1": ("preprocess {fit} --chunk-size -1 --out {out}.csv",
                           ["--chunk-size"]),
    "chunk-size-2": ("preprocess {fit} --chunk-size 2 --out {out}.csv", ["--chunk-size"]),
    "preisach-size-1": ("fit {fit} --model preisach --cells 1 --out {out}.json",
                        ["--cells 1", "levels"]),
    "boucwen-substeps-1e5": ("fit {fit} --model boucwen --cells 100000 --out {out}.json",
                             ["--cells 100000", "boucwen"]),
    "cells-zero": ("fit {fit} --cells 0 --out {out}.json", ["--cells"]),
    "cells-not-a-number": ("fit {fit} --cells 3.5 --out {out}.json", ["--cells"]),
    "tare-seconds-nan": ("fit {fit} --center tare --tare-seconds nan --out {out}.json",
                         ["--tare-seconds"]),
    "track-seconds-inf": ("fit {fit} --center track --track-seconds inf --out {out}.json",
                          ["--track-seconds"]),
    "rest-position-inf": ("compensate {model} {val} --rest-position inf --out {out}.csv",
                          ["--rest-position"]),
    "seed-negative": ("simulate-sensor --excitation sine --seed -1 --out {out}.csv",
                      ["--seed"]),
    "scope-rate-1e12": (("simulate-sensor --excitation sine --raw --scope-rate 1e12 --out "
                        "{out}.csv"), ["--scope-rate"]),
    "glitches-huge": (("simulate-sensor --excitation sine --raw --glitches 99999999 --out "
                      "{out}.csv"), ["--glitches"]),
    "compare-size-too-big": ("compare {fit} {val} --size mpl=999 --out {out}",
                             ["--size mpl=999", "at most"]),
    "generalize-size-unknown-model": ("generalize {fit} {val} --size nope=3 --out {out}",
                                      ["--size", "nope=3"]),
    "control-tf-negative": ("control --scheme direct --bode --tf -1 --out {out}", ["--tf"]),
    "control-tune-margin-90": ("control --scheme direct --bode --tune 5 90 --out {out}",
                               ["--tune PM_DEG"]),
    "control-pid-td-nan": ("control --scheme direct --bode --pid 1 1 nan --out {out}",
                           ["--pid TD"]),
    "control-mass-1e-300": ("control --scheme direct --bode --mass 1e-300 --out {out}",
                            ["--mass"]),
    "control-pid-1e300": ("control --scheme direct --bode --pid 1e300 1e-300 1e300 --out {out}",
                          ["--pid KP"]),
    "control-dob-hz-inf": ("control --scheme direct --bode --dob --dob-hz inf --out {out}",
                           ["--dob-hz"]),
    "control-sensor-size-huge": (("control --scheme direct --bode --sensor-size 10000 --out "
                                 "{out}"), ["--sensor-size 10000"]),
    "demo-cells-huge": ("demo --cells 1000 --out {out}", ["--cells 1000"]),
    "select-jobs-0": ("select {fit} --jobs 0 --out {out}.json", ["--jobs"]),
    "pl-search-p-nan": ("pl-search {fit} --p nan", ["--p"]),
    "pl-search-n-huge": ("pl-search {fit} --n 100000", ["--n"]),
    "preprocess-order-0": ("preprocess {fit} --order 0 --out {out}.csv", ["--order"]),
    "preprocess-levels-inf": ("preprocess {fit} --encoder-levels 0,1,2,inf --out {out}.csv",
                              ["--encoder-levels"]),
}


@pytest.fixture
def scratch(good: dict[str, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A working folder with copies of the valid inputs (relative paths resolve here)."""
    for key in ("fit", "val", "model"):
        shutil.copy(good[key], tmp_path / good[key].name)
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.mark.parametrize("case", CASES)
def test_bad_option_is_one_line_before_any_work(case: str, scratch: Path,
                                                cli: Callable[..., Run]) -> None:
    template, fragments = CASES[case]
    argv = template.format(fit="fit.csv", val="val.csv", model="model.json", out="out").split()
    before, names = snapshot(scratch), entries(scratch)
    t0 = time.perf_counter()
    run = cli(*argv)
    assert run.code == 2, f"exit {run.code}: {run.err}"
    run.error_line(*fragments)
    assert time.perf_counter() - t0 < 5, "refused only after doing work"
    assert snapshot(scratch) == before and entries(scratch) == names
