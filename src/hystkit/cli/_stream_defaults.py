"""``hystkit stream``'s option defaults, shared by its parser (:mod:`._stream_options`, which
must stay light) and its run (:mod:`.cmd_stream`): as ``hystkit.live``'s own (tested), not
imported from there, since that loads numba."""

from __future__ import annotations

__all__ = ["ADAPT_CHOICES", "DEFAULT_BAUD", "DEFAULT_FORGETTING", "DEFAULT_REFIT_EVERY",
           "DEFAULT_WINDOW", "SERIAL_HINT"]

# As hystkit.live.Adaptation's parameters, plus full (hystkit.live.RefittingStream).
ADAPT_CHOICES = ("gain", "weights", "full")
DEFAULT_FORGETTING = 0.9
DEFAULT_WINDOW = 60.0
DEFAULT_REFIT_EVERY = 10
DEFAULT_BAUD = 115200
SERIAL_HINT = 'pip install "hystkit[serial]"'
