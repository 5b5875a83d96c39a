"""The two ways a compensator uses its model (see :mod:`._compensator`); a module of its own so
that ``hystkit fit --help`` can list them without loading the model stack."""

__all__ = ["MODES"]

# direct: the model maps sensor -> position (paper 9.2); inverse: the model maps position ->
# sensor and its inverse is run on sensor data (paper 9.1).
MODES = ("direct", "inverse")
