"""The classical Preisach family (sec. 2.1.1, appendix 9.3-9.5) behind the family protocol.

:class:`StaircaseFamily` holds what every staircase (Preisach-type) model shares -- packed loop
state, rest states, the compiled block, the branch linearisation -- and is reused by the
generalised Preisach family (``models/gpreisach``).
"""

from __future__ import annotations

import dataclasses
from types import ModuleType
from typing import Any, ClassVar

import numpy as np

from .._protocol import Block, Family
from . import INFO, kernels
from . import model as preisach
from .export import TRANSLATION

__all__ = ["FAMILY", "PreisachFamily", "StaircaseFamily", "orientation_sign", "random_masses"]

_LOG_MASS = (np.log(0.1), np.log(10.0))  # total |mass| of a random weight (random_params)


def orientation_sign(structure, rng: np.random.Generator) -> float:
    """Sign of the hysteretic masses for the structure's orientation (``auto``: random)."""
    if structure.orientation == "auto":
        return float(rng.choice([-1.0, 1.0]))
    return 1.0 if structure.orientation == "counterclockwise" else -1.0


def random_masses(levels: int, sign: float, rng: np.random.Generator,
                  diagonal: bool = True) -> np.ndarray:
    """Cell masses (L-1, L-1), Dirichlet-spread with ``sum |m|`` log-uniform in [0.1, 10]:
    off-diagonal ones of sign ``sign``, diagonal ones ``>= 0`` (or 0 without ``diagonal``)."""
    rows, cols = np.tril_indices(levels - 1)
    keep = np.ones(rows.size, bool) if diagonal else rows != cols
    masses = np.zeros((levels - 1, levels - 1))
    total = np.exp(rng.uniform(*_LOG_MASS))
    masses[rows[keep], cols[keep]] = total * rng.dirichlet(np.ones(int(keep.sum())))
    off = rows != cols
    masses[rows[off], cols[off]] *= sign
    return masses


