"""How a CSV file is laid out: separator, decimal mark, comment lines before the header.

Labs write CSV files in more than one way: Excel in most of Europe separates fields with ``;``
and writes ``1,5``; loggers put ``# instrument ...`` lines above the header; some programs
separate with tabs. `csv_layout` looks at the first `SAMPLE_BYTES` of the file and decides,
for what `ReadOptions` leaves at ``auto``:

- comment lines: the leading lines that start with ``#`` (and blank lines among them) come
  before the header and are skipped. When the line after them is already data (numbers
  only), the last comment line is the header (``numpy.savetxt(..., header="time,position,
  sensor")`` writes ``# time,position,sensor``), provided it has as many fields;
- separator: the one of ``,`` ``;`` tab that splits the header and the first `SAMPLE_LINES`
  data lines into the same number (at least 2) of fields. When none does (a damaged line),
  the header's most frequent one, and the readers name the line that disagrees; when two do,
  the file is refused with the line and the ``--sep`` to pass;
- decimal mark: a comma when the separator is not one and the recording's cells in the
  sampled bytes write numbers as ``1,5`` (never ``1.5``); a file mixing both is refused,
  naming a line of each and ``--decimal``. Integers alone say nothing: a point is assumed,
  and a ``1,5`` further down is refused with the hint to pass ``--decimal ','``.

Pure Python: it runs on every CSV recording before pandas is needed.
"""

from __future__ import annotations

import csv
import re
from dataclasses import dataclass
from pathlib import Path

from .._read_options import FIELDS, ReadOptions
from ._cells import Where

__all__ = ["CsvLayout", "csv_layout"]

SAMPLE_BYTES = 1 << 16  # read from the start of the file; the header must end within it
SAMPLE_LINES = 50  # data lines whose field counts must agree with the header's
MAX_COLUMNS = 1000  # a wider file is not a recording; pandas would build a column per field
SEP_NAMES = {",": "comma", ";": "semicolon", "\t": "tab"}
_SEP_OPTION = {",": "','", ";": "';'", "\t": "tab"}
COMMA_NUMBER = re.compile(r"[+-]?(\d+,\d*|,\d+)([eE][+-]?\d+)?")
POINT_NUMBER = re.compile(r"[+-]?(\d+\.\d*|\.\d+)([eE][+-]?\d+)?")
# A cell of a data line (either decimal mark, nan, inf, or empty), not a column name
_DATA_CELL = re.compile(r"[+-]?(\d+([.,]\d*)?|[.,]\d+)([eE][+-]?\d+)?|[+-]?(nan|inf)|",
                        re.IGNORECASE)


@dataclass(frozen=True)
class CsvLayout:
    """Where a CSV file's header is and how its fields and numbers are written.

    Parameters
    ----------
    sep : str
        Field separator: ``,``, ``;`` or a tab.
    decimal : str
        Decimal mark: ``.`` or ``,`` (only with another separator).
    preamble : int
        Lines before the header (``#`` comments and blank lines among them).
    detected : tuple of str
        What was found rather than given (``"sep"``, ``"decimal"``, ``"preamble"``).
    comment_header : bool
        The header is a comment line (``# time,position,sensor``, as ``numpy.savetxt``
        writes it): line ``preamble + 1``, whose ``#`` `names` drops.
    """

    sep: str = ","
    decimal: str = "."
    preamble: int = 0
    detected: tuple[str, ...] = ()
    comment_header: bool = False

    def names(self, fields: list[object]) -> list[str]:
        """The column names of the header's `fields` as split: stripped, and without the
        ``#`` of a header written as a comment."""
        names = [str(field).strip() for field in fields]
        if self.comment_header and names:
            names[0] = names[0].lstrip("#").strip()
        return names

    def notice(self) -> str:
        """What was found that a plain comma-separated file would not have, in a few words
        (``"semicolon-separated, decimal comma, 2 comment lines skipped"``); "" for none."""
        parts = []
        if "sep" in self.detected and self.sep != ",":
            parts.append(f"{SEP_NAMES[self.sep]}-separated")
        if "decimal" in self.detected and self.decimal == ",":
            parts.append("decimal comma")
        if self.preamble:
            parts.append(f"{self.preamble} comment line{'s' * (self.preamble > 1)} before "
                         "the header skipped")
        if self.comment_header:
            parts.append(f"the header read from the comment on line {self.preamble + 1}")
        return ", ".join(parts)


