"""Local stability of any family's discrete model: eigenvalues of its linearised step.

Every family linearises one step, ``x+ = A x + B u`` (``Family.linearise``: analytical where
the family has it, numerical otherwise). The model is locally stable where every eigenvalue of
``A`` lies inside the unit circle, marginal on it (an integrator or a memory that holds, e.g.
a Preisach staircase or a play operator: perturbations neither grow nor decay), unstable
outside. The scan covers the rest states over the input range and the states a run on the
given input visits.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ._protocol import Family

__all__ = ["stability_report"]

TOL = 1e-9  # |lambda| within this of 1 counts as marginal (rounding of the linearisation)


def _radius(family: Family, structure: Any, params: Any, x: np.ndarray, u: float,
            inverse: bool) -> float:
    a = np.atleast_2d(family.linearise(structure, params, x, u, inverse)[0])
    if a.size == 0:
        return 0.0
    diagonal = np.count_nonzero(a) == np.count_nonzero(np.diagonal(a))  # cheaper than tril
    if diagonal or not (np.tril(a, -1).any() and np.triu(a, 1).any()):
        # triangular (a Preisach staircase's memory is the identity, 1025 states): the
        # eigenvalues are its diagonal; LAPACK's general solver took 7 ms a point there
        return float(np.max(np.abs(np.diagonal(a))))
    return float(np.max(np.abs(np.linalg.eigvals(a))))


def stability_report(family: Family, structure: Any, params: Any, u: np.ndarray, *,
                     inverse: bool = False, max_points: int = 400, n_rest: int = 9) -> dict:
    """Spectral radius of the linearised step at rest and along a run driven by ``u``.

    Parameters
    ----------
    family : Family
        The model family.
    structure, params : object
        The family's structure and parameters.
    u : array, shape (n,)
        Model input (output, for ``inverse``) covering the range of interest, normalised.
    inverse : bool
        Analyse the family's inverse (the compensator of an inverse-mode model file).
    max_points : int
        Samples of the run to linearise at (evenly spread).
    n_rest : int
        Rest states at this many constant inputs spread over ``u``'s range.

    Returns
    -------
    dict
        Plain JSON: ``n_state``, ``rest`` (inputs and radii), ``trajectory`` (points and the
        radius range), ``radius_max``, ``n_points``, ``n_unstable`` (radius > 1),
        ``n_marginal`` (radius 1 within ``TOL``), ``stable_everywhere`` (no point unstable)
        and ``details`` (the family's own, :meth:`Family.stability_details`, or None).
    """
    u = np.asarray(u, dtype=float)
    step = family.invert_step if inverse else family.step
    if step is None:
        raise ValueError(f"model {family.name!r} has no inverse ({family.no_inverse_reason})")
    levels = np.linspace(float(u.min()), float(u.max()), n_rest)
    rest = [_radius(family, structure, params,
                    family.rest_state(structure, params, v, inverse), v, inverse)
            for v in levels]
    keep = set(np.linspace(0, u.size - 1, min(max_points, u.size)).round().astype(int))
    x = family.rest_state(structure, params, float(u[0]), inverse)
    traj = []
    for i, u_i in enumerate(u):
        if i in keep:
            traj.append(_radius(family, structure, params, x, u_i, inverse))
        _, x = step(structure, params, x, u_i)
        if not np.all(np.isfinite(x)):
            raise ValueError(f"the {'inverse ' if inverse else ''}model left the finite range "
                             f"at sample {i} of the probe")
    radii = np.array(rest + traj)
    return {"n_state": int(np.size(x)), "inverse": inverse,
            "rest": {"inputs": levels.tolist(), "radius": rest},
            "trajectory": {"n_samples": int(u.size), "n_points": len(traj),
                           "radius_min": float(min(traj)), "radius_max": float(max(traj))},
            "radius_max": float(radii.max()), "n_points": int(radii.size),
            "n_unstable": int(np.sum(radii > 1 + TOL)),
            "n_marginal": int(np.sum(np.abs(radii - 1) <= TOL)),
            "stable_everywhere": bool(np.all(radii <= 1 + TOL)),
            "details": None if inverse else family.stability_details(structure, params, u)}
