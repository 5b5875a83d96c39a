"""Golden run: every ``hystkit`` command on fixed inputs, and a comparison of two such runs.

Issue 28 item 6: record one before the first move of a redesign and one after the last; the
outputs must be the same except timings. This is a before/after tool, not a test and not a
benchmark (it times nothing it compares), hence ``tools/`` and not ``benchmarks/`` or ``tests/``.

    python tools/golden_run.py record OUT [--rev REV | --src DIR] [--numba-cache DIR] [--force]
    python tools/golden_run.py compare A B [--commands export,fit] [--lines N]
    python tools/golden_run.py normalise OUT    (rebuild OUT/golden from OUT/raw and OUT/work)

``record`` runs ``python -m hystkit`` of a source tree (``--rev``: ``git archive REV src``
extracted into OUT/src, so a dirty checkout shared with others does not leak in; ``--src``: that
``src`` folder; default: this checkout's ``src``) in OUT/work, with relative paths and fixed
seeds: the virtual sensor's recordings, the shipped dataset excerpt, every model family fitted
and exported (C, C double, MATLAB), and each subcommand listed by ``hystkit --help`` once or a
few times on small inputs (about 4 minutes on 2 cores with numba's cache filled; ``warm`` runs
first, so the compiling happens there). A subcommand with no recipe here is recorded as such,
and ``compare`` then reports it. Output files stay in OUT/work, stdout and stderr in OUT/raw,
the steps in OUT/run.json; OUT/golden holds, per step, its exit code, stdout, stderr and each
output file normalised to text:

* absolute paths: OUT/work -> ``<WORK>``, the source tree -> ``<SRC>``, numba's cache folder ->
  ``<NUMBA_CACHE>``;
* hystkit's compiling notice on stderr (present or not depending on numba's cache) is dropped;
* timings: JSON keys in `TIMING_KEYS` -> ``<T>``; in text, a number in `TIMING_PATTERNS`
  (``done in 0.05 s``, ``(8.2 s)``, ``1.3 s (about 7 s left)``, ...) -> ``<T>``, and the
  ``compile s`` / ``simulation s`` columns of ``control``'s table;
* versions: JSON ``hystkit_version`` and the text ``hystkit X.Y.Z`` -> ``<VERSION>``;
* wall-clock dates ``YYYY-MM-DD HH:MM[:SS]`` (an export's time, a model file's mtime) ->
  ``<DATE>``; a temporary folder's random suffix (``.tmp-XXXXXXXX``) -> ``<RANDOM>``;
* binary files: Parquet -> its columns, dtypes and every value (repr); .mat -> every variable
  (the header, which holds the creation time, is left out); PNG and other binaries -> SHA-256;
  base64 images inside HTML -> the SHA-256 of their bytes; SVG/PDF dates -> ``<DATE>`` and
  matplotlib's random SVG clip-path ids -> ``<ID>``; a file without a known suffix is text
  when it is UTF-8 (an export's README).

Nothing else is touched: a changed number, word or file is a difference. Not normalised yet
(they show as differences between two runs of one revision): ``compare``'s and
``pl-search``'s seconds columns, ``fit_seconds`` inside .mat files, ``batch``'s fit-seconds
column and the recordings' mtimes in its sensor files. ``compare`` prints,
per command, ``same`` or ``differs`` with the first differing lines of each differing step, and
exits 1 if anything differs.
"""

from __future__ import annotations

