"""Pieces shared by the subcommand modules: exit codes, the one-line-error parser, the
option types (`hystkit.cli._option_types`) and model sizes below a per-family maximum (the
family's ``max_size``), so a bad value is one line before any work.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from typing import TextIO

from ..errors import OutputError
from ._option_types import UsageError, integer, number, positive_float, positive_int, slope_cap
from ._read_args import add_read_options, given_read_options

__all__ = ["GUARD_EXIT", "INTERNAL_EXIT", "Deferred", "Parser", "UsageError", "add_read_options",
           "check_size", "deferred", "failures_exit", "given_read_options", "integer",
           "number", "positive_float", "positive_int", "say_next",
           "size_limit", "slope_cap", "stdout_for"]

# Exit code of work that ran but failed its guards (a fit collapsed, worse than the line, on
# bounds, not converged; a family failed in compare/select); 2 is kept for errors that stop a
# command.
GUARD_EXIT = 3
# Exit code of an internal error (a bug; BSD's EX_SOFTWARE): one line instead of a traceback.
INTERNAL_EXIT = 70



def stdout_for(what: str) -> TextIO:
    """The standard output of a command whose product is written there (``stream``'s
    estimates, ``datasets list``), refused when it is closed (``>&-``: Python makes it None);
    other commands' progress lines then go nowhere, as ``print`` does."""
    if sys.stdout is None:
        raise OutputError(f"standard output is closed: nowhere to write {what} (redirect it "
                          "to a file or a pipe)")
    return sys.stdout


class Deferred:
    """A value of an option (its choices, default or help text) that needs a heavy module (the
    model families, scipy, ...): computed when its subcommand is parsed or its help shown, so
    building the whole ``hystkit`` parser stays cheap (``--help``, ``--version``)."""

    def __init__(self, compute: Callable[[], object]):
        self.compute = compute


def deferred(action: argparse.Action, **values: Callable[[], object]) -> argparse.Action:
    """Set `action`'s attributes (``choices``, ``default``, ``help``) to computed-later values."""
    for name, compute in values.items():
        setattr(action, name, Deferred(compute))
    return action


class Parser(argparse.ArgumentParser):
    def error(self, message: str):  # argparse would print the usage and call sys.exit(2)
        raise UsageError(f"{message} (see '{self.prog} --help')")

    def _resolve(self, names: tuple[str, ...] = ("choices", "default", "help")) -> None:
        for action in self._actions:
            for name in names:
                value = getattr(action, name, None)
                if isinstance(value, Deferred):
                    setattr(action, name, value.compute())

    def parse_known_args(self, args=None, namespace=None):
        # A subcommand's parser: only the chosen one pays for its values, and parsing needs
        # no help text (fit's lists every model family; its --model check needs one).
        self._resolve(("choices", "default"))
        return super().parse_known_args(args, namespace)

    def format_usage(self) -> str:
        self._resolve()
        return super().format_usage()

    def format_help(self) -> str:
        self._resolve()
        return super().format_help()


def size_limit(family) -> int:
    """Largest size of `family` the CLI accepts (the family's ``max_size``: beyond it a fit
    takes hours or its Jacobian stops being solvable, e.g. mpl with 300 cells)."""
    return family.max_size


def check_size(family_name: str, size: int | None, option: str = "--size") -> None:
    """Refuse a model size beyond the family's limit or its own structure checks, before work.

    Raises
    ------
    UsageError
        One line naming the option, the family and the accepted range.
    """
    if size is None:
        return
    from ..models import get_family  # the families load only for commands with a model

    family = get_family(family_name)
    limit = size_limit(family)
    if size > limit:
        raise UsageError(f"{_label(option, size)}: {family_name} accepts at most {limit} "
                         f"({family.size_help})")
    try:
        family.make_structure(1 / 40, size)  # the family's own checks (e.g. levels >= 2)
    except ValueError as exc:
        raise UsageError(f"{_label(option, size)}: {family_name}: {exc}") from None


def _label(option: str, size: int) -> str:
    return f"{option}{'' if option.endswith('=') else ' '}{size}"


def failures_exit(failed: list[str], what: str = "model(s)", next_step: str | None = None
                  ) -> int:
    """Exit code after everything else was written: GUARD_EXIT (a line on stderr, then the
    `say_next` line: `next_step`, or what suits `what`) when something failed, else 0."""
    if failed:
        print(f"hystkit: {len(failed)} {what} failed: {', '.join(failed)} (reasons above)",
              file=sys.stderr)
        say_next(next_step or _NEXT_AFTER_FAILED.get(what, _NEXT_AFTER_FAILED["model(s)"]))
        return GUARD_EXIT
    return 0


# What to try when part of a command failed, by what failed (failures_exit's `what`)
_NEXT_AFTER_FAILED = {
    "model(s)": "one failed family alone, 'hystkit fit DATA --model NAME --out m.json' (its "
                "refusal names the reason and what to try), or leave it out with --models",
    "sensor(s)": "'hystkit fit' on one failed sensor's recordings alone: its refusal names the "
                 "reason and what to try (e.g. --model auto)",
    "trace(s)": "--model drop (3 parameters) for a trace that does not rise first, or a longer "
                "log that reaches its rest",
}


def say_next(step: str) -> None:
    """The last line of a refusal (exit GUARD_EXIT): ``next: try STEP``. On standard output,
    after the refusal's line on stderr: the guard tests read that line as stderr's last."""
    print(f"next: try {step}", flush=True)

