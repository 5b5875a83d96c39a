"""What a family can do beyond the abstract protocol, declared once (:class:`Capabilities`).

Generic code (the fit, the CLI, live adaptation, synchronisation) asks a family what it can do
by reading its ``capabilities`` record only, never its field names or its fit module's
constants. The defaults are the safe ones: a family that declares nothing fits the plain SSE
only, takes no sum |w| constraint and no given start, and is not adapted by its weights.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

__all__ = ["ALL_LOSSES", "Capabilities"]

# The names of hystkit.identification.LOSSES, written here so that declaring them does not
# import the optimisers (scipy, +0.5 s); the contract test checks the two agree.
ALL_LOSSES = ("linear", "soft_l1", "huber", "cauchy")


@dataclasses.dataclass(frozen=True)
class Capabilities:
    """A family's declared capabilities (``Family.capabilities``).

    Parameters
    ----------
    losses : tuple of str, default ("linear",)
        The losses its fit takes (of :data:`hystkit.identification.LOSSES`): ``"linear"`` is
        the plain SSE; ``ALL_LOSSES`` for a fit that solves any of them.
    weight_sum_floor : float or None, default None
        The fit takes the document's constraint ``sum |w| <= B`` (``weight_sum_max``) for
        ``B`` above this floor (mpl: 0; mpl-g: 1, the ``w_0`` its gauge fixes); None: it does
        not.
    linear_output : bool or callable, default False
        The output is ``sum_k w_k y_k - v_b`` with ``y_k`` the run with unit weight ``k`` and
        no bias, so live adaptation may re-fit ``params.w`` and ``params.v_b``; a callable
        ``linear_output(structure) -> bool`` where it depends on the structure (pl: one output
        segment). Ask :meth:`output_is_linear`.
    sync_amplitude : callable or None, default None
        ``sync_amplitude(structure, params) -> float``: the amplitude of the synchronisation
        excitation (eq. 2.21's ``E_0``, the largest play threshold); None: the training range.
    start_from_params : bool, default False
        The fit can start from exactly given parameters (``init``,
        :meth:`hystkit.models.Family.start_options`).
    inverse : bool, default True
        The family has an inverse; set from the family's ``no_inverse_reason``.
    """

    losses: tuple[str, ...] = ("linear",)
    weight_sum_floor: float | None = None
    linear_output: bool | Callable[[Any], bool] = False
    sync_amplitude: Callable[[Any, Any], float] | None = None
    start_from_params: bool = False
    inverse: bool = True

    def output_is_linear(self, structure: Any) -> bool:
        """Whether the output of a model of `structure` is linear in ``w`` and ``v_b``.

        Parameters
        ----------
        structure : Structure
            The model's structure.

        Returns
        -------
        bool
        """
        if callable(self.linear_output):
            return bool(self.linear_output(structure))
        return bool(self.linear_output)

    @property
    def fit_options(self) -> frozenset[str]:
        """The optional keywords of the fit these capabilities imply (``init``,
        ``weight_sum_max``)."""
        return frozenset({"init"} if self.start_from_params else set()) | frozenset(
            {"weight_sum_max"} if self.weight_sum_floor is not None else set())