def csv_layout(path: str | Path, options: ReadOptions | None = None,
               where: Where | None = None) -> CsvLayout:
    """The layout of CSV file `path`: what `options` gives, the rest detected.

    Parameters
    ----------
    path : str or path-like
        The CSV recording.
    options : ReadOptions, optional
        ``sep`` and ``decimal`` other than ``auto`` are taken as given; ``columns``,
        ``units_row`` and ``skip_rows`` say which lines and cells hold numbers.
    where : Where, optional
        The error locator (for the column names in messages); by default the file's.

    Returns
    -------
    CsvLayout

    Raises
    ------
    InputError
        A header line longer than `SAMPLE_BYTES` or wider than `MAX_COLUMNS` fields; only
        comment lines; two separators that both fit, or numbers written with both decimal
        marks: one line naming the file, the line and the option to pass.

    Examples
    --------
    >>> from pathlib import Path
    >>> _ = Path("eu.csv").write_text("# rig 3\\nt_ms;x_mm;R\\n0;0,5;100,25\\n20;0,75;100,5\\n")
    >>> csv_layout("eu.csv").notice()
    'semicolon-separated, decimal comma, 1 comment line before the header skipped'
    """
    options = ReadOptions() if options is None else options
    where = Where(str(path), names=options.columns) if where is None else where
    lines = _head_lines(Path(path), where)
    if not lines:
        return CsvLayout()  # an empty file: the readers say so
    preamble = _preamble(lines)
    if preamble == len(lines):
        raise where.fail(f"line {preamble}: only comment lines, no header naming the columns")
    comment_header = _comment_header(lines, preamble, options.units_row + options.skip_rows)
    if comment_header:
        preamble -= 1  # the header is the last comment line, the data follow it
    header = lines[preamble].lstrip().lstrip("#") if comment_header else lines[preamble]
    first_data = preamble + 1 + options.units_row + options.skip_rows  # 0-based line index
    body = [(i, line) for i, line in enumerate(lines[first_data:], start=first_data)
            if line.strip()]
    sample = body[:SAMPLE_LINES]
    detected = ["preamble"] if preamble else []
    detected += ["comment_header"] if comment_header else []
    sep = options.sep
    if sep == "auto":
        sep = _separator(header, sample, preamble, where)
        detected.append("sep")
    fields = _split(header, sep)
    if len(fields) > MAX_COLUMNS:
        raise where.fail(f"the header line has {len(fields)} fields; a recording has at most "
                         f"{MAX_COLUMNS} columns")
    decimal = options.decimal
    if decimal == "auto":
        decimal = "." if sep == "," else _decimal(fields, body, sep, where)
        detected.append("decimal")
    return CsvLayout(sep, decimal, preamble, tuple(detected), comment_header)


def _head_lines(path: Path, where: Where) -> list[str]:
    """The complete lines among the first `SAMPLE_BYTES` of the file (a BOM dropped; bytes
    that are not UTF-8 replaced: the readers name them)."""
    with path.open("rb") as file:
        head = file.read(SAMPLE_BYTES)
    text = head.decode("utf-8-sig", errors="replace")
    lines = text.splitlines()
    if len(head) == SAMPLE_BYTES and not text.endswith(("\n", "\r")):
        if len(lines) <= 1:
            raise where.fail(f"the header line is longer than {SAMPLE_BYTES} bytes; this is "
                             "not a recording")
        lines.pop()  # cut off by the sample
    return lines


