"""Reading the user's recordings with the command line's reading options and the settings
file beside each (`hystkit.io.options_for`): what every command that reads a recording calls.

A `Reader` holds the reading options given on one command line and what it has said (the
settings file used, a CSV layout it guessed), so each is said once per command: a command
builds one, ``Reader(given_read_options(args))``, and keeps it in its options record or passes
it along (nothing is written onto the parsed command line).
"""

from __future__ import annotations

from pathlib import Path

from .._read_options import ReadOptions
from ..io import csv_layout, options_for, read_pieces, read_recording, settings_for
from ._own_layout import remembered_options

__all__ = ["Reader"]


class Reader:
    """How one command reads the user's recordings.

    Parameters
    ----------
    given : dict
        The reading options set on the command line, as `hystkit.io.ReadOptions` keyword
        arguments (`hystkit.cli._read_args.given_read_options`).
    """

    def __init__(self, given: dict):
        self.given = dict(given)
        self._said: set[str] = set()  # settings lines, once per command
        self._layouts: set[str] = set()  # files whose CSV layout was said
        self._trained: set[str] = set()  # "as the model's training data" lines

    def options(self, path) -> ReadOptions:
        """The `hystkit.io.ReadOptions` of a recording `path`: the settings file next to it
        (``my.toml`` for ``my.csv``) first, the command line over it; the file used is printed
        once per command."""
        options, settings = options_for(path, self.given)
        note = settings_for(path)[1] if settings is None else ""
        said = (f"reading {path} with the settings in {settings}" if settings is not None
                else f"reading {path} without its settings: {note}" if note else "")
        if said and said not in self._said:
            self._said.add(said)
            print(said, flush=True)
        self._say_layout(Path(path), options)
        return options

    def as_trained(self, path, reading: ReadOptions | None) -> ReadOptions:
        """`options` for a command that applies a model: the model's `reading` when it
        applies to `path` (`hystkit.cli._own_layout.remembered_options`, said once per file
        and command), else the command line and the settings file as for any command."""
        options = self.options(path)
        found = remembered_options(self.given, Path(path), reading)
        if found is None:
            return options
        options, line = found
        if line not in self._trained:
            self._trained.add(line)
            print(line, flush=True)
        return options

    def _say_layout(self, path: Path, options: ReadOptions) -> None:
        """Print once per file what was detected in a CSV file that a plain comma-separated
        one would not have (``reading my.csv: semicolon-separated, decimal comma``): a guess
        is said. A file that cannot be opened is left to the reader, whose message names the
        problem."""
        if str(path) in self._layouts or path.suffix.lower() != ".csv" or not path.is_file():
            return
        self._layouts.add(str(path))
        try:
            notice = csv_layout(path, options).notice()
        except OSError:
            return
        if notice:
            print(f"reading {path}: {notice}", flush=True)

    def recording(self, path, *, need_position: bool = True):
        """Recording `path`, read with `options`."""
        return read_recording(path, need_position=need_position, options=self.options(path))

    def training_files(self, paths, *, need_position: bool = True) -> tuple[list, list]:
        """How each file of `paths` is read and its recordings: one per file, or its pieces
        between time gaps (fitted jointly)."""
        reading, recs = [], []
        for path in paths:
            reading.append(self.options(path))
            if reading[-1].gaps == "split":
                recs += read_pieces(path, need_position=need_position, options=reading[-1])
            else:
                recs.append(read_recording(path, need_position=need_position,
                                           options=reading[-1]))
        return reading, recs
