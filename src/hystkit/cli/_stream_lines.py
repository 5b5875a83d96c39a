"""``hystkit stream``'s input lines one by one: the header, the fields of a ``time,sensor
[,reference]`` line, the checks of its time, and the count of each kind of problem with the
line it first appeared on (the warnings at the end of a stream)."""

from __future__ import annotations

import math
import sys

from ._stream_read import TOO_LONG

__all__ = ["DEFAULT_COLUMNS", "STEP_TOLERANCE", "Columns", "Reading", "Tally", "reference_of"]

# Relative step tolerance of the model's dt, as Compensator.check_sampling.
STEP_TOLERANCE = 0.01

# Kinds of problem whose sample is still compensated, and what happened instead of skipping it.
NOT_SKIPPED = {
    "irregular step": "compensated, but the step differs from the model's dt = {dt:g} s by more "
                      f"than {STEP_TOLERANCE:.0%}",
    "reference not a number": "compensated; the reference ignored",
}

Columns = tuple[int, int, int | None]
# Without a header: time, sensor and (adapting) the reference in this order.
DEFAULT_COLUMNS: Columns = (0, 1, 2)


class Tally:
    """Counts and first line number per kind of problem."""

    def __init__(self) -> None:
        self.count: dict[str, int] = {}
        self.first: dict[str, int] = {}

    def add(self, kind: str, line_no: int, n: int = 1) -> None:
        """`n` lines of this kind, the first at `line_no`."""
        self.count[kind] = self.count.get(kind, 0) + n
        self.first.setdefault(kind, line_no)

    def report(self, source: str, dt: float) -> None:
        for kind, n in self.count.items():
            what = NOT_SKIPPED.get(kind, "skipped").format(dt=dt)
            print(f"hystkit: warning: {source}: {n} line(s) {kind} ({what}; first at line "
                  f"{self.first[kind]})", file=sys.stderr)


class Reading:
    """Where the reading of an input stands: its lines' numbers, the columns (a header may
    name them), the time of the last sample compensated."""

    def __init__(self, time_scale: float) -> None:
        self.line_no = 0
        self.columns: Columns = DEFAULT_COLUMNS
        self.first = True  # no non-empty line yet
        self.previous: float | None = None
        self.time_scale = time_scale

    def parsed(self, line: str, tally: Tally) -> tuple[str, float, float] | None:
        """The next line's ``(time text, time [s], sensor)``, or None (a header, a blank
        line, or a problem counted in `tally`). The time's order is not checked here."""
        self.line_no += 1
        if line is TOO_LONG:
            tally.add("line too long", self.line_no)
            return None
        if not line.strip():
            return None
        if not line.endswith("\n"):  # only the last line can be: cut off mid-write?
            tally.add("unterminated last line", self.line_no)
            return None
        if self.first and (named := _columns(line.split(","))) is not None:
            self.columns, self.first = named, False
            return None
        self.first = False
        parsed = _parse(line, self.columns, self.time_scale)
        if isinstance(parsed, str):
            tally.add(parsed, self.line_no)
            return None
        return parsed

    @staticmethod
    def step_problem(t: float, previous: float | None, dt: float) -> str | None:
        """Why the time `t` after `previous` is a problem: ``time not advancing`` (skipped),
        ``irregular step`` (compensated, counted), or None."""
        if previous is None:
            return None
        if not t > previous:
            return "time not advancing"
        if abs(t - previous - dt) > STEP_TOLERANCE * dt:
            return "irregular step"
        return None


def _columns(fields: list[str]) -> Columns | None:
    """Indices of time, sensor and reference (None: no such column) if ``fields`` is a header
    naming time and sensor, else None."""
    names = [f.strip().lstrip("\ufeff").lower() for f in fields]  # a UTF-8 BOM first
    if "time" in names and "sensor" in names:
        reference = names.index("reference") if "reference" in names else None
        return names.index("time"), names.index("sensor"), reference
    return None


def _parse(line: str, columns: Columns, time_scale: float) -> tuple[str, float, float] | str:
    """``(time text, time [s], sensor)`` or the kind of problem."""
    fields = line.strip().split(",")
    if len(fields) <= max(columns[:2]) or any(not fields[i].strip() for i in columns[:2]):
        return "missing field"
    text = fields[columns[0]].strip()
    try:
        t, s = float(text) * time_scale, float(fields[columns[1]])
    except ValueError:
        return "not a number"
    if not (abs(t) < math.inf and abs(s) < math.inf):  # also NaN
        return "not a number"
    return text, t, s


def reference_of(line: str, columns: Columns) -> float | None:
    """The line's reference [mm]: NaN when absent, empty or ``nan`` (unknown), None when not a
    number or infinite."""
    fields = line.strip().split(",")
    if columns[2] is None or len(fields) <= columns[2] or not fields[columns[2]].strip():
        return float("nan")
    try:
        r = float(fields[columns[2]])
    except ValueError:
        return None
    return r if math.isnan(r) or abs(r) < float("inf") else None
