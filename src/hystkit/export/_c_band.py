"""The prediction band in the C export: the state's fields, their reset and the band's
half-width per sample (``hystkit.compensation._band``), and the README's paragraph on it.

The same code for every family; a plan without a band (``plan.band is None``) gets none of it.
"""

from __future__ import annotations

from collections.abc import Callable

from ._plan import ExportPlan

__all__ = ["BAND_RESET", "BAND_STEP", "band_fields", "band_header", "band_readme",
           "band_source"]

BAND_RESET = "\n    reset_band(st);"
BAND_STEP = """
    {
        const real half = band_half(st, s);
        st->lower = estimate - half;
        st->upper = estimate + half;
    }"""


def band_header(plan: ExportPlan) -> str:
    up = plan.name.upper()
    if plan.band is None:
        return (f"/* No prediction band: the model file has none, so no lower/upper outputs. */\n"
                f"#define {up}_HAS_BAND 0\n")
    return f"""/* The prediction band: after a step, st->lower and st->upper [mm] bound the estimate it
 * returned at this nominal level (hystkit's Compensator.estimate_with_band). */
#define {up}_HAS_BAND 1
#define {up}_BAND_LEVEL {plan.band['LEVEL']!r}
"""


def band_fields(plan: ExportPlan) -> str:
    if plan.band is None:
        return ""
    n = plan.name
    return f"""
    {n}_real lower;      /* band of the last estimate [mm]: lower bound */
    {n}_real upper;      /* band of the last estimate [mm]: upper bound */
    int band_started;    /* band: a sample has been seen (the first has no rate) */
    {n}_real band_previous;  /* band: the last normalised sensor sample */
    {n}_real band_rate;  /* band: running mean of |ds/dt| of the normalised sensor [1/s] */
    {n}_real band_outside;  /* band: remembered distance outside the training range */"""


def band_source(plan: ExportPlan, lit: Callable[[float], str]) -> str:
    """The band's feature state (``_band.BandState``) and its half-width per sample:
    ``_band._features_kernel`` then ``_band.half_width``, in their order of operations."""
    if plan.band is None:
        return ""
    n = plan.name
    consts = "\n".join(f"#define BAND_{k} {lit(v)}" for k, v in plan.band.items()
                       if k != "LEVEL")
    return f"""
/* The prediction band (hystkit.compensation._band): its constants at the exported level. */
{consts}

static void reset_band({n}_state *st)
{{
    st->lower = R(0.0);
    st->upper = R(0.0);
    st->band_started = 0;
    st->band_previous = R(0.0);
    st->band_rate = R(0.0);
    st->band_outside = R(0.0);
}}

/* The band's half-width [mm] at normalised sensor sample s: the rate's running mean and the
 * remembered excursion beyond the training range (causal), then q * sigma + w * o. */
static real band_half({n}_state *st, real s)
{{
    const real d = st->band_started ? FABS(s - st->band_previous) / BAND_DT : R(0.0);
    real beyond = BAND_LOW - s;
    real kept, over;
    if (s - BAND_HIGH > beyond) beyond = s - BAND_HIGH;
    if (R(0.0) > beyond) beyond = R(0.0);
    beyond = beyond / BAND_WIDTH;
    st->band_rate = BAND_DECAY * st->band_rate + BAND_GAIN * d;
    kept = BAND_DECAY * st->band_outside;
    st->band_outside = kept > beyond ? kept : beyond;  /* max(beyond, kept) */
    st->band_previous = s;
    st->band_started = 1;
    over = st->band_rate / BAND_RATE_HIGH - R(1.0);
    if (R(0.0) > over) over = R(0.0);
    return BAND_Q * ((BAND_BASE + BAND_SHARE * st->band_rate / BAND_RATE_REFERENCE) + over)
           + BAND_POSITION_WIDTH * st->band_outside;
}}
"""


def band_readme(plan: ExportPlan) -> str:
    n = plan.name
    if plan.band is None:
        return ("\nNo prediction band: the model file has none (fitted with --no-band, or by a "
                "hystkit\nbefore bands), so the export has no lower/upper outputs.\n")
    return f"""    ./estimate --band < sensor.txt > band.txt   # estimate lower upper [mm] per line

Prediction band at nominal level {plan.band['LEVEL']:g}: after each `{n}_step`, `st.lower` and
`st.upper` [mm] bound its estimate, as Compensator.estimate_with_band in hystkit; the band's
features (rate, range excursion) are carried in the state and start afresh with `{n}_init`.
"""
