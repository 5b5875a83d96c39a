"""Write an :class:`ExportPlan` as dependency-free C99: ``NAME.h``, ``NAME.c``,
``example_main.c`` and a ``README``.

The compensator's files use nothing but ``math.h`` (no allocation, no I/O): the state is a
struct the caller owns, ``NAME_init`` starts it at rest at the first sensor sample (as
``Compensator.estimate`` and ``simulate(x0=None)`` do), ``NAME_step`` turns one sensor sample
into one position estimate [mm]. ``float`` by default (single-precision FPUs of
microcontrollers), ``double`` on request. The generated arithmetic repeats the Python
reference's operations in the same order (centring of ``_centring.sensor_level``, then
``Compensator.normalised_sensor``, the family block, ``p * scale + offset``). With a
prediction band, ``NAME_step`` also sets ``st->lower`` and ``st->upper`` [mm], the band of
that estimate (``Compensator.estimate_with_band``): its features (``_band._features_kernel``)
are carried in the state like the model's own.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ._c_band import BAND_RESET, BAND_STEP, band_fields, band_header, band_readme, band_source
from ._comments import c_comment_text, comment_text
from ._plan import ExportPlan

__all__ = ["COMPILE_LINE", "c_files", "float_warning"]

COMPILE_LINE = "cc -O2 -std=c99 *.c -lm -o estimate"

_MATH = {  # macro -> (double, float) function of math.h
    "FABS": ("fabs", "fabsf"), "SINH": ("sinh", "sinhf"), "COSH": ("cosh", "coshf"),
    "EXP": ("exp", "expf"), "LOG": ("log", "logf"), "TANH": ("tanh", "tanhf"), "POW": ("pow", "powf"),
    "ASINH": ("asinh", "asinhf"), "SQRT": ("sqrt", "sqrtf"), "FLOOR": ("floor", "floorf"),
}


def literal(double: bool) -> Callable[[float], str]:
    """Formatter of a number as a C literal that rounds to the same double / float."""

    def lit(value: float) -> str:
        value = float(value)
        if np.isinf(value):
            return "((real)HUGE_VAL)" if value > 0 else "(-(real)HUGE_VAL)"
        if not double:
            return f"{np.format_float_scientific(np.float32(value), unique=True)}f"
        text = repr(value)
        return text if ("." in text or "e" in text or "n" in text) else f"{text}.0"

    return lit


def _array(name: str, values: np.ndarray, lit: Callable[[float], str]) -> str:
    items = [lit(v) for v in np.asarray(values, dtype=float).ravel()]
    rows = [", ".join(items[i:i + 4]) for i in range(0, len(items), 4)]
    body = ",\n    ".join(rows)
    return f"static const real {name}[{max(1, len(items))}] = {{\n    {body}\n}};\n"


def float_warning(plan: ExportPlan) -> str:
    """Why a float export of this model will not follow the double reference.

    Parameters
    ----------
    plan : ExportPlan
        The export plan; its float sensitivity is read (:func:`make_plan` measures it).

    Returns
    -------
    str
        The reason on one line, or "" if float is enough.
    """
    if plan.float_is_enough:
        return ""
    return (f"float is not enough for this model: rounding its input to float moves its output "
            f"by {plan.float_sensitivity:.2g} of its range (weights that nearly cancel); "
            f"export with --double")


def _float_note(plan: ExportPlan) -> str:
    if plan.float_sensitivity != plan.float_sensitivity:  # NaN: the probe could not run
        return ("Float check: not possible (the model leaves the finite range on the probe "
                "chirp even in double); compare with --double on your data.\n")
    return ""


def _comment(plan: ExportPlan, what: str, double: bool) -> str:
    p = {key: c_comment_text(value) for key, value in plan.provenance.items()}
    warning = "" if double or plan.float_is_enough else f" *\n * WARNING: {float_warning(plan)}\n"
    return f"""/* {what}
 * Hysteresis compensator exported by hystkit {p['hystkit']} on {p['exported']}.
 * Do not edit: re-export from the model file instead.
 *
 * model family : {p['family']}
 * mode         : {p['mode']} ({'the inverse of a fitted position -> sensor model' if plan.inverse
                                else 'a fitted sensor -> position model'})
 * structure    : {p['structure']}
 * centring     : {p['center']} (causal; see docs/centring.md)
 * source file  : {p['source']}
 * fit date     : {p['fit_date']}
 * band         : {p['band']}
 * arithmetic   : {'double' if double else 'float'}
{warning} */
"""


def _header(plan: ExportPlan, double: bool) -> str:
    n, up = plan.name, plan.name.upper()
    sync = "" if plan.sync_state is None else f"""
/* Start after the synchronisation excitation e_sync (eq. 2.21-2.22): run e_sync on the device,
 * then call this instead of {n}_init; the centring starts with the next sample. */
void {n}_sync({n}_state *st);
"""
    return _comment(plan, f"{n}.h", double) + f"""
#ifndef {up}_H
#define {up}_H

