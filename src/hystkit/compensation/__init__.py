"""Compensators: fitted models that turn a sensor signal into a position estimate."""

from ._centring import (
    CENTERS,
    DEFAULT_CENTER,
    DEFAULT_TARE_SECONDS,
    DEFAULT_TRACK_SECONDS,
    DEPLOYABLE_CENTERS,
    ORACLE_CENTER,
    center_label,
)
from ._compensator import MODES, POSITION_MARGIN, SENSOR_MARGIN, Compensator
from ._conventions import LinearBaseline, Scaling, centre_and_scale, prepare_training_data
from ._estimator import CompensatorEstimator
from ._evaluate import evaluate, use_flags
from ._fitting import fit_compensator
from ._model_file import (
    MODEL_SUFFIXES,
    compensator_from_dict,
    compensator_to_dict,
    load_compensator,
    save_compensator,
)
from ._stream import StepOutput, Stream, StreamOutput, StreamState, advance
from ._sync import SyncExcitation, sync_excitation
from ._training_checks import check_excursion, check_fitting_data

__all__ = ["CENTERS", "DEFAULT_CENTER", "DEFAULT_TARE_SECONDS", "DEFAULT_TRACK_SECONDS",
           "DEPLOYABLE_CENTERS", "MODEL_SUFFIXES", "MODES", "ORACLE_CENTER", "POSITION_MARGIN",
           "SENSOR_MARGIN", "Compensator", "CompensatorEstimator", "LinearBaseline", "Scaling",
           "StepOutput", "Stream", "StreamOutput", "StreamState", "SyncExcitation", "advance",
           "center_label", "centre_and_scale", "check_excursion", "check_fitting_data",
           "compensator_from_dict", "compensator_to_dict", "evaluate", "fit_compensator",
           "load_compensator", "prepare_training_data", "save_compensator", "sync_excitation",
           "use_flags"]