import argparse
import base64
import difflib
import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
import tarfile
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
TEXT_SUFFIXES = {".csv", ".txt", ".c", ".h", ".m", ".md", ".toml", ".html", ".svg", ".log"}
TIMING_KEYS = {
    "fit_seconds", "seconds", "elapsed", "elapsed_seconds", "wall_seconds", "compile_seconds",
    "simulation_seconds", "run_seconds", "total_seconds", "cpu_seconds",
}
_NUM = r"\d+(?:\.\d+)?(?:e[+-]?\d+)?"
TIMING_PATTERNS = [
    re.compile(rf"(done in |took |in )({_NUM})( ?s\b)"),
    re.compile(rf"(\()({_NUM})( ?s\))"),
    re.compile(rf"(: )({_NUM})( s \(about )({_NUM})( s left\))"),
    re.compile(rf"(: )({_NUM})( s)$", re.MULTILINE),
    re.compile(rf"(about )({_NUM})( s left)"),
    re.compile(rf"(\()({_NUM})( s, )({_NUM})( M samples/s)"),  # preprocess's throughput
    re.compile(rf"(median )({_NUM})( µs, p99 )({_NUM})( µs, max )({_NUM})( µs)"),  # stream
]
COMPILE_NOTICE = re.compile(r"^hystkit: compiling numba kernels.*\n?", re.MULTILINE)
VERSION_TEXT = re.compile(r"(hystkit )\d+\.\d+\.\d+\S*")
DATE_TEXT = re.compile(r"(<dc:date>|/CreationDate \(|/ModDate \()[^<)]*")
CLOCK_TEXT = re.compile(r"\d{4}-\d{2}-\d{2}[ T]\d{2}:\d{2}(?::\d{2}(?:\.\d+)?)?")
TEMP_NAME = re.compile(r"(\.tmp-)[A-Za-z0-9_]{8}\b")  # tempfile.mkdtemp's suffix
SVG_ID = re.compile(r"(url\(#|id=\"|xlink:href=\"#)[pm][0-9a-f]{10}")  # matplotlib's random ids
DATA_URI = re.compile(r"data:(image/[a-z+]+);base64,([A-Za-z0-9+/=]+)")


# ---------------------------------------------------------------------------------- record


@dataclass
class Recorder:
    """Runs steps in `work` with the source tree `src` and writes their normalised golden files."""

    out: Path
    src: Path
    numba_cache: Path
    steps: list[dict] = field(default_factory=list)

    @property
    def work(self) -> Path:
        return self.out / "work"

    def run(self, command: str, name: str, argv: list[str], outputs: tuple[str, ...] = ()) -> int:
        env = dict(os.environ, PYTHONPATH=str(self.src), NUMBA_CACHE_DIR=str(self.numba_cache),
                   MPLBACKEND="Agg", PYTHONHASHSEED="0")
        env.pop("HYSTKIT_SHARED_DATA", None)
        started = time.perf_counter()
        done = subprocess.run([sys.executable, "-m", "hystkit", *argv], cwd=self.work, env=env,
                              capture_output=True, text=True, stdin=subprocess.DEVNULL, check=False)
        seconds = time.perf_counter() - started
        raw = self.out / "raw" / command / name
        raw.mkdir(parents=True, exist_ok=True)
        (raw / "stdout.txt").write_text(done.stdout)
        (raw / "stderr.txt").write_text(done.stderr)
        step = {"command": command, "name": name, "argv": argv, "outputs": list(outputs),
                "exit": done.returncode, "seconds": round(seconds, 2)}
        self.steps.append(step)
        self.normalise_step(step)
        print(f"  {command:18s} {name:34s} exit {done.returncode}  {seconds:6.1f} s", flush=True)
        return done.returncode

    def normalise_step(self, step: dict) -> None:
        """OUT/golden/<command>/<name>/ from the step's raw stdout, stderr and output files."""
        raw = self.out / "raw" / step["command"] / step["name"]
        folder = self.out / "golden" / step["command"] / step["name"]
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "argv.txt").write_text(" ".join(step["argv"]) + "\n")
        (folder / "exit.txt").write_text(f"{step['exit']}\n")
        (folder / "stdout.txt").write_text(self.text((raw / "stdout.txt").read_text()))
        stderr = COMPILE_NOTICE.sub("", (raw / "stderr.txt").read_text())
        (folder / "stderr.txt").write_text(self.text(stderr))
        for output in step["outputs"]:
            self.keep(self.work / output, folder / "files" / output)

    def text(self, text: str) -> str:
        for path, label in ((self.work, "<WORK>"), (self.src, "<SRC>"),
                            (self.numba_cache, "<NUMBA_CACHE>")):
            text = text.replace(str(path.resolve()), label).replace(str(path), label)
        for pattern in TIMING_PATTERNS:
            text = pattern.sub(_timing_groups, text)
        text = _control_timing_columns(text)
        text = VERSION_TEXT.sub(r"\1<VERSION>", text)
        text = CLOCK_TEXT.sub("<DATE>", text)
        text = TEMP_NAME.sub(r"\1<RANDOM>", text)
        return DATE_TEXT.sub(r"\1<DATE>", text)

    def keep(self, path: Path, target: Path) -> None:
        if path.is_dir():
            for child in sorted(path.rglob("*")):
                if child.is_file():
                    self.keep(child, target / child.relative_to(path))
            return
        target.parent.mkdir(parents=True, exist_ok=True)
        if not path.exists():
            target.with_name(target.name + ".missing").write_text("not written\n")
            return
        target.with_name(target.name + ".txt").write_text(self.normalise_file(path))

    def normalise_file(self, path: Path) -> str:
        suffix = path.suffix.lower()
        if suffix == ".json":
            return self.text(json.dumps(_without_timings(json.loads(path.read_text())),
                                        indent=1) + "\n")
        if suffix == ".parquet":
            return self.text(_parquet_text(path))
        if suffix == ".mat":
            return self.text(_mat_text(path))
        data = path.read_bytes()
        if suffix in TEXT_SUFFIXES or (b"\0" not in data and _is_utf8(data)):  # README too
            text = data.decode("utf-8", errors="replace")
            return self.text(SVG_ID.sub(r"\1<ID>", DATA_URI.sub(_hash_data_uri, text)))
        return f"sha256 {hashlib.sha256(path.read_bytes()).hexdigest()}  {path.stat().st_size} bytes\n"


