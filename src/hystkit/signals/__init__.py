"""Excitation trajectories of the document's experiments."""

from ._excitations import (
                           EXPERIMENTS,
                           Experiment,
                           decaying_sine,
                           excitation,
                           exponential_chirp,
                           filtered_noise,
                           sine,
)

__all__ = ["EXPERIMENTS", "Experiment", "decaying_sine", "excitation", "exponential_chirp",
           "filtered_noise", "sine"]
