"""The live path: a fitted compensator run sample by sample on a sensor as it records.

- :class:`Stream`: one sample in, the estimate, its flags and band out; compiled, and bit for bit
  the offline result of :meth:`hystkit.compensation.Compensator.estimate`;
- :class:`AdaptiveStream`: the same, with the linear output map tracked by recursive least
  squares (sensor drift);
- :class:`RefittingStream`: the same, refitting the model on a window of recent samples;
- :func:`sync_excitation`: the synchronisation excitation that puts the model in a known state
  (eq. 2.21-2.22).

Names are imported on first use (PEP 562, :func:`hystkit._lazy.lazy_exports`), so
``hystkit stream --help`` loads no numba.
"""

from .._lazy import lazy_exports

__getattr__, __dir__ = lazy_exports(
    __name__, globals(),
    {"_adaptive": ("AdaptiveStream", "advance_adaptive"),
     "_adaptive_records": ("ADAPT_PARAMETERS", "Adaptation", "AdaptiveState"),
     "_refit": ("Refit", "RefitReport", "RefittingStream"),
     "_readable": ("advance",),
     "_stream": ("Stream",),
     "_stream_output": ("StepOutput", "StreamOutput"),
     "_stream_state": ("StreamState",),
     "_sync": ("SyncExcitation", "sync_excitation")},
    first=())
