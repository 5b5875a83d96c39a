"""The Bouc-Wen oscillator (beyond the reference document) behind the family protocol."""

from __future__ import annotations

import numpy as np

from .._protocol import Block, Family
from . import kernels
from . import model as boucwen
from .fit import fit_family

__all__ = ["BoucWenFamily"]


class BoucWenFamily(Family):
    name = "boucwen"
    title = ("Bouc-Wen oscillator, m y'' + c y' + k y + z = u (beyond the document; "
             "Noel-Schoukens benchmark)")
    size_help = "RK4 substeps per sample (7 parameters whatever the size)"
    default_size = 2
    docs = "docs/models/boucwen.md"
    Structure = boucwen.BoucWenStructure
    Params = boucwen.BoucWenParams
    model = boucwen
    fit_function = fit_family
    no_inverse_reason = ("its input is a force and its output a displacement of a second-order "
                         "system: the inverse needs the measured output differentiated twice "
                         "(dynamic inversion), which is not implemented")

    def make_structure(self, dt: float, size: int, input_hold: str = "linear",
                       start: str = "equilibrium") -> boucwen.BoucWenStructure:
        # Recordings start wherever the sensor happens to be, not at rest with zero force.
        return boucwen.BoucWenStructure(dt=dt, substeps=size, input_hold=input_hold, start=start)

    def at(self, structure, dt):
        """The same ODE at ``dt`` (its parameters are physical and do not depend on the step)
        with the same number of RK4 substeps per sample, so the step ``h = dt / substeps``
        follows ``dt``: shorter (more accurate) at a finer ``dt``. At a coarser one it grows;
        the fit bounds ``w0 h <= 1`` and RK4 is stable to ``w0 h`` of about 2.8, so up to about
        2.8 times the fitted ``dt`` is safe, and beyond ``simulate`` raises
        ``FitDivergedError`` if the integration diverges (give more substeps). Keeping the
        count, not ``h``, makes ``at`` reversible, ``at(at(s, dt), s.dt) == s``."""
        return super().at(structure, dt)

    def block(self, structure, params, inverse=False):
        """The per-sample scheme of :meth:`step`: RK4 substeps with the force held or linear
        between the previous sample and this one (causal). It cannot band-limit the force the
        way :func:`~hystkit.models.boucwen.bandlimited_upsample` does over a whole record;
        docs/models/boucwen.md says how far the two differ."""
        if inverse:
            raise ValueError(f"model {self.name!r} has no inverse ({self.no_inverse_reason})")
        body = np.concatenate([params.as_array(), [structure.dt, structure.substeps,
                                                   structure.input_hold == "linear"]])
        return Block(kernels.block_forward, np.ascontiguousarray(body, dtype=np.float64), 4)