def _is_utf8(data: bytes) -> bool:
    try:
        data.decode("utf-8")
    except UnicodeDecodeError:
        return False
    return True


def _timing_groups(match: re.Match) -> str:
    # Every even group (2, 4, ...) of a timing pattern is a number of seconds.
    return "".join("<T>" if i % 2 == 0 else (g or "")
                   for i, g in enumerate(match.groups(), start=1))


def _control_timing_columns(text: str) -> str:
    """The last two columns of control's table ('compile s', 'simulation s') are timings."""
    lines = text.split("\n")
    in_table = False
    for i, line in enumerate(lines):
        if line.rstrip().endswith("compile s  simulation s"):
            in_table = True
            continue
        if in_table:
            fields = line.split()
            if len(fields) < 3:
                in_table = False
                continue
            lines[i] = re.sub(rf"\s+{_NUM}\s+{_NUM}\s*$", "  <T>  <T>", line)
    return "\n".join(lines)


def _without_timings(value):
    if isinstance(value, dict):
        return {key: ("<T>" if key in TIMING_KEYS and isinstance(item, (int, float))
                      else "<VERSION>" if key == "hystkit_version" else _without_timings(item))
                for key, item in value.items()}
    if isinstance(value, list):
        return [_without_timings(item) for item in value]
    return value


def _hash_data_uri(match: re.Match) -> str:
    digest = hashlib.sha256(base64.b64decode(match.group(2))).hexdigest()
    return f"data:{match.group(1)};sha256,{digest}"


def _parquet_text(path: Path) -> str:
    import pandas as pd

    frame = pd.read_parquet(path)
    lines = [f"{name}: {dtype}" for name, dtype in frame.dtypes.items()]
    lines += [",".join(repr(v) for v in row) for row in frame.itertuples(index=False)]
    return "\n".join(lines) + "\n"


