"""Noise in the loop: white Gaussian sensor and process noise, reproducible from a seed.

Sensor noise is added to the sensor signal ``s`` [sensor units] after ``S_r`` (the kernel's
``noise`` input), so the compensator, ``S_m``'s comparison and the DOB all see it. Process
noise is a force [N] added to the plant input (the kernel's ``d_in``), as a vibrating base or a
noisy amplifier would. Both are drawn per case from ``numpy.random.default_rng([seed, case])``:
the same seed gives the same noise, whatever else the run does.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["NoiseSpec", "parse_noise"]


@dataclass(frozen=True)
class NoiseSpec:
    """Standard deviations of the loop's noise inputs and the seed they are drawn with.

    Parameters
    ----------
    sensor : float
        SD of the additive sensor noise [sensor units] (one draw per sample ``Ts``).
    process : float
        SD of the additive plant-input force noise [N].
    seed : int
        Seed of ``numpy.random.default_rng``; case ``k`` of an experiment draws from
        ``default_rng([seed, k])``.
    """

    sensor: float = 0.0
    process: float = 0.0
    seed: int = 0

    def __post_init__(self) -> None:
        for name in ("sensor", "process"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                raise ValueError(f"noise {name} SD must be a finite number >= 0, got {value!r}")
        if not (isinstance(self.seed, int | np.integer) and self.seed >= 0):
            raise ValueError(f"noise seed must be an integer >= 0, got {self.seed!r}")

    @property
    def silent(self) -> bool:
        """Both SDs are zero."""
        return self.sensor == 0 and self.process == 0

    def draw(self, n_steps: int, case: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """``(sensor_noise [sensor units], process_noise [N])``, each shape ``(n_steps,)``.

        Sensor noise is drawn first, then process noise, from one generator; a zero SD gives
        exact zeros (so a silent spec runs bit for bit like a run without noise).
        """
        rng = np.random.default_rng([self.seed, case])
        sensor = self.sensor * rng.standard_normal(n_steps)
        process = self.process * rng.standard_normal(n_steps)
        return sensor + 0.0, process + 0.0  # + 0.0: -0.0 from a zero SD becomes 0.0

    def to_dict(self) -> dict:
        """JSON-safe: ``sensor_sd`` [sensor units], ``process_sd_n`` [N], ``seed``."""
        return {"sensor_sd": self.sensor, "process_sd_n": self.process, "seed": self.seed}


def parse_noise(text: str) -> NoiseSpec:
    """``"sensor=SD,process=SD[,seed=N]"`` (any subset, any order) as a :class:`NoiseSpec`.

    Parameters
    ----------
    text : str
        Comma-separated ``key=value`` items: ``sensor`` [sensor units] and ``process`` [N]
        standard deviations, ``seed`` an integer; a key left out keeps its default.

    Returns
    -------
    NoiseSpec
        The parsed specification.

    Raises
    ------
    ValueError
        With one line naming the bad item.
    """
    values: dict = {}
    for item in (x.strip() for x in text.split(",")):
        key, sep, value = item.partition("=")
        key = key.strip()
        if not sep or key not in ("sensor", "process", "seed"):
            raise ValueError(f"{item!r}: expected sensor=SD, process=SD or seed=N")
        if key in values:
            raise ValueError(f"{key} given twice")
        try:
            values[key] = int(value) if key == "seed" else float(value)
        except ValueError:
            raise ValueError(f"{key}={value!r}: not a number") from None
    return NoiseSpec(**values)
