"""``hystkit fit``'s cost options: ``--loss``, ``--f-scale``, ``--weights`` (issue 14.4).

By default a fit minimises the SSE (eq. 5.9). ``--loss`` picks one of scipy's robust losses
instead, ``--f-scale`` its residual scale (normalised units: the data are scaled to max |.| = 1
before the fit, eq. 5.10) and ``--weights`` a column of the recordings with one weight per
sample. A model whose fit is a linear least-squares solve takes weights but no robust loss:
it is refused here, before any data are read, with the library's message.
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass
from pathlib import Path

from ._common import UsageError, number, read_options

__all__ = ["LOSSES", "CostOptions", "add_cost_options", "cost_options", "print_cost_summary"]


# hystkit.identification.LOSSES, spelt out: importing it loads scipy and numba, which building
# the parser must not (tests/cli/test_fit_cost_options.py checks that the two agree)
LOSSES = ("linear", "soft_l1", "huber", "cauchy")

_DEFAULT_F_SCALE_WARNING = ("hystkit: warning: --loss {loss} without --f-scale: f_scale 1 "
                            "leaves a robust loss close to the SSE on the normalised data "
                            "(max |.| = 1); set --f-scale to 5-10 times the plain fit's RMS "
                            "residual")


def add_cost_options(parser: argparse.ArgumentParser) -> None:
    """Add ``--loss``, ``--f-scale`` and ``--weights`` to the ``fit`` parser.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The ``fit`` subcommand's parser.
    """
    parser.add_argument(
        "--loss", default="linear", choices=LOSSES,
        help="cost the fit minimises: linear = the SSE (eq. 5.9, default); soft_l1, huber, "
             "cauchy = scipy's robust losses, which count residuals beyond --f-scale less "
             "(outliers, spikes); models fitted by linear least squares (preisach, gpreisach, "
             "bobbio, pi) take linear only")
    parser.add_argument(
        "--f-scale", type=number(0, low_open=True), default=None, metavar="F",
        help="residual scale of a robust --loss, > 0, in normalised units: the data are "
             "scaled to max |.| = 1 before the fit (eq. 5.10), so 0.05 is 5 %% of the largest "
             "|value|; default 1 (scipy's), which on such data leaves a robust loss close to "
             "the SSE: set it to 5-10 times the plain fit's RMS residual, below the outliers")
    parser.add_argument(
        "--weights", default=None, metavar="COLUMN",
        help="column of the recording(s) with one weight per sample (finite, >= 0; 0 drops "
             "a sample from the cost); the fit minimises the weighted cost, while R², AIC and "
             "BIC stay on the plain SSE")


@dataclass(frozen=True)
class CostOptions:
    """The cost a ``fit`` command asked for, checked against its model."""

    loss: str = "linear"
    f_scale: float = 1.0
    weights: str | None = None

    def fit_arguments(self, args: argparse.Namespace, recs: list) -> dict:
        """Keyword arguments of `hystkit.compensation.fit_compensator` for the recordings
        `recs` read from ``args.data`` (the weights column read with the same read options);
        empty for the plain SSE."""
        out: dict = {}
        if self.loss != "linear":
            out.update(loss=self.loss, f_scale=self.f_scale)
        if self.weights is not None:
            from ..io import read_other_columns

            out["weights"] = self.weights
            out["other_columns"] = [
                read_other_columns(path, rec.n_samples, read_options(args, Path(path)))
                for path, rec in zip(args.data, recs, strict=True)]
        return out


def cost_options(args: argparse.Namespace) -> CostOptions:
    """The parsed cost options, refused in one line (before any work) where they do not apply.

    A robust ``--loss`` without ``--f-scale`` runs with scipy's f = 1 and a warning on stderr:
    on data normalised to max |.| = 1 that leaves the loss close to the SSE.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed ``fit`` arguments (``model``, ``loss``, ``f_scale``, ``weights``,
        ``weight_sum_max``).

    Returns
    -------
    CostOptions
        The cost to fit with.

    Raises
    ------
    UsageError
        ``--f-scale`` without a robust loss, an empty ``--weights``, or ``--weights`` with
        ``--weight-sum-max``.
    InputError
        A robust loss for a model fitted by linear least squares
        (:func:`hystkit.compensation._fitting.check_loss_available`).
    """
    from ..compensation._fitting import check_loss_available

    if args.f_scale is not None and args.loss == "linear":
        raise UsageError("--f-scale applies to a robust --loss (soft_l1, huber, cauchy), not "
                         "to linear (the SSE)")
    f_scale = 1.0 if args.f_scale is None else args.f_scale
    check_loss_available(args.model, args.loss, f_scale)
    if args.weights is not None and not args.weights.strip():
        raise UsageError("--weights needs a column name")
    if args.weights is not None and getattr(args, "weight_sum_max", None) is not None:
        raise UsageError("--weight-sum-max is solved on the SSE (eq. 5.9), not with --weights")
    if args.loss != "linear" and args.f_scale is None:
        print(_DEFAULT_F_SCALE_WARNING.format(loss=args.loss), file=sys.stderr)
    return CostOptions(loss=args.loss, f_scale=f_scale, weights=args.weights)


def print_cost_summary(info: dict) -> None:
    """Print what a fit minimised when that was not the plain SSE.

    Parameters
    ----------
    info : dict
        ``fit_info`` of :func:`hystkit.compensation.fit_compensator`; nothing is printed for
        the plain SSE, whose value ``fit`` prints itself.
    """
    if info.get("criteria_note") is not None:
        print(f"  minimised the {info['objective_label']}: {info['objective']:.4g} "
              f"(normalised); R², AIC and BIC are on the plain SSE")