def _preamble(lines: list[str]) -> int:
    """Leading lines before the header: ``#`` comments, and blank lines among them (without a
    comment, a blank first line is the file's own problem, reported as such)."""
    n = 0
    while n < len(lines) and (not lines[n].strip() or lines[n].lstrip().startswith("#")):
        n += 1
    return n if any(line.lstrip().startswith("#") for line in lines[:n]) else 0


def _comment_header(lines: list[str], preamble: int, after: int = 0) -> bool:
    """Whether the last of the `preamble` comment lines is the header: the first line of
    data below it (past `after` lines: a units line, skipped lines) holds only numbers (no
    header of its own follows) and, split by some separator, as many fields as the comment."""
    first = preamble + after
    if not preamble or first >= len(lines) or not lines[preamble - 1].lstrip().startswith("#"):
        return False
    comment = lines[preamble - 1].lstrip().lstrip("#")
    for sep in SEP_NAMES:
        fields = [field.strip() for field in _split(lines[first], sep)]
        if (len(fields) >= 2 and all(_DATA_CELL.fullmatch(field) for field in fields)
                and any(fields) and len(_split(comment, sep)) == len(fields)):
            return True
    return False


def _split(line: str, sep: str) -> list[str]:
    """The fields of one line (quotes as pandas reads them)."""
    return next(csv.reader([line], delimiter=sep), [])


def _separator(header: str, sample: list[tuple[int, str]], preamble: int, where: Where) -> str:
    """The separator that splits the header and every sampled line alike (see the module)."""
    counts = {sep: len(_split(header, sep)) for sep in SEP_NAMES}
    fitting = [sep for sep, n in counts.items()
               if n >= 2 and all(len(_split(line, sep)) == n for _, line in sample)]
    if len(fitting) == 1:
        return fitting[0]
    if len(fitting) > 1:
        names = " and ".join(SEP_NAMES[sep] for sep in fitting)
        passes = " or ".join(f"--sep {_SEP_OPTION[sep]}" for sep in fitting)
        raise where.fail(f"line {preamble + 1}: cannot tell the field separator: {names} each "
                         f"split the header and the {len(sample)} line(s) below it alike; pass "
                         f"{passes} (or sep = \"...\" in the settings file)")
    most = max(counts.values())
    if most > 1 and list(counts.values()).count(most) > 1:
        tied = " and ".join(SEP_NAMES[sep] for sep, n in counts.items() if n == most)
        raise where.fail(f"line {preamble + 1}: cannot tell the field separator: the header "
                         f"has as many of {tied} and the lines below it fit neither; pass --sep")
    # The header decides; the readers name the first line whose fields do not match it.
    return max(counts, key=counts.__getitem__)


def _sep_setting(sep: str) -> str:
    return "tab" if sep == "\t" else sep


def _decimal(fields: list[str], sample: list[tuple[int, str]], sep: str, where: Where) -> str:
    """``,`` when the recording's cells in `sample` (line index, line) write numbers with a decimal comma and
    none with a point, else ``.``; both: refused."""
    names = [name.strip() for name in fields]
    columns = [names.index(where.name(f)) for f in FIELDS if where.name(f) in names]
    comma = point = None
    for line_no, line in sample:
        cells = _split(line, sep)
        for j in columns or range(len(cells)):
            cell = cells[j].strip() if j < len(cells) else ""
            if comma is None and COMMA_NUMBER.fullmatch(cell):
                comma = (line_no + 1, cell)
            elif point is None and POINT_NUMBER.fullmatch(cell):
                point = (line_no + 1, cell)
    if comma is not None and point is not None:
        raise where.fail(f"cannot tell the decimal mark: line {comma[0]} writes {comma[1]!r}, "
                         f"line {point[0]} {point[1]!r}; pass --decimal ',' or --decimal '.' "
                         "(or decimal = \",\" in the settings file)")
    return "," if comma is not None else "."
