"""
The virtual sensor's four experiments
=====================================

The reference document measured its 3D-printed sensor under four excitations: a 0.5 Hz sine
of 3 mm, a decaying sine (2 mm to 100 µm), a chirp (0.1 to 3 Hz) and band-limited noise.
``hystkit.sensors.simulate_experiment`` records each from the virtual sensor, a physical
stand-in that is deliberately not the mPL model (:doc:`/virtual_sensor`). The loops show what
a compensator has to undo: hysteresis whose width depends on the excitation's amplitude and
speed, and a slow drift.
"""

import matplotlib.pyplot as plt

from hystkit.sensors import simulate_experiment

experiments = ("sine", "decay", "chirp", "noise")
recordings = {name: simulate_experiment(name, seed=1) for name in experiments}

fig, axes = plt.subplots(2, 4, figsize=(12, 5.5), layout="constrained")
for (name, rec), loop, trace in zip(recordings.items(), axes[0], axes[1], strict=True):
    loop.plot(rec.position, rec.sensor, lw=0.4)
    loop.set(title=name, xlabel="position [mm]")
    trace.plot(rec.time, rec.sensor, lw=0.4, color="C1")
    trace.set(xlabel="time [s]")
axes[0, 0].set_ylabel("sensor ΔR/R (differential)")
axes[1, 0].set_ylabel("sensor ΔR/R")
plt.show()

# %%
# Each recording is 40 Hz after the document's preprocessing (a 20 Hz zero-phase
# Butterworth, ΔR/R about the recording's mean):

for name, rec in recordings.items():
    print(f"{name:6s} {rec.n_samples} samples, {rec.time[-1] + rec.dt:.0f} s at {rec.fs:.0f} Hz")
