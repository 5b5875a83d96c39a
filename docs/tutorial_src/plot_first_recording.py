"""
From your first recording to a compensator you can trust
========================================================

This tutorial takes one real device from its first recording to a compensator whose
scores and band you can believe: read the data, fit, score the fit on another run, select
a model on runs it was not fitted on, compensate with a prediction band, and write a report.
Everything runs when the site is built, so the outputs and figures below are real ones.

**The data** ship with hystkit: excerpts of the public ``piezo_micromanipulator`` data set
(a piezo flexure micromanipulator with a capacitive displacement sensor, driven by a 1 Hz
sine; Y. N. Aye and W. T. Ang, 2018, MIT licence; see :doc:`/real_data`). A piezo stack is
hysteretic: the same drive voltage gives a different displacement going up than coming down.
hystkit's "sensor" here is the measured displacement [µm] and its "position" the drive [V]
that caused it, so the compensator learns which drive produced a displacement, the inverse
hysteresis a feedforward needs. With your own sensor the roles are the usual ones: position
is what you measure against (an encoder, a caliper), sensor is the sensor's reading.

Three runs: the author's identification run, and two parts of a later test run, one driven
by his feedforward (a pre-distorted sine) and one by a plain sine. The commands are the ones
you would type in a shell; here each goes through a small helper that runs it and prints
what it printed.
"""

# %%
# Setting up
# ----------
# A fresh folder to work in, ``work``, and ``hystkit``, a helper that runs one command line
# there and prints its output. It calls :func:`hystkit.cli.main`, what the ``hystkit``
# program runs, in this Python process (one start of Python for the whole page instead of
# one per command; the output is the program's).

import contextlib
import io
import shlex
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import pandas as pd

from hystkit.cli import main

work = Path(tempfile.mkdtemp(prefix="hystkit-tutorial-"))


def hystkit(command: str) -> None:
    """Run ``hystkit COMMAND`` in ``work``, print its output; stop if it fails."""
    print(f"$ hystkit {command}")
    output = io.StringIO()
    with (contextlib.chdir(work), contextlib.redirect_stdout(output),
          contextlib.redirect_stderr(output)):
        code = main(shlex.split(command))
    print(output.getvalue(), end="")
    if code != 0:
        raise RuntimeError(f"exit code {code}: {output.getvalue()}")


# %%
# 1. Read: your first recording
# -----------------------------
# ``hystkit datasets export`` writes a data set's run as a recording (``--excerpt``: the
# copy that ships with hystkit). Your own file goes straight to ``hystkit fit``; its
# column names, time unit and separator are options or a settings file beside it
# (:doc:`/own_data`). Each export also writes ``NAME.toml`` with the columns' units,
# which every later command reads with the file.

export = "datasets export piezo_micromanipulator --excerpt"
hystkit(f"{export} --variant identification --out first.csv")
hystkit(f"{export} --variant test_feedforward --out second.csv")
hystkit(f"{export} --variant test_uncompensated --out third.csv")

names = ("first", "second", "third")
runs = {name: pd.read_csv(work / f"{name}.csv") for name in names}
runs["first"].head()

# %%
# The loops: drive against measured displacement. A straight line through them is what a
# plain calibration would use; the width of each loop is the hysteresis it cannot follow.

fig, ax = plt.subplots(figsize=(6, 4), layout="constrained")
for (name, run), style in zip(runs.items(), ("-", "--", ":")):
    ax.plot(run["sensor"], run["position"], style, lw=1, label=f"{name}.csv")
ax.set(xlabel="sensor: measured displacement [µm]",
       ylabel="position: drive [V]",
       title="Three runs of the piezo micromanipulator")
ax.legend()
plt.show()

# %%
# 2. Fit
# ------
# ``hystkit fit --model mpl`` fits one model, a 1-cell modified Power-Law (mPL) compensator
# in direct mode (sensor -> position), in a fraction of a second. (Without ``--model``,
# ``hystkit fit`` is a guided first fit: mpl with 1-3 cells, mpl-poly, pi and pl, each
# scored on held-out data, the best usable one kept, in a few tens of seconds; ``select``
# below does that over every family.) It prints the parameters
# with their standard errors, the training R² beside the straight line's, and a 90 %
# prediction band. It also says how the band was calibrated. With one recording that is
# interleaved cycles of that recording, and the note warns that it holds for runs like
# this one, not for an offset, gain or excitation that changes between runs.

hystkit("fit first.csv --model mpl --out model.json")