typedef {'double' if double else 'float'} {n}_real;

#define {up}_N_STATE {plan.n_state}
/* Bits of st->flags after a step (the use-time guards of 'hystkit evaluate'). */
#define {up}_SENSOR_OUTSIDE 1u  /* sensor beyond the training range (+-5 % of its width) */
#define {up}_ESTIMATE_OUTSIDE 2u  /* estimate beyond the training positions (+-10 %) */
#define {up}_RAN_AWAY 4u  /* model output not finite or beyond 1e6 x the training range */
{band_header(plan)}
typedef struct {{
    {n}_real x[{up}_N_STATE];  /* model state, normalised units */
    {n}_real level;      /* sensor level removed (tare / track centring) */
    {n}_real sum_z;      /* tare: running sum; track: delay of the weighted sum */
    {n}_real weight_z;   /* track: delay of the weight sum */
    long n_seen;         /* tare: samples in the running mean so far */
    unsigned flags;      /* guard bits of the last step */{band_fields(plan)}
}} {n}_state;

/* Start at rest at the first sensor sample (then pass that sample to {n}_step too). */
void {n}_init({n}_state *st, {n}_real first_sensor);
{sync}
/* One sensor sample in, one position estimate [mm] out{
    '; its band in st->lower, st->upper' if plan.band else ''}. */
{n}_real {n}_step({n}_state *st, {n}_real sensor);

#endif
"""


def _centring(plan: ExportPlan) -> str:
    """``Compensator.normalised_sensor`` for one sample, with the causal level of
    ``_centring.sensor_level`` kept in the state."""
    tail = "    return (POLARITY * (sensor - {offset})) / SENSOR_SCALE;\n"
    if plan.center in ("fit", "none"):
        return ("    (void)st;\n" + tail.format(offset="SENSOR_OFFSET"))
    if plan.center == "tare":  # np.cumsum(s[:n_tare]) / arange(1, n_tare + 1), then held
        body = """    if (st->n_seen < N_TARE) {
        st->sum_z = st->sum_z + sensor;
        st->n_seen = st->n_seen + 1;
        st->level = st->sum_z / (real)st->n_seen;
    }
"""
    else:  # lfilter([a], [1, a - 1], s) / lfilter(.., ones): y = z + b0 x; z = x b1 - y a1
        body = """    {
        const real num = st->sum_z + TRACK_A * sensor;
        const real den = st->weight_z + TRACK_A * R(1.0);
        st->sum_z = sensor * R(0.0) - num * TRACK_A1;
        st->weight_z = R(0.0) - den * TRACK_A1;
        st->level = num / den;
    }
"""
    return body + tail.format(offset="((SENSOR_OFFSET + st->level) - SENSOR_REFERENCE)")


def _source(plan: ExportPlan, double: bool) -> str:
    n, up = plan.name, plan.name.upper()
    lit = literal(double)
    math = "\n".join(f"#define {m} {fs[0] if double else fs[1]}" for m, fs in _MATH.items())
    consts = "\n".join(f"#define {k} {lit(v)}" for k, v in plan.constants.items()
                       if k not in ("N_TARE", "DT"))
    sync = "" if plan.sync_state is None else f"""
{_array('SYNC_STATE', plan.sync_state, lit)}
void {n}_sync({n}_state *st)
{{
    int k;
    for (k = 0; k < {up}_N_STATE; k++) st->x[k] = SYNC_STATE[k];
    reset_centring(st);{BAND_RESET if plan.band else ''}
}}
"""
    model = plan.translation.c_model(plan, lit)
    return _comment(plan, f"{n}.c", double) + f"""
#include <math.h>
#include "{n}.h"

typedef {n}_real real;
#define R(v) ((real)(v))
{math}

{consts}
#define N_TARE {int(plan.constants['N_TARE'])}L

/* The family block's parameters (Family.block(...).body, the closed loop's numbers). */
{_array('BODY', plan.body, lit)}
{model}
static void reset_centring({n}_state *st)
{{
    st->level = R(0.0);
    st->sum_z = R(0.0);
    st->weight_z = R(0.0);
    st->n_seen = 0L;
    st->flags = 0u;
}}
{band_source(plan, lit)}
/* The model's input: offset removed, flipped by the polarity, scaled (eq. 5.10). */
static real normalised({n}_state *st, real sensor)
{{
{_centring(plan)}}}

