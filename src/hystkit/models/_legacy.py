"""TRANSITIONAL (removed when every family has its folder): families still registered the old
way, as ``hystkit.identification.family_<name>.FAMILY`` (a ``ModelFamily``), behind the
protocol. They have no compiled loop block yet."""

from __future__ import annotations

import importlib
import pkgutil

from ._protocol import Family


class LegacyFamily(Family):
    def __init__(self, old):
        self._old = old
        self.name, self.title, self.size_help = old.name, old.title, old.size_help
        self.default_size, self.Structure, self.Params = (old.default_size, old.structure_type,
                                                          old.params_type)
        self.no_inverse_reason = old.no_inverse_reason
        if old.invert is not None:
            self.invert = old.invert

    def make_structure(self, dt, size, **options):
        return self._old.make_structure(dt, size, **options)

    def rest_state(self, structure, params, value, inverse=False):
        raise NotImplementedError(f"{self.name}: not moved to the family protocol yet")

    def step(self, structure, params, x, u):
        raise NotImplementedError(f"{self.name}: not moved to the family protocol yet")

    def simulate(self, structure, params, u, x0=None):
        return self._old.simulate(structure, params, u, x0)

    def fit(self, u, y, structure, *, accept=None,
            accept_reason="rejected by the acceptance test", **options):
        return self._old.fit(u, y, structure, accept=accept, accept_reason=accept_reason,
                             **options)

    def block(self, structure, params, inverse=False):
        raise NotImplementedError(f"{self.name}: not moved to the family protocol yet")


def legacy_families() -> dict:
    package = importlib.import_module("hystkit.identification")
    found = {}
    for info in sorted(pkgutil.iter_modules(package.__path__), key=lambda m: m.name):
        if info.name.startswith("family_"):
            old = importlib.import_module(f"hystkit.identification.{info.name}").FAMILY
            found[old.name] = LegacyFamily(old)
    return found