# %%
# 3. Evaluate on another run
# --------------------------
# A training R² says little. ``hystkit evaluate`` scores the compensator on a run it has
# not seen. The first column is **deployable**: the estimate at each sample uses only the
# sensor up to that sample and the model file, as it would in use. The *oracle* columns
# are the reference document's protocol, which also uses the scored run's own means, and
# are labelled as such. The verdict line at the end says whether the model may be used
# (exit code 3 when it may not: see :doc:`/reliability`).

hystkit("evaluate model.json third.csv")

# %%
# The compensator beats the straight line clearly on the new run. The band does not hold,
# though: read its *coverage* line. A 90 % band that covers well under 90 % of the new
# run's samples (0.40 when this page was written) was calibrated on too little
# variety. That is the warning ``fit`` gave: one recording cannot show what changes
# between runs. The cure is to train, and to validate, on more than one run.
#
# 4. Select, validated on runs the fit did not see
# ------------------------------------------------
# ``hystkit select`` tries model families, sizes, modes and centrings. It scores each the
# way it will be used: given one recording per run, each run is held out in turn
# (*left-out recording*), and the winner's band is calibrated the same way. The full
# search tries every family (a minute or so); here three families and two centrings keep
# it to seconds. ``third.csv`` stays out of it: it is the run we keep for the final check.

hystkit("select first.csv second.csv --models mpl,mpl-poly,pi "
        "--centers fit,tare --workers 1 --out best.json --report selection")

# %%
# ``select`` wrote its table and a figure of every candidate's held-out score:

selection = pd.read_csv(work / "selection" / "selection.csv")
columns = ["candidate", "cv_r2", "cv_r2_min", "cv_linear_r2", "verdict"]
selection[columns]

# %%
fig, ax = plt.subplots(figsize=(8, 5), layout="constrained")
ax.imshow(plt.imread(work / "selection" / "selection.png"))
ax.set_axis_off()
plt.show()

# %%
# The winner, on the run nobody has touched yet. The band was calibrated across runs this
# time, and its coverage is much closer to its nominal 90 % (0.82 when this page was
# written). It is still below 90 %: two short runs are little to calibrate a band on,
# and :doc:`/band` shows where bands hold and where they miss.

hystkit("evaluate best.json third.csv")

# %%
# 5. Compensate, with the band
# ----------------------------
# ``hystkit compensate`` keeps the recording's columns and adds the estimate, the band's
# lower and upper bounds, and two flags per sample: the sensor outside its training range,
# the estimate outside the training positions.

hystkit("compensate best.json third.csv --out compensated.csv")
out = pd.read_csv(work / "compensated.csv")
out.head()

# %%
# The error over time with the band around it (both relative to the true drive), and
# the estimate against the truth: a compensator without hysteresis left would draw the
# diagonal.

t = out["time"] - out["time"].iloc[0]
truth = out["position"]
fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4), layout="constrained")
left.fill_between(t, out["position_lower"] - truth, out["position_upper"] - truth,
                  alpha=0.3, lw=0, label="90 % band")
left.plot(t, out["position_estimate"] - truth, lw=0.8, color="k",
          label="estimate - true drive")
left.axhline(0, color="0.5", lw=0.5)
left.set(xlabel="time [s]", ylabel="error [V]", title="third.csv, compensated")
left.legend(loc="lower right", fontsize=8)
right.plot(truth, out["position_estimate"], lw=1)
right.plot([truth.min(), truth.max()], [truth.min(), truth.max()], "k:", lw=0.8)
right.set(xlabel="true drive [V]", ylabel="estimated drive [V]",
          title="estimate against the truth")
plt.show()

# %%
# 6. Report
# ---------
# ``hystkit report`` writes one self-contained HTML page (figures embedded, no script;
# it opens offline) with the model file's provenance, the fit, the deployable and oracle
# scores on every recording given, and the loops before and after compensation
# (:doc:`/report`). ``--figures`` also writes its figures as files; here is one of them.

hystkit("report best.json first.csv second.csv third.csv "
        "--out report.html --figures report-figures")

fig, ax = plt.subplots(figsize=(9, 6), layout="constrained")
ax.imshow(plt.imread(work / "report-figures" / "loops.png"))
ax.set_axis_off()
plt.show()

# %%
# Where to go from here
# ---------------------
# - Your own files: :doc:`/own_data`; many runs of many sensors: :doc:`/scale`.
# - How the scores are made honest: :doc:`/centring`, :doc:`/band`, :doc:`/selection`.
# - The compensator in use: :doc:`/live` (sample by sample, a serial port) and
#   :doc:`/export` (C99 and MATLAB code).
# - Every command and option: :doc:`/reference/cli`.

