"""Names and constants of the control package that option parsing needs (``hystkit control
--help``): kept apart from the loop code, which loads numba, scipy and python-control."""

__all__ = ["EXPERIMENTS", "MASS", "SCHEMES", "SLOW_GROWTH_S", "TRAININGS", "TYPICAL_RUN_S"]

MASS = 0.250
"""Moving mass of the SMAC stroke [kg], eq. 7.1."""

EXPERIMENTS = ("sine", "frequency", "amplitude", "cubic", "disturbance")
"""The document's closed-loop experiments (sec. 7.3)."""

SCHEMES = ("direct", "weighting")
"""Where the compensator sits: in the feedback path, or as a reference weighting (sec. 7.2)."""

TRAININGS = ("recording", "loop")
"""What a loop's sensor models are trained on: a recording, or the loop's own run."""

SLOW_GROWTH_S = 86400.0
"""A linearised closed loop that grows e-fold in this long [s] or longer is unstable in
principle and bounded over any run of minutes: said so, with its growth over TYPICAL_RUN_S."""

TYPICAL_RUN_S = 300.0
"""The run length [s] over which a slow instability's growth is quoted."""