def _mat_text(path: Path) -> str:
    import numpy as np
    import scipy.io

    lines = []
    with np.printoptions(threshold=sys.maxsize, precision=17, linewidth=100):
        for name, value in sorted(scipy.io.loadmat(path).items()):
            if not name.startswith("__"):
                lines.append(f"{name} = {value!r}")
    return "\n".join(lines) + "\n"


def _source_tree(out: Path, rev: str | None, src: Path | None) -> Path:
    if rev is None:
        return (src or REPO / "src").resolve()
    archive = subprocess.run(["git", "-C", str(REPO), "archive", rev, "src"], check=True,
                             capture_output=True).stdout
    with tempfile.TemporaryFile() as handle:
        handle.write(archive)
        handle.seek(0)
        with tarfile.open(fileobj=handle) as tar:
            tar.extractall(out, filter="data")
    return (out / "src").resolve()


def _listed(recorder: Recorder, argv: list[str], pattern: str) -> list[str]:
    env = dict(os.environ, PYTHONPATH=str(recorder.src))
    helptext = subprocess.run([sys.executable, "-m", "hystkit", *argv], env=env,
                              capture_output=True, text=True, check=True).stdout
    return re.search(pattern, helptext).group(1).split(",")


def record(recorder: Recorder) -> list[str]:
    """Every step, in order: later steps read what earlier ones wrote. Returns the subcommands
    of ``hystkit --help`` that no step ran."""
    subcommands = _listed(recorder, ["--help"], r"\{([a-z0-9,.-]+)\}")
    families = _listed(recorder, ["fit", "--help"], r"--model \{([a-z0-9,_-]+)\}")
    run = recorder.run
    recorder.work.mkdir(parents=True)
    run("help", "version", ["--version"])
    run("help", "help", ["--help"])
    for sub in subcommands:
        run("help", sub, [sub, "--help"])
    done = set()

    done.add("warm")
    run("warm", "all", ["warm"])

    done.add("simulate-sensor")
    run("simulate-sensor", "sine", ["simulate-sensor", "--excitation", "sine", "--seed", "1",
                                    "--out", "sine.csv"], ("sine.csv",))
    run("simulate-sensor", "noise", ["simulate-sensor", "--excitation", "noise", "--seed", "2",
                                     "--out", "noise.csv"], ("noise.csv",))
    run("simulate-sensor", "chirp-drift-refs",
        ["simulate-sensor", "--excitation", "chirp", "--seed", "3", "--gain-drift", "0.1",
         "--references-every", "5", "--out", "drift.csv"], ("drift.csv",))
    run("simulate-sensor", "raw",
        ["simulate-sensor", "--excitation", "sine", "--seed", "4", "--raw", "--scope-rate", "2e4",
         "--duration", "20", "--truth", "truth.csv", "--out", "raw.csv"],
        ("raw.csv", "raw.toml", "truth.csv"))

    done.add("simulate-settling")
    run("simulate-settling", "day", ["simulate-settling", "--hours", "24", "--interval", "10",
                                     "--seed", "0", "--out", "settling_log.csv"],
        ("settling_log.csv",))
    done.add("settling")
    run("settling", "auto", ["settling", "settling_log.csv", "--out", "settling"], ("settling",))

    done.add("preprocess")
    run("preprocess", "raw", ["preprocess", "raw.csv", "--out", "pre.csv"],
        ("pre.csv", "pre.json"))
    done.add("spectrum")
    run("spectrum", "raw", ["spectrum", "raw.csv", "--out", "spectrum_raw"], ("spectrum_raw",))
    run("spectrum", "recording", ["spectrum", "sine.csv", "--out", "spectrum_rec"],
        ("spectrum_rec",))
    done.add("cycles")
    run("cycles", "recording", ["cycles", "sine.csv", "--out", "cycles"], ("cycles",))
    run("cycles", "raw", ["cycles", "--raw", "raw.csv", "--out", "cycles_raw"], ("cycles_raw",))

    done.add("datasets")
    run("datasets", "list", ["datasets", "list"])
    run("datasets", "show", ["datasets", "show", "piezo_micromanipulator"])
    run("datasets", "export-excerpt",
        ["datasets", "export", "piezo_micromanipulator", "--excerpt", "--out", "piezo.csv"],
        ("piezo.csv", "piezo.json"))

    done.add("fit")
    run("fit", "default-model", ["fit", "sine.csv", "--out", "fit_default.json"],
        ("fit_default.json",))
    run("fit", "mpl-2-band", ["fit", "sine.csv", "--model", "mpl", "--cells", "2",
                              "--out", "mpl_band.json"], ("mpl_band.json",))
    run("fit", "mpl-inverse", ["fit", "sine.csv", "--model", "mpl", "--mode", "inverse",
                               "--no-band", "--out", "mpl_inverse.json"], ("mpl_inverse.json",))
    run("fit", "pl-mat", ["fit", "sine.csv", "--model", "pl", "--no-band", "--out", "pl.mat"],
        ("pl.mat",))
    run("fit", "piezo-excerpt", ["fit", "piezo.csv", "--model", "mpl", "--no-band",
                                 "--out", "piezo_mpl.json"], ("piezo_mpl.json",))
    for family in families:
        run("fit", family, ["fit", "sine.csv", "--model", family, "--no-band",
                            "--out", f"models/{family}.json"], (f"models/{family}.json",))

    done.add("export")
    run("export", "missing-parent", ["export", "models/mpl.json", "--out", "nested/export/mpl"],
        ("nested",))
    for family in families:
        for lang, extra in (("c", []), ("c-double", ["--double"]), ("matlab", [])):
            run("export", f"{family}-{lang}",
                ["export", f"models/{family}.json", "--lang", lang.split("-")[0], *extra,
                 "--out", f"export_{lang}_{family}"], (f"export_{lang}_{family}",))
    run("export", "mpl-band-c", ["export", "mpl_band.json", "--out", "export_band_c"],
        ("export_band_c",))
    run("export", "mpl-band-matlab", ["export", "mpl_band.json", "--lang", "matlab",
                                      "--level", "0.8", "--out", "export_band_matlab"],
        ("export_band_matlab",))
    run("export", "mpl-inverse-c", ["export", "mpl_inverse.json", "--name", "inv",
                                    "--out", "export_inverse_c"], ("export_inverse_c",))

    done.add("evaluate")
    run("evaluate", "mpl-band", ["evaluate", "mpl_band.json", "noise.csv", "--json", "eval.json",
                                 "--out", "eval.mat"], ("eval.json", "eval.mat"))
    run("evaluate", "pl-mat", ["evaluate", "pl.mat", "noise.csv"])
    done.add("compensate")
    run("compensate", "mpl-band", ["compensate", "mpl_band.json", "noise.csv",
                                   "--out", "compensated.csv"], ("compensated.csv",))
    done.add("stability")
    run("stability", "mpl", ["stability", "models/mpl.json", "--json", "stability.json"],
        ("stability.json",))
    run("stability", "control", ["stability", "--control", "--scheme", "direct",
                                 "--sensor-size", "1", "--model-size", "1"])
    done.add("stream")
    run("stream", "band", ["stream", "mpl_band.json", "--in", "noise.csv"])
    run("stream", "adapt-gain", ["stream", "models/mpl.json", "--in", "drift.csv",
                                 "--adapt", "gain"])

    done.add("compare")
    run("compare", "mpl-pi", ["compare", "sine.csv", "noise.csv", "--models", "mpl,pi",
                              "--workers", "1", "--out", "compare"], ("compare",))
    done.add("generalize")
    run("generalize", "mpl", ["generalize", "sine.csv", "noise.csv", "--models", "mpl",
                              "--workers", "1", "--out", "generalize"], ("generalize",))
    done.add("select")
    run("select", "mpl-fit", ["select", "sine.csv", "--models", "mpl", "--centers", "fit",
                              "--workers", "1", "--out", "select.json"],
        ("select.json", "select-selection"))
    done.add("pl-search")
    run("pl-search", "one", ["pl-search", "sine.csv", "--n", "1", "--p", "21", "--m", "1",
                             "--s", "0.001", "--workers", "1", "--json", "pl_search.json"],
        ("pl_search.json",))
    done.add("batch")
    (recorder.work / "batch_in").mkdir()
    shutil.copy(recorder.work / "sine.csv", recorder.work / "batch_in" / "sensor_a.csv")
    run("batch", "folder", ["batch", "batch_in", "--workers", "1", "--out", "batch"],
        ("batch",))

    done.add("control")
    run("control", "direct-sine", ["control", "--scheme", "direct", "--sensor-size", "1",
                                   "--model-size", "1", "--experiment", "sine",
                                   "--out", "control"], ("control",))
    done.add("creep")
    run("creep", "quick", ["creep", "--quick", "--models", "mpl", "--out", "creep"], ("creep",))
    done.add("table")
    run("table", "5.4-quick", ["table", "5.4", "--quick", "--out", "table_5_4"], ("table_5_4",))
    run("table", "2.2-quick", ["table", "2.2", "--quick", "--models", "mpl",
                               "--out", "table_2_2"], ("table_2_2",))
    done.add("demo")
    run("demo", "one-cell", ["demo", "--cells", "1", "--out", "demo"], ("demo",))
    done.add("report")
    run("report", "model", ["report", "mpl_band.json", "noise.csv", "--out", "report.html"],
        ("report.html",))
    run("report", "compare", ["report", "compare", "--out", "report_compare.html"],
        ("report_compare.html",))

    no_recipe = [sub for sub in subcommands if sub not in done]
    _no_recipes(recorder, no_recipe)
    return no_recipe


