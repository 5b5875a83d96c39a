"""Write an :class:`ExportPlan` as MATLAB / GNU Octave code (double precision).

Files:

- ``NAME_init.m``: ``state = NAME_init(first_sensor)``, at rest at the first sensor sample;
- ``NAME.m``: ``[estimate, state, flags] = NAME(sensor, state)`` over a chunk (a vector) of
  sensor samples; ``state`` omitted or ``[]`` starts with ``NAME_init(sensor(1))``; calling it
  chunk after chunk gives the same as one call on the whole signal. With a prediction band,
  ``[estimate, state, flags, lower, upper] = NAME(...)``: the band [mm] of each estimate, its
  features carried in ``state`` (``Compensator.estimate_with_band``);
- ``NAME_block.m``: one sample in, one estimate out (with a band: ``[estimate, lower,
  upper]``), the state ``persistent`` (for a Simulink MATLAB Function block; ``clear
  NAME_block`` restarts it);
- ``NAME_sync.m`` when the state after the synchronisation excitation is known.

The arithmetic repeats :meth:`Compensator.estimate` in the same order as the C export.
"""

from __future__ import annotations

from textwrap import indent

import numpy as np

from ._comments import comment_text
from ._plan import ExportPlan

__all__ = ["matlab_files"]


def lit(value: float) -> str:
    """A MATLAB literal that reads back as the same double."""
    value = float(value)
    if np.isinf(value):
        return "Inf" if value > 0 else "-Inf"
    return repr(value)


def _column(values: np.ndarray) -> str:
    items = [lit(v) for v in np.asarray(values, dtype=float).ravel()]
    rows = [", ".join(items[i:i + 6]) for i in range(0, len(items), 6)]
    return "[" + " ...\n     ".join(rows) + "]'"


def _comment(plan: ExportPlan, what: str) -> str:
    p = {key: comment_text(value) for key, value in plan.provenance.items()}
    return f"""% {what}
% Hysteresis compensator exported by hystkit {p['hystkit']} on {p['exported']}.
% Do not edit: re-export from the model file instead.
%
% model family : {p['family']}
% mode         : {p['mode']}
% structure    : {p['structure']}
% centring     : {p['center']} (causal)
% source file  : {p['source']}
% fit date     : {p['fit_date']}
% band         : {p['band']}
"""


def _constants(plan: ExportPlan) -> dict[str, str]:
    return {k: lit(v) for k, v in plan.constants.items()}


def _normalise(plan: ExportPlan, st: str, sensor: str = "sensor", s: str = "s") -> str:
    """Code setting ``s`` from ``sensor``, the centring's state in ``{st}sum_z`` etc. (``st.``
    in the function below; the chunk's loop keeps it in plain variables, ``st`` empty)."""
    c = _constants(plan)
    if plan.center in ("fit", "none"):
        offset = c["SENSOR_OFFSET"]
        level = ""
    else:
        offset = f"(({c['SENSOR_OFFSET']} + {st}level) - {c['SENSOR_REFERENCE']})"
        if plan.center == "tare":
            level = f"""if {st}n_seen < {int(plan.constants['N_TARE'])}
    {st}sum_z = {st}sum_z + {sensor};
    {st}n_seen = {st}n_seen + 1;
    {st}level = {st}sum_z / {st}n_seen;
end
"""
        else:
            level = f"""num = {st}sum_z + {c['TRACK_A']} * {sensor};
den = {st}weight_z + {c['TRACK_A']} * 1.0;
{st}sum_z = {sensor} * 0.0 - num * {c['TRACK_A1']};
{st}weight_z = 0.0 - den * {c['TRACK_A1']};
{st}level = num / den;
"""
    return f"{level}{s} = ({c['POLARITY']} * ({sensor} - {offset})) / {c['SENSOR_SCALE']};\n"


def _centring(plan: ExportPlan) -> str:
    return f"""function [s, st] = normalised(st, sensor)
% the model's input: offset removed, flipped by the polarity, scaled (eq. 5.10)
{_normalise(plan, "st.")}end
"""


def _body(plan: ExportPlan) -> str:
    return f"""function B = body()
% the family block's parameters (Family.block(...).body)
B = {_column(plan.body)};
end
"""


_LOAD = """function x = model_load(B, x_block)
x = x_block(:);
end
"""


def _init(plan: ExportPlan) -> str:
    n = plan.name
    load = plan.translation.m_load or _LOAD
    return _comment(plan, f"{n}_init.m") + f"""function state = {n}_init(first_sensor, x_model)
% state = {n}_init(first_sensor): at rest at the first sensor sample (pass that sample to
% {n} too). state = {n}_init([], x_model): from a saved model state (the family block's state
% vector, as hystkit's Stream and {n}_sync give it); the centring starts afresh.
state = struct('x', zeros({plan.n_state}, 1), 'level', 0.0, 'sum_z', 0.0, 'weight_z', 0.0, ...
               'n_seen', 0{_BAND_FIELDS if plan.band else ''});
if nargin > 1
    state.x = model_load(body(), x_model);
    return;
end
[s, probe] = normalised(state, first_sensor);
state.x = model_rest(body(), s);
end

{load}
{_centring(plan)}
{_body(plan)}
{plan.translation.m_model(plan, lit)}"""


_BAND_FIELDS = (", ...\n               'band_started', 0, 'band_previous', 0.0, 'band_rate', 0.0, "
                "'band_outside', 0.0")


