"""Export a fitted compensator as code that runs where the sensor is: dependency-free C99
(microcontrollers) and MATLAB / Simulink (Octave-compatible).

The generated code repeats :meth:`hystkit.compensation.Compensator.estimate` sample by sample:
the causal centring (fit / tare / track), polarity and scaling, and the family's compiled
block (``Family.block``), translated by the family itself (``Family.export``, from its
``export.py``); and, when the compensator carries one, its prediction band
(:meth:`Compensator.estimate_with_band`: lower and upper [mm] per sample, the same code for
every family). A family, mode or centring without a translation is refused with the reason
(``Family.export_refusal``, an ``InputError``), never stubbed.
"""

from ._c import COMPILE_LINE, c_files, float_warning
from ._matlab import matlab_files
from ._plan import ExportPlan, identifier, make_plan
from ._write import LANGUAGES, export_compensator

__all__ = ["COMPILE_LINE", "LANGUAGES", "ExportPlan", "c_files", "export_compensator",
           "float_warning", "identifier", "make_plan", "matlab_files"]