def _no_recipes(recorder: Recorder, subcommands: list[str]) -> None:
    for sub in subcommands:
        folder = recorder.out / "golden" / sub / "no-recipe"
        folder.mkdir(parents=True)
        (folder / "exit.txt").write_text("no recipe in tools/golden_run.py\n")
        print(f"  {sub:18s} no recipe", flush=True)


# --------------------------------------------------------------------------------- compare


_NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")


def same_within(text_a: str, text_b: str, rtol: float) -> bool:
    """Whether two texts are the same but for numbers that agree to `rtol` relative (the words,
    the punctuation and the count of numbers the same): rounding-level changes of a kernel, a
    fit that ends a few ulps elsewhere. Integers are compared the same way."""
    if _NUMBER.sub("#", text_a) != _NUMBER.sub("#", text_b):
        return False
    for x, y in zip(_NUMBER.findall(text_a), _NUMBER.findall(text_b), strict=True):
        u, v = float(x), float(y)
        if abs(u - v) > rtol * max(abs(u), abs(v)):
            return False
    return True


def compare(a: Path, b: Path, commands: set[str] | None, lines: int,
            rtol: float = 0.0) -> bool:
    """Print per command: same, or differs with the first differing lines; True if all same.
    With `rtol`, files whose numbers agree to it count as the same (said per command)."""
    golden_a, golden_b = a / "golden", b / "golden"
    names = sorted({p.name for p in golden_a.iterdir()} | {p.name for p in golden_b.iterdir()})
    all_same = True
    for command in names:
        if commands and command not in commands:
            continue
        files_a = _files(golden_a / command)
        files_b = _files(golden_b / command)
        differing, close = [], 0
        for rel in sorted(set(files_a) | set(files_b)):
            if rel not in files_a or rel not in files_b:
                differing.append((rel, [f"only in {'B' if rel in files_b else 'A'}"]))
            elif rtol and files_a[rel] != files_b[rel] and same_within(files_a[rel],
                                                                        files_b[rel], rtol):
                close += 1
            elif files_a[rel] != files_b[rel]:
                diff = difflib.unified_diff(files_a[rel].splitlines(), files_b[rel].splitlines(),
                                            "A", "B", n=0, lineterm="")
                differing.append((rel, [d for d in diff if not d.startswith(("---", "+++"))]))
        within = f", {close} of them only within rtol {rtol:g}" if close else ""
        if not differing:
            print(f"{command}: same ({len(files_a)} files{within})")
            continue
        all_same = False
        steps = sorted({rel.split("/")[0] for rel, _ in differing})
        print(f"{command}: differs in {len(differing)} of {len(set(files_a) | set(files_b))} "
              f"files (steps: {', '.join(steps)}){within}")
        for rel, diff in differing:
            print(f"  {rel}")
            for line in diff[:lines]:
                print(f"    {line[:160]}")
            if len(diff) > lines:
                print(f"    ... {len(diff) - lines} more diff lines")
    return all_same