class StaircaseFamily(Family):
    """Protocol methods of a model whose memory is the Preisach staircase.

    The protocol's state is the packed staircase (:func:`preisach.pack_state`,
    ``capacity + 1`` floats); ``stairs`` is the family's module of functions on the
    plain staircase (``simulate``, ``invert``, ``step``, ``invert_step``, ``kernel_parts``),
    which every method here wraps (so the protocol's ``model`` defaults are not used).
    """

    export = TRANSLATION  # export.py: the staircase block in C and MATLAB (gpreisach's too)
    stairs: ClassVar[ModuleType]

    def at(self, structure, dt):
        """Rate independent: the same model at any sample time (``dt`` only records it)."""
        return dataclasses.replace(structure, dt=float(dt))

    def _unpack(self, structure, x):
        return preisach.unpack_state(x, structure.capacity)

    def _pack(self, structure, staircase):
        return preisach.pack_state(staircase, structure.capacity)

    def rest_state(self, structure, params, value, inverse=False):
        # The state simulate(x0=None) / invert(x0=None) reach at the first sample of a constant
        # signal: the demagnetised staircase moved to the input (or to the input found for the
        # output). A second sample of the same value changes nothing: a fixed point.
        run = self.stairs.invert if inverse else self.stairs.simulate
        _, x_end = run(structure, params, np.array([float(value)]))
        return self._pack(structure, x_end)

    def step(self, structure, params, x, u):
        y, x_next = self.stairs.step(structure, params, self._unpack(structure, x), u)
        return float(y), self._pack(structure, x_next)

    def invert_step(self, structure, params, x, y):
        u_hat, x_next = self.stairs.invert_step(structure, params, self._unpack(structure, x), y)
        return float(u_hat), self._pack(structure, x_next)

    def simulate(self, structure, params, u, x0=None):
        x0 = None if x0 is None else self._unpack(structure, x0)
        y, x_end = self.stairs.simulate(structure, params, u, x0)
        return y, self._pack(structure, x_end)

    def invert(self, structure, params, y, x0=None):
        x0 = None if x0 is None else self._unpack(structure, x0)
        u_hat, x_end = self.stairs.invert(structure, params, y, x0)
        return u_hat, self._pack(structure, x_end)

    def block(self, structure, params, inverse=False):
        """``kernels.block_forward`` / ``block_inverse`` on the packed staircase.

        When the staircase is about to fill its ``capacity``, the innermost closed loop is
        forgotten, exactly as in :meth:`simulate` (``PreisachStructure``): a documented
        degradation of the memory, never an overflow.
        """
        self.simulate(structure, params, np.zeros(2))  # checks that params fit the structure
        tables, weighted, poly, slope = self.stairs.kernel_parts(params)
        if inverse:  # the inverse's own checks: a major loop that rises enough to invert
            self.invert(structure, params, np.zeros(2))
        levels = tables.shape[1]
        head = [structure.capacity, levels, tables.shape[0], float(weighted), slope,
                preisach.INVERT_TOL, poly.size]
        body = np.concatenate([head, poly, tables.reshape(-1)])
        step = kernels.block_inverse if inverse else kernels.block_forward
        return Block(step, np.ascontiguousarray(body, dtype=np.float64), structure.capacity + 1)

    def linearise(self, structure, params, x, u, inverse=False, rel_step=1e-6):
        """Linearisation along the branch being traversed (a numerical Jacobian is degenerate).

        A reversal pushes an entry onto the staircase (the length jumps), so at rest a
        two-sided difference is meaningless, and the staircase is not a state that may be
        perturbed freely (it must stay nested, from -1). Instead, in the direction ``d`` of
        the present change -- the sign of ``u`` minus the last input (for the inverse: of the
        output minus the present output), or at rest the direction of the staircase's last
        segment, rising from negative saturation -- the step is a static map along one branch:

        - ``D`` is the one-sided slope ``(g(u + d h) - g(u)) / (d h)`` of that branch (exact
          inside a linear piece; for the inverse ``du/dy`` on the inverse branch);
        - ``A`` holds the stored extrema (1 on their diagonal: a memory that neither grows nor
          decays, eigenvalue 1, "marginal" in ``models/_stability.py``), 0 elsewhere;
        - ``B`` is 1 on the entry that stores the present input (0 beyond [-1, 1], clipped);
        - ``C`` is 0: small signals along the branch do not move the stored extrema, and the
          output's dependence on the present input is all in ``D``.
        """
        staircase = self._unpack(structure, x)
        run = self.stairs.invert_step if inverse else self.stairs.step
        last = staircase[-1]
        present = self.stairs.step(structure, params, staircase, last)[0] if inverse else last
        if u != present:
            direction = 1.0 if u > present else -1.0
        else:
            direction = 1.0 if staircase.size == 1 or last > staircase[-2] else -1.0
        h = direction * rel_step * max(1.0, abs(u))
        out, nxt = run(structure, params, staircase, u)
        out_h, nxt_h = run(structure, params, staircase, u + h)
        n = structure.capacity + 1
        a, b = np.zeros((n, n)), np.zeros(n)
        stored = np.arange(1, nxt_h.size)  # packed indices of s_0 .. s_{k-2}
        a[stored, stored] = 1.0
        if nxt_h[-1] != nxt[-1]:  # the present input's entry moves with the input
            b[nxt_h.size] = 1.0
        return a, b, np.zeros(n), float((out_h - out) / h)


class PreisachFamily(StaircaseFamily):
    """The classical Preisach model (sec. 2.1.1, appendix 9.3-9.5) as a registered family."""

    info = INFO
    Structure = preisach.PreisachStructure
    Params = preisach.PreisachParams
    stairs = preisach

    fit_function = "fit.fit_preisach"  # fit.py, imported on the first fit (optimisers)

    def make_structure(self, dt: float, size: int, **options: Any) -> preisach.PreisachStructure:
        return preisach.PreisachStructure(levels=size, dt=dt, **options)

    def random_params(self, structure, rng):
        """The fit's sign constraints (``fit.py``): cell masses of the structure's loop
        orientation (``auto``: either, at random) -- counter-clockwise all ``>= 0``, clockwise
        off-diagonal ``<= 0`` and diagonal ``>= 0`` -- spread at random (Dirichlet) with total
        ``sum |m|`` log-uniform in ``[0.1, 10]`` (1: a major loop spanning [-1, 1], eq. 5.10),
        offset in ``[-1, 1]``. Bounded: ``|y - y_0| <= sum |m| max(1, |u|)``."""
        masses = random_masses(structure.levels, orientation_sign(structure, rng), rng)
        return preisach.PreisachParams.from_masses(masses, offset=rng.uniform(-1.0, 1.0))

    def n_params(self, structure, params) -> int:
        """The Everett nodes below the diagonal (one per cell mass) and the offset."""
        return structure.levels * (structure.levels - 1) // 2 + 1


FAMILY = PreisachFamily()