void {n}_init({n}_state *st, real first_sensor)
{{
    {n}_state probe;
    reset_centring(st);{BAND_RESET if plan.band else ''}
    probe = *st;  /* the first sample's level, without counting it twice */
    model_rest(st->x, normalised(&probe, first_sensor));
}}
{sync}
real {n}_step({n}_state *st, real sensor)
{{
    const real s = normalised(st, sensor);
    const real p = model_step(st->x, s);
    const real estimate = p * POSITION_SCALE + POSITION_OFFSET;
    unsigned flags = 0u;
    if (s < SENSOR_LOW || s > SENSOR_HIGH) flags |= {up}_SENSOR_OUTSIDE;
    if (estimate < ESTIMATE_LOW || estimate > ESTIMATE_HIGH) flags |= {up}_ESTIMATE_OUTSIDE;
    if (!(FABS(p) <= MAX_NORMALISED) || !isfinite(estimate)) flags |= {up}_RAN_AWAY;
    st->flags = flags;{BAND_STEP if plan.band else ''}
    return estimate;
}}
"""


def _example(plan: ExportPlan, double: bool) -> str:
    n, up = plan.name, plan.name.upper()
    fmt = '%.17g' if double else '%.9g'
    out = f'printf("{fmt}\\n", (double){n}_step(&st, ({n}_real)value));'
    if plan.band is None:
        usage, includes, main, options = "", "", "int main(void)", ""
    else:
        usage = (" * With --band, each line is the estimate and its band: estimate lower upper "
                 "[mm].\n")
        includes = "#include <string.h>\n"
        main = "int main(int argc, char **argv)"
        options = "    const int band = argc > 1 && strcmp(argv[1], \"--band\") == 0;\n"
        out = f"""{{
            const double estimate = (double){n}_step(&st, ({n}_real)value);
            if (band) printf("{fmt} {fmt} {fmt}\\n", estimate, (double)st.lower,
                             (double)st.upper);
            else printf("{fmt}\\n", estimate);
        }}"""
    return f"""/* example_main.c: one sensor value per line on stdin, one estimate [mm] per line on stdout.
{usage} * Starts at rest at the first sample (the model file's default start-up). A line that is not
 * a number is skipped with a warning on stderr; the count of flagged samples is printed at the
 * end. Build: {COMPILE_LINE}
 */
#include <stdio.h>
#include <stdlib.h>
{includes}#include "{n}.h"

{main}
{{
{options}    char line[512];
    {n}_state st;
    int started = 0;
    long n_bad = 0, n_flagged = 0, n_line = 0;
    while (fgets(line, sizeof line, stdin) != NULL) {{
        char *end;
        double value;
        n_line++;
        value = strtod(line, &end);
        while (*end == ' ' || *end == '\\t' || *end == '\\r' || *end == '\\n') end++;
        if (end == line || *end != '\\0') {{
            fprintf(stderr, "example_main: line %ld: not a number, skipped\\n", n_line);
            n_bad++;
            continue;
        }}
        if (!started) {{
            {n}_init(&st, ({n}_real)value);
            started = 1;
        }}
        {out}
        if (st.flags & {up}_RAN_AWAY) n_flagged++;
    }}
    if (n_bad > 0) fprintf(stderr, "example_main: %ld line(s) skipped\\n", n_bad);
    if (n_flagged > 0) fprintf(stderr, "example_main: %ld estimate(s) ran away\\n", n_flagged);
    return 0;
}}
"""


def _readme(plan: ExportPlan, double: bool) -> str:
    n, p = plan.name, {key: comment_text(value) for key, value in plan.provenance.items()}
    sync = (f"- `{n}_sync(&st)`: instead of `{n}_init`, start after the synchronisation "
            f"excitation e_sync;\n  {plan.sync_note}.\n" if plan.sync_state is not None else
            f"- {plan.sync_note}\n")
    return f"""{n}: hysteresis compensator exported by hystkit {p['hystkit']}

Model: {p['family']}, {p['mode']}, centring {p['center']}
From:  {p['source']} (fit date: {p['fit_date']})
Arithmetic: {'double' if double else 'float'}; model state: {plan.n_state} number(s).
{_float_note(plan) if not double else ''}{'' if double or plan.float_is_enough else 'WARNING: ' + float_warning(plan) + chr(10)}
Build and run the example (one sensor value per line in, one estimate [mm] per line out):

    {COMPILE_LINE}
    ./estimate < sensor.txt > estimate.txt
{band_readme(plan)}
In your own program: add {n}.c and {n}.h (they need only math.h, no allocation), then

- `{n}_state st; {n}_init(&st, first_sensor);` at rest at the first sample, then
- `estimate = {n}_step(&st, sensor);` for every sample, that first one included;
{sync}- `st.flags` after a step: {n.upper()}_SENSOR_OUTSIDE, {n.upper()}_ESTIMATE_OUTSIDE,
  {n.upper()}_RAN_AWAY (the guards of `hystkit evaluate`).

Feed samples at the model's sample time, dt = {plan.constants['DT']:g} s.
"""


def c_files(plan: ExportPlan, double: bool = False) -> dict[str, str]:
    """File name -> text of the C export.

    Parameters
    ----------
    plan : ExportPlan
        The export plan.
    double : bool
        Compute in double instead of float.

    Returns
    -------
    dict of str to str
        ``NAME.h``, ``NAME.c``, ``example_main.c`` and ``README``.
    """
    return {f"{plan.name}.h": _header(plan, double), f"{plan.name}.c": _source(plan, double),
            "example_main.c": _example(plan, double), "README": _readme(plan, double)}
