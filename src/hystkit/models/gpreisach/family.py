"""The generalised Preisach family (sec. 2.1.2, eq. 2.2) behind the family protocol.

The memory is the classical staircase, so everything but the structure, the fit and the
parameter count comes from the classical family's :class:`StaircaseFamily` (packed loop state,
rest states, the shared compiled block, the branch linearisation, rate independence).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .. import preisach
from ..preisach.family import StaircaseFamily, orientation_sign, random_masses
from . import INFO
from . import model as gpreisach

__all__ = ["FAMILY", "GPreisachFamily"]


class GPreisachFamily(StaircaseFamily):
    """The generalised Preisach model (sec. 2.1.2, eq. 2.2) as a registered family."""

    info = INFO
    Structure = gpreisach.GPreisachStructure
    Params = gpreisach.GPreisachParams
    stairs = gpreisach

    fit_function = "fit.fit_gpreisach"  # fit.py, imported on the first fit (optimisers)

    def make_structure(self, dt: float, size: int,
                       **options: Any) -> gpreisach.GPreisachStructure:
        return gpreisach.GPreisachStructure(levels=size, dt=dt, **options)

    def random_params(self, structure, rng):
        """The fit's constraints (``fit.py``): off-diagonal masses of ``mu_-`` and ``mu_+`` of
        the structure's loop orientation (``auto``: either), diagonal 0, each weight's
        ``sum |m|`` log-uniform in ``[0.1, 10]``; ``nu_k >= 0`` with ``int nu`` log-uniform in
        ``[0.01, 10]``; offset in ``[-1, 1]``. Bounded: ``|y - y_0| <= max(sum |m_-|,
        sum |m_+|) + int nu`` for ``|u| <= 1``."""
        levels, degree = structure.levels, structure.degree
        sign = orientation_sign(structure, rng)
        tables = [preisach.everett_from_masses(random_masses(levels, sign, rng, diagonal=False))
                  for _ in range(2)]
        # int_{-1}^{1} B_k^d = 2 / (d + 1) on [-1, 1]
        nu = (np.exp(rng.uniform(np.log(0.01), np.log(10.0))) * (degree + 1) / 2
              * rng.dirichlet(np.ones(degree + 1)))
        return gpreisach.GPreisachParams(everett_minus=tables[0], everett_plus=tables[1], nu=nu,
                                         offset=rng.uniform(-1.0, 1.0))

    def n_params(self, structure, params) -> int:
        """Off-diagonal masses of both weights (the fit keeps the diagonal at zero), the
        Bernstein coefficients of ``nu`` and the offset."""
        return (structure.levels - 1) * (structure.levels - 2) + params.nu.size + 1


FAMILY = GPreisachFamily()
