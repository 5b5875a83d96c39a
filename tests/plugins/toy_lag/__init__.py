"""A toy model family as a separately installed package would ship it: one folder, found by
hystkit through the ``hystkit.families`` entry point (``toy-lag = toy_lag.family``).

``y = w0 u + w1 x + bias`` with a first-order lag ``x' = rate (u - x)``: not hysteresis, just
small enough to read in one sitting. ``tests/plugins/test_adding_a_family.py`` copies this folder
into a temporary site, declares the entry point and runs every command on it;
``docs/models/README.md`` ("Adding a family") walks through the same files.
"""
