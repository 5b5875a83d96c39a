"""The figure of a :class:`~._spectrum.Spectrum` (``hystkit spectrum --plot``)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure

if TYPE_CHECKING:
    from ._spectrum import Spectrum

__all__ = ["plot_spectrum"]


def plot_spectrum(spec: Spectrum, title: str = "") -> Figure:
    """PSDs, floor and threshold on log axes; the filters' zero-phase response (dB) on a
    second axis; f_signal and the cut-offs marked."""
    fig = Figure(figsize=(8, 5), layout="constrained")
    ax = fig.add_subplot()
    keep = spec.freq > 0
    f = spec.freq[keep]
    labels = {"dr1": "gauge 1 dR/R", "dr2": "gauge 2 dR/R",
              "differential": "dR1/R1 - dR2/R2"}
    for name, values in spec.psd.items():
        ax.loglog(f, values[keep], lw=0.8 if name != "differential" else 1.1,
                  label=labels[name], alpha=0.6 if name != "differential" else 1.0)
    ax.loglog(f, spec.floor[keep], "k--", lw=0.8, label="noise floor (differential)")
    ax.loglog(f, spec.floor[keep] * 10 ** (spec.rule.margin_db / 10), "k:", lw=0.8,
              label=f"floor + {spec.rule.margin_db:g} dB")
    if math.isfinite(spec.f_signal):
        ax.axvline(spec.f_signal, color="tab:red", lw=0.8)
        ax.text(spec.f_signal, 0.02, f" f_signal {spec.f_signal:.3g} Hz", color="tab:red",
                transform=ax.get_xaxis_transform(), rotation=90, va="bottom")
    # Far below the floor of the flat band only the decimation filter's edge remains.
    flat = keep & (spec.freq <= 0.4 * spec.fs)
    ax.set_ylim(bottom=max(ax.get_ylim()[0], 1e-3 * float(np.min(spec.floor[flat]))))
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("PSD [1/Hz]")
    lines, more = ax.get_legend_handles_labels(), ([], [])
    if spec.response:  # no filter to draw when no line gave a cut-off and none is compared
        twin = ax.twinx()
        for (label, h), style in zip(spec.response.items(), ("-", "-."), strict=False):
            twin.semilogx(f, 20 * np.log10(np.maximum(h[keep], 1e-12)), style,
                          color="tab:purple", lw=1.0,
                          label=f"zero-phase Butterworth {label}")
        twin.set_ylim(-120, 5)
        twin.set_ylabel("filter |H|² [dB]")
        more = twin.get_legend_handles_labels()
    ax.legend(lines[0] + more[0], lines[1] + more[1], fontsize=7, loc="lower left")
    ax.set_title(title or (f"Welch PSD; suggested cut-off {spec.cutoff:.3g} Hz"
                           if math.isfinite(spec.cutoff)
                           else "Welch PSD; no spectral line above the margin, no cut-off"))
    return fig
