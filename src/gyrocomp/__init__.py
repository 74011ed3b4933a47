"""gyrocomp: remove the deterministic errors of MEMS gyroscopes from logged data, and prove it.

Internal units: angular rate [deg/s], acceleration [g], temperature [degC], time [s].
"""

__version__ = "0.1.0"

from .allan import AllanResult, allan_deviation, noise_parameters
from .calibration import Calibration
from .compensate import Compensator, apply
from .errors import GyrocompError, InputError, ModelError, NotFittedError, TemperatureRangeWarning
from .io import read
from .metrics import Evaluation, evaluate_run
from .models import PolynomialTemperatureModel
from .models.pipelines import fit_calibration
from .noise import analyse_noise
from .recording import Recording

__all__ = [
    "AllanResult", "Calibration", "Compensator", "Evaluation", "GyrocompError", "InputError", "ModelError",
    "NotFittedError", "PolynomialTemperatureModel", "Recording", "TemperatureRangeWarning", "allan_deviation",
    "analyse_noise", "apply", "evaluate_run", "fit_calibration", "noise_parameters", "read", "__version__",
]