def _band(plan: ExportPlan) -> str:
    """``band_half``: the band's feature state (``_band.BandState``) and its half-width per
    sample, ``_band._features_kernel`` then ``_band.half_width`` in their order of
    operations."""
    b = {k: lit(v) for k, v in plan.band.items()}
    return f"""function [h, st] = band_half(st, s)
% the prediction band's half-width [mm] at normalised sensor sample s (hystkit's
% compensation._band): the rate's running mean and the remembered excursion beyond the training
% range (causal), then q * sigma + w * o
if st.band_started
    d = abs(s - st.band_previous) / {b['DT']};
else
    d = 0.0;
end
st.band_rate = {b['DECAY']} * st.band_rate + {b['GAIN']} * d;
beyond = max(max({b['LOW']} - s, s - {b['HIGH']}), 0.0) / {b['WIDTH']};
st.band_outside = max(beyond, {b['DECAY']} * st.band_outside);
st.band_previous = s;
st.band_started = 1;
h = {b['Q']} * (({b['BASE']} + {b['SHARE']} * st.band_rate / {b['RATE_REFERENCE']}) ...
    + max(st.band_rate / {b['RATE_HIGH']} - 1.0, 0.0)) + {b['POSITION_WIDTH']} * st.band_outside;
end
"""


_CENTRING_STATE = ("level", "sum_z", "weight_z", "n_seen")


def _chunk(plan: ExportPlan) -> str:
    """``NAME.m``. Octave interprets every statement and call, so only what carries state runs
    per sample: the model step (a call), a drifting centring and the band (in the loop); a
    fixed centring, the estimate and the flags are array operations on the whole chunk, the
    same arithmetic per sample."""
    n, c = plan.name, _constants(plan)
    if plan.band is None:
        outputs, doc, start, step, sub, band = "[estimate, state, flags]", "", "", "", "", ""
    else:
        outputs = "[estimate, state, flags, lower, upper]"
        doc = (f"% lower, upper: the prediction band [mm] of each estimate at nominal level "
               f"{plan.band['LEVEL']:g}; its\n% features are carried in state.\n")
        start = "h = zeros(size(sensor));\n"
        step = "    [h(i), state] = band_half(state, s);\n"
        sub = "\n" + _band(plan)
        band = "lower = estimate - h;\nupper = estimate + h;\n"
    if plan.center in ("fit", "none"):  # s depends on the sample alone
        before = _normalise(plan, "", "sensor", "u")
        per_sample = "    s = u(i);\n"
        load = save = ""
    else:
        before = "u = zeros(size(sensor));\n"
        per_sample = indent(_normalise(plan, "", "sensor(i)"), "    ") + "    u(i) = s;\n"
        load = "".join(f"{f} = state.{f}; " for f in _CENTRING_STATE)[:-1] + "\n"
        save = "".join(f"state.{f} = {f}; " for f in _CENTRING_STATE)[:-1] + "\n"
    return _comment(plan, f"{n}.m") + f"""function {outputs} = {n}(sensor, state)
% [estimate, state, flags] = {n}(sensor, state): position estimates [mm] for a chunk of sensor
% samples. state omitted or [] starts at rest at sensor(1) ({n}_init); pass the returned state
% to the next call. flags per sample: 1 sensor outside the training range, 2 estimate outside
% the training positions, 4 model output not finite or beyond 1e6 x the training range.
{doc}if nargin < 2 || isempty(state)
    state = {n}_init(sensor(1));
end
B = body();
p = zeros(size(sensor));
{start}x = state.x;
{load}{before}for i = 1:numel(sensor)
{per_sample}{step}    [p(i), x] = model_step(B, x, s);
end
state.x = x;
{save}estimate = p * {c['POSITION_SCALE']} + {c['POSITION_OFFSET']};
flags = (u < {c['SENSOR_LOW']} | u > {c['SENSOR_HIGH']}) ...
        + 2 * (estimate < {c['ESTIMATE_LOW']} | estimate > {c['ESTIMATE_HIGH']}) ...
        + 4 * (~(abs(p) <= {c['MAX_NORMALISED']}) | ~isfinite(estimate));
{band}end
{sub}
{_body(plan)}
{plan.translation.m_model(plan, lit)}"""


def _block(plan: ExportPlan) -> str:
    n = plan.name
    if plan.band is None:
        outputs, call, doc = "estimate", "[estimate, state]", ""
    else:
        outputs, call = "[estimate, lower, upper]", "[estimate, state, ~, lower, upper]"
        doc = "% lower, upper: the estimate's prediction band [mm].\n"
    return _comment(plan, f"{n}_block.m") + f"""function {outputs} = {n}_block(sensor)
% estimate = {n}_block(sensor): one sample in, one estimate [mm] out, the state kept in a
% persistent variable (for a Simulink MATLAB Function block). Starts at rest at the first
% sample; 'clear {n}_block' starts again.
{doc}persistent state
if isempty(state)
    state = {n}_init(sensor);
end
{call} = {n}(sensor, state);
end
"""


def _sync(plan: ExportPlan) -> str:
    n = plan.name
    return _comment(plan, f"{n}_sync.m") + f"""function state = {n}_sync()
% state = {n}_sync(): the state after the synchronisation excitation e_sync (eq. 2.21-2.22);
% run e_sync on the device, then use this instead of {n}_init. Centring starts afresh.
state = {n}_init([], {_column(plan.sync_state)});
end
"""


def matlab_files(plan: ExportPlan) -> dict[str, str]:
    """File name -> text of the MATLAB export.

    Parameters
    ----------
    plan : ExportPlan
        The export plan.

    Returns
    -------
    dict of str to str
        ``NAME.m``, ``NAME_init.m``, ``NAME_block.m``, and ``NAME_sync.m`` when the plan has
        a sync state.
    """
    files = {f"{plan.name}.m": _chunk(plan), f"{plan.name}_init.m": _init(plan),
             f"{plan.name}_block.m": _block(plan)}
    if plan.sync_state is not None:
        files[f"{plan.name}_sync.m"] = _sync(plan)
    return files