def _files(folder: Path) -> dict[str, str]:
    if not folder.exists():
        return {}
    return {str(p.relative_to(folder)): p.read_text() for p in sorted(folder.rglob("*"))
            if p.is_file()}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="action", required=True)
    rec = sub.add_parser("record", help="run every command into OUT")
    rec.add_argument("out", type=Path)
    which = rec.add_mutually_exclusive_group()
    which.add_argument("--rev", help="git revision to run (git archive into OUT/src)")
    which.add_argument("--src", type=Path, help="src folder to run (default: this checkout's)")
    rec.add_argument("--numba-cache", type=Path, default=Path("/tmp/hystkit-golden-numba"),
                     help="numba's cache folder (kept between runs; default %(default)s)")
    rec.add_argument("--force", action="store_true", help="replace OUT if it exists")
    cmp = sub.add_parser("compare", help="compare two recorded folders")
    cmp.add_argument("a", type=Path)
    cmp.add_argument("b", type=Path)
    cmp.add_argument("--commands", help="comma-separated commands to compare (default: all)")
    cmp.add_argument("--lines", type=int, default=6, help="diff lines shown per file")
    cmp.add_argument("--rtol", type=float, default=0.0,
                     help="count files whose numbers agree to this relative tolerance as the "
                          "same (default 0: exact)")
    again = sub.add_parser("normalise", help="rebuild OUT/golden (after changing the rules)")
    again.add_argument("out", type=Path)
    args = parser.parse_args()

    if args.action == "normalise":
        out = args.out.resolve()
        run = json.loads((out / "run.json").read_text())
        recorder = Recorder(out, Path(run["src"]), Path(run["numba_cache"]))
        shutil.rmtree(out / "golden")
        for step in run["steps"]:
            recorder.normalise_step(step)
        _no_recipes(recorder, run["no_recipe"])
        return 0
    if args.action == "compare":
        commands = set(args.commands.split(",")) if args.commands else None
        return 0 if compare(args.a, args.b, commands, args.lines, args.rtol) else 1
    out = args.out.resolve()
    if out.exists():
        if not args.force:
            print(f"golden_run: {out} exists (use --force to replace it)", file=sys.stderr)
            return 2
        shutil.rmtree(out)
    out.mkdir(parents=True)
    src = _source_tree(out, args.rev, args.src)
    recorder = Recorder(out, src, args.numba_cache.resolve())
    started = time.perf_counter()
    no_recipe = record(recorder)
    rev = subprocess.run(["git", "-C", str(REPO), "rev-parse", args.rev or "HEAD"],
                         capture_output=True, text=True, check=False).stdout.strip()
    (out / "run.json").write_text(json.dumps(
        {"rev": rev if args.rev else f"{rev} (working tree {src})", "python": sys.version,
         "src": str(src), "numba_cache": str(recorder.numba_cache),
         "seconds": round(time.perf_counter() - started, 1), "no_recipe": no_recipe,
         "steps": recorder.steps}, indent=1) + "\n")
    print(f"recorded {len(recorder.steps)} steps into {out} "
          f"in {time.perf_counter() - started:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
