"""Pieces shared by the subcommand modules: the one-line-error parser and option types."""

from __future__ import annotations

import argparse
import sys

from ..errors import HystkitError

__all__ = ["GUARD_EXIT", "INTERNAL_EXIT", "Parser", "UsageError", "failures_exit", "positive_int", "slope_cap"]

# Exit code of work that ran but failed its guards (a fit collapsed, worse than the line, on
# bounds, not converged; a family failed in compare/select); 2 is kept for errors that stop a
# command.
GUARD_EXIT = 3
# Exit code of an internal error (a bug; BSD's EX_SOFTWARE): one line instead of a traceback.
INTERNAL_EXIT = 70


class UsageError(HystkitError):
    """A command line argparse rejected; reported on one line like every other error."""


class Parser(argparse.ArgumentParser):
    def error(self, message: str):  # argparse would print the usage and call sys.exit(2)
        raise UsageError(f"{message} (see '{self.prog} --help')")


def positive_int(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be a positive integer, got {value}")
    return value


def slope_cap(text: str) -> float:
    value = float(text)
    if not 0 < value < 2:
        raise argparse.ArgumentTypeError(f"must lie in (0, 2) for a stable Euler step "
                                         f"(eq. 5.28), got {value}")
    return value




def failures_exit(failed: list[str], what: str = "model(s)") -> int:
    """Exit code after everything else was written: GUARD_EXIT (and a line on stderr) when
    something failed, else 0."""
    if failed:
        print(f"hystkit: {len(failed)} {what} failed: {', '.join(failed)} (reasons above)",
              file=sys.stderr)
        return GUARD_EXIT
    return 0
