"""Preisach staircase models (``models/preisach/kernels.py``, shared by the classical and the
generalised family): ``block_forward`` / ``block_inverse`` and the rest state.

Body: ``[capacity, L, K, weighted, slope, tol, n_poly, poly (n_poly), A (K L L)]``. The state
is the block's (``[n, s_0 .. s_{capacity-1}]``) followed by the running sums ``c`` (capacity x
K) that the run kernels keep and the block rebuilds every sample: kept here, the cost per
sample is amortised O(1) instead of O(n), and the sums are the same additions in the same
order, so the numbers are too. The rest state is the demagnetised staircase moved by one
sample of the value, as ``FAMILY.rest_state`` does. The C code is in :mod:`.export_c`, the
MATLAB code in :mod:`.export_matlab`, the body's layout in :mod:`.export_layout`.
"""

from __future__ import annotations

from .._protocol import Translation
from .export_c import c_model
from .export_layout import body_sizes
from .export_matlab import m_model
from .staircase import demagnetised_state

M_LOAD = """function x = model_load(B, x_block)
x = zeros(round(B(1)) + 1 + round(B(1)) * round(B(3)), 1);
x(1:numel(x_block)) = x_block;
x = load_sums(B, x);
end
"""


def extra(comp) -> dict:
    """The demagnetised staircase every run starts from (``model.demagnetised_state``)."""
    return {"DEMAG": demagnetised_state(comp.structure.levels - 1)}


def state_size(plan) -> int:
    cap, _, n_tab, _ = body_sizes(plan)
    return cap + 1 + cap * n_tab


# The family's block in C and MATLAB: FAMILY.export (family.py).
TRANSLATION = Translation(
    c_model=c_model,
    m_model=m_model,
    m_functions=("branch_output", "everett", "load_sums", "make_room", "term", "update"),
    extra=extra,
    state_size=state_size,
    m_load=M_LOAD)
