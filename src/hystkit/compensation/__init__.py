"""Compensators: fitted models that turn a sensor signal into a position estimate.

Fitting, the model file, the band, the verdict and offline evaluation; running a compensator
sample by sample on a live sensor is :mod:`hystkit.live`.

Names are imported on first use (PEP 562, :func:`hystkit._lazy.lazy_exports`), so a command
that only needs the centring names (``hystkit fit --help``) loads no scipy, numba or pandas.
"""

from .._lazy import lazy_exports

__getattr__, __dir__ = lazy_exports(
    __name__, globals(),
    {"_redundancy": ("redundancy_notes",),
     "_param_vector": ("named_floats",),
     "_centring": ("CENTERS", "DEFAULT_CENTER", "DEFAULT_TARE_SECONDS", "DEFAULT_TRACK_SECONDS",
                   "DEPLOYABLE_CENTERS", "ORACLE_CENTER", "center_label"),
     "_modes": ("MODES",),
     # with the band's per-sample pieces the live stream and its compiled kernel share
     "_band": ("BAND_SCORE_KEYS", "DEFAULT_LEVEL", "Band", "BandState", "band_features",
               "feature_decay", "feature_range", "feature_step", "half_width", "interval",
               "interval_scores", "position_width"),
     "_calibration": ("calibrate_band", "with_band"),
     "_compensator": ("POSITION_MARGIN", "SENSOR_MARGIN", "BandedEstimate", "Compensator"),
     "_conventions": ("LinearBaseline", "Scaling", "centre_and_scale", "prepare_training_data"),
     "_estimator": ("CompensatorEstimator",),
     "_evaluate": ("evaluate", "use_flags"),
     "_fitting": ("fit_compensator",),
     "_fit_info": ("FitInfo",),
     "_fit_costs": ("check_loss_available", "supported_losses",
                    "weight_column"),
     "_runaway": ("MAX_NORMALISED", "runaway_kind", "runaway_samples"),
     "_folds": ("EXTRAPOLATION_NOTE", "ONE_RUN_CAVEAT", "Candidate", "PROTOCOLS", "Fold",
                "admissible_size", "fit_fold", "fits_in", "fold_scores", "folds", "protocol"),
     "_model_file": ("MODEL_SUFFIXES", "compensator_from_dict", "compensator_to_dict",
                     "load_compensator", "save_compensator"),
     "_training_checks": ("MIN_SAMPLES_PER_PARAM", "check_excursion", "check_fitting_data",
                          "count_fitted"),
     "_verdict": ("FAR_MARGIN", "MAX_OUTSIDE", "MIN_EXPLAINED", "MIN_USABLE", "USE_STATUSES",
                  "pooled_verdict", "use_verdict", "verdict")},
    first=())
