"""gyrocomp: remove the deterministic errors of MEMS gyroscopes from logged data, and prove it.

Internal units: angular rate [deg/s], acceleration [g], temperature [degC], time [s].
"""

from ._version import __version__

from .allan import AllanResult, allan_deviation, noise_parameters
from .calibration import Calibration
from .compensate import Compensator, apply, predict_error
from .errors import (
    DataQualityWarning,
    GyrocompError,
    InputError,
    MissingDependencyError,
    ModelChoiceWarning,
    ModelError,
    NotFittedError,
    PlausibilityWarning,
    TemperatureRangeWarning,
)
from .evaluation import evaluate, evaluate_stages
from .io import read
from .io import write_recording as write
from .metrics import Evaluation, evaluate_run
from .models import PolynomialTemperatureModel
from .models.pipelines import fit_calibration, fit_channels
from .models.pose_rotation import fit_gyro_between_poses, rotation_errors
from .models.triad_fit import find_poses, fit_accel_multiposition, fit_gyro_rate_table
from .noise import analyse_noise
from .recording import Recording
from .simulate import simulate
from .triad import TriadCalibration
from .validation import validate

#: ``gyrocomp.fit`` is :func:`fit_calibration`: recordings in, a frozen Calibration out
fit = fit_calibration

__all__ = [
    "AllanResult", "Calibration", "Compensator", "DataQualityWarning", "Evaluation", "GyrocompError", "InputError",
    "MissingDependencyError", "ModelChoiceWarning", "ModelError", "NotFittedError", "PlausibilityWarning", "PolynomialTemperatureModel",
    "Recording", "TemperatureRangeWarning", "TriadCalibration", "allan_deviation", "analyse_noise", "apply", "evaluate",
    "evaluate_run", "evaluate_stages", "find_poses", "fit", "fit_accel_multiposition", "fit_calibration",
    "fit_channels", "fit_gyro_between_poses", "fit_gyro_rate_table", "noise_parameters",
    "predict_error", "read", "rotation_errors", "simulate", "validate", "write", "__version__",
]
