"""Option types of the loop options (``hystkit control``, ``hystkit stability --control``):
PID gains and ``--tune`` targets, each value of an ``nargs`` option checked by its own type."""

from __future__ import annotations

import argparse

from ._common import UsageError, number

__all__ = ["PID_TYPES", "TUNE_TYPES", "Checked"]


# PID gains (eq. 7.2): 0 < Kp <= 1e9, 1 us <= Ti <= 1e6 s (inf: no integral action),
# 0 <= Td <= 1000 s; one type per slot. Far beyond any tuning of a 0.25 kg stage, and the range
# in which the loop's linearisation and simulation stay well conditioned.
def _gain(text: str) -> float:
    """KP: finite, nonzero, |KP| <= 1e9. A negative gain is allowed: a sign error is an
    experiment worth running (the loop then reports itself unbounded)."""
    value = number(-1e9, 1e9)(text)
    if value == 0:
        raise argparse.ArgumentTypeError("must not be 0 (no feedback at all)")
    return value


PID_TYPES = (_gain, number(1e-6, 1e6, allow_inf=True), number(0, 1e3))
TUNE_TYPES = (number(0, 1e4, low_open=True), number(0, 90, low_open=True, high_open=True))


class Checked(argparse.Action):
    """``nargs`` values, each parsed by its own type (argparse gives all one type)."""

    def __init__(self, *args, types=(), **kwargs) -> None:
        self.types = types
        super().__init__(*args, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None) -> None:
        parsed = []
        for meta, parse, text in zip(self.metavar, self.types, values, strict=True):
            try:
                parsed.append(parse(text))
            except argparse.ArgumentTypeError as exc:
                raise UsageError(f"argument {option_string} {meta}: {exc}") from None
        setattr(namespace, self.dest, parsed)
