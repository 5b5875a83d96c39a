"""Closed-loop position control with a hysteretic sensor (ch. 7 of the reference document).

Names are imported on first use (PEP 562, :func:`hystkit._lazy.lazy_exports`), so parsing
``hystkit control`` options loads none of numba, scipy or python-control.
"""

from .._lazy import lazy_exports

__getattr__, __dir__ = lazy_exports(
    __name__, globals(),
    {"_words": ("slow_cell_words",),
     "_names": ("EXPERIMENTS", "MASS", "SCHEMES", "SLOW_GROWTH_S", "TRAININGS", "TYPICAL_RUN_S"),
     "_analysis": ("DOB_CANDIDATES_HZ", "bode_data", "design_dob", "loop_margins", "tune_pid"),
     "_linearise": ("classify_poles", "open_loop", "slowest_cell", "static_sign_flips"),
     "_loop_margins": ("LoopMargins",),
     "_blocks": ("DOCUMENT_PID_DIRECT", "DOCUMENT_PID_WEIGHTING", "PID", "TS",
                 "DisturbanceObserver", "Plant", "plant_matrices"),
     "_experiments": ("AMPLITUDES_MM", "FREQUENCIES_HZ", "Case", "ExperimentResult", "build_loop",
                      "cubic_trajectory", "experiment_cases", "measured_sensor_noise",
                      "noise_study", "run_experiment", "sine_reference"),
     "_noise": ("NoiseSpec", "parse_noise"),
     "_sectors": ("Sector", "chord_sector", "measure_sector"),
     "_stability": ("CircleResult", "StabilityReport", "circle_criterion", "global_stability",
                    "sector_channel"),
     "_tuning": ("HELD_OUT", "OBJECTIVES", "TuneResult", "tune_nonlinear"),
     "_loop": ("ControlLoop", "LoopState", "rest_state", "tare"),
     "_simulate": ("LoopResponse", "simulate_loop", "simulate_loop_reference"),
     "_nlsys": ("as_nlsys", "loop_initial_state", "loop_nlsys"),
     "_disk_cache": ("cached_loop_margins", "cached_sensor_models"),
     "_setup": ("LoopError", "LoopSetup", "SetupResult", "sensor_from", "setup_loop"),
     "_study": ("ControlRun", "LoopStudy", "Tuning", "examine_loop", "run_control"),
     "_plots": ("plot_bode", "plot_cases", "plot_response"),
     "_sensor_blocks": ("SensorBlock", "SensorModels", "compensator_block", "forward_block",
                        "linear_block", "sensor_block"),
     "_sensors": ("fit_forward_sensor", "fit_sensor_models", "table_ii_sensor",
                  "table_ii_sensors", "virtual_sensor_block"),
     },
    first=())
