"""``hystkit stream``'s input in chunks: each read takes what the input holds at that moment
(up to ``CHUNK_BYTES``) and never waits for more.

A chunk is text: a run of whole lines (each ended by ``"\\n"``, none of ``MAX_LINE`` characters
or more), the marker ``TOO_LONG`` for a longer line (never held in memory), or, last, a line
without its line end as it is (cut off mid-write). A file or a fast pipe gives chunks of
thousands of lines that the stream parses at once; a live sensor's line is a chunk of one as
soon as it arrives. A serial port gives one line per chunk.
"""

from __future__ import annotations

import codecs
import io
import sys
from collections.abc import Callable, Iterator
from typing import TYPE_CHECKING

from ..errors import InputError
from ._stream_defaults import DEFAULT_BAUD, SERIAL_HINT

if TYPE_CHECKING:
    from ._stream_options import StreamOptions

__all__ = ["CHUNK_BYTES", "MAX_LINE", "TOO_LONG", "Input",
           "bounded", "decoded", "line_chunks", "lines_of", "open_input"]

# A longer line is no "time,sensor" pair: skipped without holding it in memory.
MAX_LINE = 4096
# At most this many bytes per read: what a pipe holds at once, a few thousand lines.
CHUNK_BYTES = 1 << 16
TOO_LONG = "\0 line too long"


class Input:
    """The chunks of an input and the handle they come from, closed together by `close` (also
    when never read: the output's header failed)."""

    def __init__(self, chunks: Iterator[str], handle) -> None:
        self.chunks, self.handle = chunks, handle

    def __iter__(self) -> Iterator[str]:
        return self.chunks

    def close(self) -> None:
        self.chunks.close()  # type: ignore[attr-defined]  (a generator)
        self.handle.close()


def open_input(options: StreamOptions) -> tuple[str, Input]:
    """Name of the input and its chunks (a serial port's until it closes)."""
    if options.serial is not None:
        return options.source, _serial_lines(options.serial, options.baud or DEFAULT_BAUD)
    if options.input is not None:
        try:
            handle = open(options.input, "rb")  # noqa: SIM115
        except OSError as exc:
            raise InputError(f"{options.input}: cannot read ({exc.strerror})") from None
        return options.source, Input(line_chunks(decoded(handle.read1)), handle)
    binary = getattr(sys.stdin, "buffer", None)
    if binary is not None and hasattr(binary, "read1"):
        return options.source, Input(line_chunks(decoded(binary.read1)), sys.stdin)
    # a text stream without bytes underneath (a StringIO put in place of stdin)
    return options.source, Input(line_chunks(lambda: sys.stdin.read(CHUNK_BYTES)), sys.stdin)


def decoded(read1: Callable[[int], bytes]) -> Callable[[], str]:
    """Text from `read1` (one system call at most: what is there, waiting only when nothing
    is), as UTF-8 with universal line ends as a text file reads it; "" at the end."""
    decoder = io.IncrementalNewlineDecoder(codecs.getincrementaldecoder("utf-8")("replace"),
                                           translate=True)
    ended = False

    def read() -> str:
        nonlocal ended
        while not ended:
            data = read1(CHUNK_BYTES)
            ended = not data
            if text := decoder.decode(data, final=ended):
                return text  # (a lone carriage return waits for what follows it)
        return ""

    return read


def line_chunks(read: Callable[[], str]) -> Iterator[str]:
    """The chunks (see the module) of the text `read` returns, "" at its end: the whole
    lines of each read, the line it cut held back for the next."""
    pending, too_long = "", False
    while text := read():
        if too_long:  # the rest of an overlong line: dropped up to its end
            end = text.find("\n")
            if end < 0:
                continue
            yield TOO_LONG
            too_long, text = False, text[end + 1:]
        else:
            text = pending + text
        cut = text.rfind("\n") + 1
        pending = text[cut:]
        if len(pending) >= MAX_LINE:
            pending, too_long = "", True
        if cut:
            yield from _whole_lines(text[:cut])
    if too_long:
        yield TOO_LONG
    elif pending:
        yield pending


def _whole_lines(block: str) -> Iterator[str]:
    """`block` (whole lines) as chunks: runs of lines shorter than ``MAX_LINE`` and a
    ``TOO_LONG`` for each longer one."""
    if len(block) <= MAX_LINE or max(map(len, block.split("\n"))) < MAX_LINE:
        yield block
        return
    kept: list[str] = []
    for line in block.split("\n")[:-1]:
        if len(line) < MAX_LINE:
            kept.append(line)
            continue
        if kept:
            yield "\n".join(kept) + "\n"
            kept = []
        yield TOO_LONG
    if kept:
        yield "\n".join(kept) + "\n"


def lines_of(chunk: str) -> list[str]:
    """A chunk's lines, each with its line end (a last line without one as it is)."""
    if chunk is TOO_LONG:
        return [chunk]
    parts = chunk.split("\n")
    lines = [part + "\n" for part in parts[:-1]]
    if parts[-1]:
        lines.append(parts[-1])
    return lines


def bounded(readline: Callable[[int], str]) -> Iterator[str]:
    """Lines from ``readline(limit)``, one per chunk; a line longer than ``MAX_LINE`` is
    read to its end in pieces (memory stays bounded) and given as ``TOO_LONG``."""
    while piece := readline(MAX_LINE):
        if len(piece) < MAX_LINE or piece.endswith("\n"):
            yield piece
            continue
        while (more := readline(MAX_LINE)) and not more.endswith("\n"):
            pass
        yield TOO_LONG


def _open_serial(port: str, baud: int):
    try:
        import serial  # the optional pyserial: only --serial needs it
    except ImportError:
        raise InputError(f"--serial needs the optional pyserial package: {SERIAL_HINT}") from None
    try:
        return serial, serial.Serial(port, baudrate=baud, timeout=None)
    except (serial.SerialException, OSError, ValueError) as exc:
        raise InputError(f"{port}: cannot open serial port ({exc})") from None


def _serial_lines(port: str, baud: int) -> Input:
    """Lines of a serial port, one per chunk, opened now (before the output's header: a
    caller that waits for the header knows the port is listening)."""
    serial, handle = _open_serial(port, baud)

    def lines() -> Iterator[str]:
        with handle:
            try:
                yield from bounded(lambda limit: handle.readline(limit).decode(
                    "ascii", errors="replace"))
            except serial.SerialException:  # unplugged, or the other end closed
                print(f"hystkit stream: {port} closed", file=sys.stderr)

    return Input(lines(), handle)
