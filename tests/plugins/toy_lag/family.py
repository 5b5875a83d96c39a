"""The toy family: records, the readable step, a grid-search fit and the compiled block."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hystkit.identification import FitResult, check_fit_data
from hystkit.models import Block, Family, Record

from .export import TRANSLATION
from .kernels import block_forward, block_inverse

RATES = np.geomspace(0.05, 20.0, 25)  # candidate lag rates [1/s] of the grid search


@dataclass(frozen=True)
class LagStructure(Record):
    dt: float = 0.025


@dataclass(frozen=True, eq=False)
class LagParams(Record):
    rate: float
    w0: float
    w1: float
    bias: float = 0.0


class LagFamily(Family):
    """y = w0 u + w1 x + bias with a first-order lag x' = rate (u - x)."""

    name = "toy-lag"
    title = "first-order lag (a toy plugin family)"
    size_help = "ignored"
    Structure = LagStructure
    Params = LagParams
    export = TRANSLATION

    def make_structure(self, dt, size, **options):
        return LagStructure(dt)

    def rest_state(self, structure, params, value, inverse=False):
        if inverse:
            value = (value - params.bias) / (params.w0 + params.w1)
        return np.array([float(value)])

    def step(self, structure, params, x, u):
        y = params.w0 * u + params.w1 * x[0] + params.bias
        return float(y), np.array([x[0] + params.rate * structure.dt * (u - x[0])])

    def invert_step(self, structure, params, x, y):
        u = (y - params.w1 * x[0] - params.bias) / params.w0
        return float(u), np.array([x[0] + params.rate * structure.dt * (u - x[0])])

    def _run(self, step, structure, params, u, x0, inverse):
        u = np.asarray(u, dtype=float)
        x = self.rest_state(structure, params, float(u[0]), inverse) if x0 is None else x0
        y = np.empty_like(u)
        for k, u_k in enumerate(u):
            y[k], x = step(structure, params, x, u_k)
        return y, x

    def simulate(self, structure, params, u, x0=None):
        return self._run(self.step, structure, params, u, x0, False)

    def invert(self, structure, params, y, x0=None):
        return self._run(self.invert_step, structure, params, y, x0, True)

    def fit(self, u, y, structure, *, accept=None, accept_reason="", **options):
        u, y = check_fit_data(u, y)
        best = None
        for rate in RATES:
            lag = self.simulate(structure, LagParams(rate, 0.0, 1.0), u)[0]  # the state x
            columns = np.column_stack([u, lag, np.ones_like(u)])
            coef = np.linalg.lstsq(columns, y, rcond=None)[0]
            params = LagParams(rate, *coef)
            cost = float(np.sum((columns @ coef - y) ** 2))  # the model's output is columns @ coef
            if best is None or cost < best[0]:
                best = (cost, params)
        return FitResult(structure=structure, params=best[1], cost=best[0],
                         n_evaluations=RATES.size, seconds=0.0, converged=True,
                         message="grid search", n_starts=RATES.size)

    def block(self, structure, params, inverse=False):
        body = np.array([params.rate, params.w0, params.w1, params.bias, structure.dt])
        return Block(block_inverse if inverse else block_forward, body, 1)


FAMILY = LagFamily()
