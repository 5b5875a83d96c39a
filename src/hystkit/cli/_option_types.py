"""Option types: every numeric option goes through one, so a bad value is one line (exit 2)
before any work: finite unless infinity means something (no actuator limit), within a range."""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable

from ..errors import HystkitError

__all__ = ["UsageError", "integer", "number", "positive_float", "positive_int", "slope_cap"]


class UsageError(HystkitError):
    """A command line argparse rejected; reported on one line like every other error."""


def number(low: float | None = None, high: float | None = None, *, low_open: bool = False,
           high_open: bool = False, allow_inf: bool = False) -> Callable[[str], float]:
    """An option type: a float in ``[low, high]`` (ends open if asked), finite unless
    `allow_inf` (then ``inf`` is accepted beside the range)."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
        if math.isinf(value) and value > 0 and allow_inf:
            return value
        if not math.isfinite(value):
            raise argparse.ArgumentTypeError(f"must be a finite number, got {text!r}")
        if low is not None and (value < low or (low_open and value == low)):
            raise argparse.ArgumentTypeError(f"must be {'>' if low_open else '>='} {low:g}, "
                                             f"got {text}")
        if high is not None and (value > high or (high_open and value == high)):
            raise argparse.ArgumentTypeError(f"must be {'<' if high_open else '<='} {high:g}, "
                                             f"got {text}")
        return value

    return parse


def integer(low: int | None = None, high: int | None = None) -> Callable[[str], int]:
    """An option type: a whole number (decimal digits, optional sign) in ``[low, high]``."""

    def parse(text: str) -> int:
        stripped = text.strip()
        if not stripped.lstrip("+-").isascii() or not stripped.lstrip("+-").isdigit():
            raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}")
        value = int(stripped)
        if (low is not None and value < low) or (high is not None and value > high):
            span = (f"in [{low}, {high}]" if low is not None and high is not None
                    else f">= {low}" if low is not None else f"<= {high}")
            raise argparse.ArgumentTypeError(f"must be a whole number {span}, got {text}")
        return value

    return parse


positive_int = integer(1)
positive_float = number(0, low_open=True)


def slope_cap(text: str) -> float:
    # Below 1e-3 the cap undercuts the fit's smallest conductance at usual rates: no box left.
    value = number(1e-3, 2, high_open=True)(text)
    return value
