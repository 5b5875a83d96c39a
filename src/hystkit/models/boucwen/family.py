"""The Bouc-Wen oscillator (beyond the reference document) behind the family protocol."""

from __future__ import annotations

import numpy as np

from .._capabilities import ALL_LOSSES, Capabilities
from .._protocol import Block, Family
from . import INFO, kernels
from . import model as boucwen
from .export import TRANSLATION

__all__ = ["FAMILY", "BoucWenFamily"]


class BoucWenFamily(Family):
    """The Bouc-Wen oscillator (Noel and Schoukens' benchmark) as a registered family."""

    info = INFO
    export = TRANSLATION  # export.py: the block in C and MATLAB
    Structure = boucwen.BoucWenStructure
    Params = boucwen.BoucWenParams
    model = boucwen
    capabilities = Capabilities(losses=ALL_LOSSES)

    fit_function = "fit.fit_family"  # fit.py, imported on the first fit (optimisers)

    def make_structure(self, dt: float, size: int, input_hold: str = "linear",
                       start: str = "equilibrium") -> boucwen.BoucWenStructure:
        # Recordings start wherever the sensor happens to be, not at rest with zero force.
        return boucwen.BoucWenStructure(dt=dt, substeps=size, input_hold=input_hold, start=start)

    def random_params(self, structure, rng):
        """Softening, dissipative loops that RK4 integrates stably at ``h = dt / substeps``:
        ``K0 = k + alpha`` log-uniform in ``[0.1, 10]``, damping ratio ``zeta`` log-uniform in
        ``[0.1, 10]``, ``w0`` log-uniform up to the value whose fastest linear mode has
        ``|lambda| h = 1`` (``|lambda| = w0`` underdamped, ``w0 (zeta + sqrt(zeta^2 - 1))``
        overdamped; RK4's limit is 2.8) and down to a tenth of it or 1 rad/s, hysteretic share
        ``r = alpha / K0`` with ``logit r`` in the fit's ``[-9, 9]``, ``nu = 1``, loading slope
        ``(beta + gamma) / K0`` in ``[0, 1]`` (per unit static deflection ``1 / K0``) and
        unloading ``beta - gamma`` in ``[0, beta + gamma]``. Outside this, runs may diverge
        and raise ``FitDivergedError`` (:func:`~hystkit.models.boucwen.model.simulate_states`).
        Bounded: by passivity ``|y| <= sqrt(2 (E_0 + T max u^2 / (4 c)) / k)`` over a run of
        ``T`` seconds (:func:`~hystkit.models.boucwen.model.divergence_bound`)."""
        k0 = np.exp(rng.uniform(np.log(0.1), np.log(10.0)))
        zeta = np.exp(rng.uniform(np.log(0.1), np.log(10.0)))
        fastest = max(1.0, zeta + np.sqrt(max(zeta**2 - 1.0, 0.0)))  # |lambda| / w0
        w_hi = 1.0 / (structure.step_size * fastest)
        log_w0 = rng.uniform(np.log(min(1.0, w_hi / 10)), np.log(w_hi))
        load = rng.uniform(0.0, k0)
        unload = rng.uniform(0.0, load)
        return boucwen.BoucWenParams.from_vector(
            [np.log(k0), log_w0, np.log(zeta), rng.uniform(-9.0, 9.0), load, unload, 1.0])

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


FAMILY = BoucWenFamily()
