"""``hystkit fit``'s cost options: ``--loss``, ``--f-scale``, ``--weights`` (issue 14.4).

By default a fit minimises the SSE (eq. 5.9). ``--loss`` picks one of scipy's robust losses
instead, ``--f-scale`` its residual scale (normalised units: the data are scaled to max |.| = 1
before the fit, eq. 5.10) and ``--weights`` a column of the recordings with one weight per
sample. A family takes the losses its capabilities declare (a linear least-squares fit takes
weights but no robust loss): another is refused before any data are read, with the library's
message.
"""

from __future__ import annotations

import argparse

from ._option_types import number

__all__ = ["LOSSES", "add_cost_options"]


# hystkit.identification.LOSSES, spelt out: importing it loads scipy and numba, which building
# the parser must not (tests/cli/test_fit_cost_options.py checks that the two agree)
LOSSES = ("linear", "soft_l1", "huber", "cauchy")

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
             "(outliers, spikes); a family takes the losses it declares, linear only unless "
             "it declares more (the error names the ones it takes)")
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
