"""What a recording's time column says about its unit: a units row or a column name naming
another unit than the one read is refused; a step that makes the rate implausible is warned of.
"""

from __future__ import annotations

import re

import numpy as np

from hystkit._read_options import TIME_UNITS, ReadOptions

from ._cells import Where

__all__ = ["MIN_PLAUSIBLE_HZ", "check_time_name", "check_time_unit", "time_step_warning"]


# Words that name a time unit in a column name (``time_sec``, ``t [ms]``); a name with none
# says nothing, and then the step is all there is to go by
_UNIT_WORDS = {"s", "sec", "secs", "second", "seconds", "ms", "msec", "millis", "us", "usec",
               "micros", "ns", "nsec", "min", "mins", "minute", "minutes"}
MIN_PLAUSIBLE_HZ = 1.0
"""A rate at or below which a time column whose name states no unit is probably not in the
unit read: a logger in ms writes integer steps of 1 to 1000 (1 kHz to 1 Hz), read as seconds
a rate of 1 Hz down to 1 mHz."""


def time_step_warning(time: np.ndarray, options: ReadOptions, where: Where) -> str:
    """The one-line warning for a time column (in seconds) whose median step makes the
    rate `MIN_PLAUSIBLE_HZ` or lower when its name states no unit, with the unit that would
    make it plausible; "" otherwise. Never a guess that changes the numbers: the time stays
    as read, in the unit the options say (``min`` is taken as meant).

    Examples
    --------
    >>> import numpy as np
    >>> print(time_step_warning(np.arange(5) * 20.0, ReadOptions(), Where("my.csv")))
    my.csv: column 'time': one sample every 20 s (0.05 Hz) read in s; if the time is in ms, ...
    """
    name = where.name("time")
    words = {w.lower().replace("µ", "u") for w in re.split(r"[^0-9A-Za-zµ]+", name) if w}
    finite = time[np.isfinite(time)]
    if options.time_unit == "min" or words & _UNIT_WORDS or finite.size < 2:
        return ""
    step = float(np.median(np.diff(finite)))
    if not step >= 1 / MIN_PLAUSIBLE_HZ:  # also NaN: the checks report a bad time column
        return ""
    raw = step / options.time_scale  # as written in the file
    smaller = [u for u, scale in TIME_UNITS.items() if scale < options.time_scale]
    fits = [u for u in sorted(smaller, key=TIME_UNITS.__getitem__, reverse=True)
            if raw * TIME_UNITS[u] < 1 / MIN_PLAUSIBLE_HZ]
    hint = (f"; if the time is in {fits[0]}, pass --time-unit {fits[0]} (or time_unit = "
            f"\"{fits[0]}\" in the settings file)" if fits else "")
    return where.fail(f"one sample every {step:.6g} s ({1 / step:.6g} Hz) read in "
                      f"{options.time_unit}{hint}", "time").args[0]


def check_time_unit(unit: str | None, options: ReadOptions, where: Where) -> None:
    """A units row naming a time unit other than the one read would mean reading ms as s."""
    if unit is None:
        return
    named = unit.strip().strip("[]()").strip()
    if named in TIME_UNITS and named != options.time_unit:
        raise where.fail(f"the file gives the time unit {unit!r} but time is read in "
                         f"{options.time_unit}; pass --time-unit {named} (or time_unit = "
                         f"\"{named}\" in the settings file)", "time")


def check_time_name(name: str, options: ReadOptions, where: Where) -> None:
    """A time column named for a unit (``t_ms``, ``time [us]``) other than the one read would
    mean reading ms as s: 12000 samples at 0.05 Hz instead of 20 Hz, fitted without a word."""
    words = {w.replace("µ", "u") for w in re.split(r"[^0-9A-Za-zµ]+", name) if w}
    named = sorted(words & set(TIME_UNITS) - {options.time_unit})
    if named and options.time_unit not in words:
        raise where.fail(f"the time column {name!r} is named for {named[0]} but time is read "
                         f"in {options.time_unit}; pass --time-unit {named[0]} (or time_unit = "
                         f"\"{named[0]}\" in the settings file)", "time")
