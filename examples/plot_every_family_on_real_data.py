"""
Every model family on a real run
================================

``hystkit.compare`` fits every registered model family on one recording and scores it on
another: each family's forward model (position -> sensor), its inverse used as a compensator,
and a compensator fitted directly (sensor -> position), beside the straight line. Here the
recordings are the piezo micromanipulator excerpts that ship with hystkit: fitted on the
identification run, scored on the uncompensated part of the test run (real data; see
:doc:`/real_data`). The same table is ``hystkit compare FIT.csv VAL.csv`` (:doc:`/compare`).
"""

import matplotlib.pyplot as plt
import numpy as np

import hystkit as hk
from hystkit.datasets import load_excerpt

fit_run = load_excerpt("piezo_micromanipulator", "identification").to_recording()
new_run = load_excerpt("piezo_micromanipulator", "test_uncompensated").to_recording()
table = hk.compare(fit_run, new_run)
table[["n_params", "r2_forward", "r2_compensated", "r2_direct", "linear_r2", "verdict"]]

# %%
# The deployable R² of each compensator on the new run. A missing bar is a family whose
# inverse does not exist or diverged on these data (the table's ``compensated_note`` says
# which), never a silent zero.

fig, ax = plt.subplots(figsize=(9, 4), layout="constrained")
x = np.arange(len(table))
ax.bar(x - 0.2, table["r2_direct"], width=0.4, label="direct (sensor -> position)")
ax.bar(x + 0.2, table["r2_compensated"], width=0.4, label="inverse of the forward model")
ax.axhline(table["linear_r2"].iloc[0], color="k", lw=0.8, ls="--", label="straight line")
ax.set_xticks(x, table.index, rotation=30)
ax.set(ylabel="deployable R² on the new run", ylim=(0.9, 1.0),
       title="Piezo micromanipulator: every family, fitted on one run, scored on another")
ax.legend(loc="lower right", fontsize=8)
plt.show()
