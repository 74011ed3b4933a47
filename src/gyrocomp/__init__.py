"""gyrocomp: remove the deterministic errors of MEMS gyroscopes from logged data, and prove it.

Internal units: angular rate [deg/s], acceleration [g], temperature [degC], time [s].

The names below are imported from their modules the first time they are used (PEP 562), so ``import gyrocomp``
and the command line's ``--help`` start without loading numpy, scipy and pandas; ``from gyrocomp import X``
works as usual.
"""

from __future__ import annotations

from ._version import __version__
from .lazy import lazy_exports

#: public name -> (module, name in it)
_EXPORTS = {
    "AllanResult": ("allan", "AllanResult"),
    "allan_deviation": ("allan", "allan_deviation"),
    "noise_parameters": ("allan", "noise_parameters"),
    "Calibration": ("calibration", "Calibration"),
    "Compensator": ("calibration.compensate", "Compensator"),
    "apply": ("calibration.compensate", "apply"),
    "predict_error": ("calibration.compensate", "predict_error"),
    **{
        name: ("errors", name)
        for name in (
            "DataQualityWarning",
            "GyrocompError",
            "InputError",
            "MissingDependencyError",
            "ModelChoiceWarning",
            "ModelError",
            "NotFittedError",
            "PlausibilityWarning",
            "TemperatureRangeWarning",
            "TimeOrderError",
            "UnusedOptionWarning",
        )
    },
    "evaluate": ("evaluation", "evaluate"),
    "evaluate_stages": ("evaluation", "evaluate_stages"),
    "read": ("io", "read"),
    "write": ("io", "write_recording"),
    "Evaluation": ("measures.merit", "Evaluation"),
    "evaluate_run": ("measures.merit", "evaluate_run"),
    "PolynomialTemperatureModel": ("fitting.polynomial_model", "PolynomialTemperatureModel"),
    "fit_calibration": ("models.joint", "fit_calibration"),
    "fit_channels": ("models.fit", "fit_channels"),
    "fit_pipeline": ("models.pipelines", "fit_pipeline"),
    **{name: ("models.options", name) for name in ("Curve", "FitOptions", "Network", "Polynomial")},
    "FitReport": ("calibration.fit_report", "FitReport"),
    "analyse_noise_file": ("files", "analyse_noise_file"),
    "evaluate_file": ("files", "evaluate_file"),
    "apply_file": ("files", "apply_file"),
    "convert_file": ("files", "convert_file"),
    # the one entry point: runs and typed options in, a frozen Calibration out (the others wrap it)
    "fit": ("models.fit", "fit"),
    "fit_gyro_between_poses": ("fitting.pose_rotation", "fit_gyro_between_poses"),
    "rotation_errors": ("fitting.pose_rotation", "rotation_errors"),
    "find_poses": ("fitting.triad_fit", "find_poses"),
    "fit_accel_multiposition": ("fitting.triad_fit", "fit_accel_multiposition"),
    "fit_gyro_rate_table": ("fitting.rate_table", "fit_gyro_rate_table"),
    "analyse_noise": ("measures.noise", "analyse_noise"),
    "Recording": ("recording", "Recording"),
    "simulate": ("simulation", "simulate"),
    "TriadCalibration": ("calibration.triad", "TriadCalibration"),
    "validate": ("evaluation.validation", "validate"),
    "UseProfile": ("evaluation.drift_forecast", "UseProfile"),
    "forecast_drift": ("evaluation.drift_forecast", "forecast_drift"),
    "plan": ("evaluation.run_advice", "plan"),
    "detect_still": ("motion.stillness", "detect_still"),
    "StillnessState": ("motion.stillness", "StillnessState"),
    "field_recordings": ("models.field", "field_recordings"),
    "OnlineCalibrator": ("fitting.online", "OnlineCalibrator"),
    "LearnerSettings": ("fitting.online", "LearnerSettings"),
}


__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)

__all__ = sorted(_EXPORTS) + ["__version__"]
