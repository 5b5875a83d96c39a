"""hystkit: hysteresis models, compensators and closed-loop simulation for lousy sensors.

The notebook interface::

    import hystkit as hk
    rec = hk.read("my.csv", columns={"time": "t", "position": "x_mm", "sensor": "r"},
                  time_unit="ms")
    comp = hk.fit(rec, "mpl", size=1)          # a Recording, a DataFrame or a path
    hk.evaluate(comp, "validation.csv")        # deployable scores first, oracle labelled
    hk.compare(rec, "validation.csv", models=["mpl", "pi"])   # a DataFrame
    hk.save(comp, "model.json"); hk.load("model.json")

Every name (and every subpackage: ``hk.models``, ``hk.datasets``, ...) is imported on first use
(PEP 562), so ``import hystkit`` itself loads nothing heavy.
"""

from ._lazy import lazy_exports

__version__ = "0.1.0"

__getattr__, __dir__ = lazy_exports(
    __name__, globals(),
    {"_api": ("read", "fit", "evaluate", "compensate", "compare", "load", "save"),
     "io": ("Recording", "ReadOptions"),
     "compensation": ("Compensator", "CompensatorEstimator"),
     "models": ("FAMILIES",),
     "errors": ("HystkitError", "InputError")},
    first=("__version__",))
