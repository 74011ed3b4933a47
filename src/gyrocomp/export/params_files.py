"""The PX4 and ArduPilot parameter files as export formats (``px4``, ``ardupilot``): the parameters computed
once, the file written from them atomically, its header's steps returned as notes, and how far the firmware's
correction is from the model's (:mod:`gyrocomp.export.firmware`)."""

from __future__ import annotations

import warnings
from collections.abc import Callable
from pathlib import Path

from ..calibration import Calibration
from ..io.atomic import write_text_atomic
from ..recording import GYRO_AXES
from .autopilot import ardupilot_parameters, ardupilot_params_text, px4_parameters, px4_params_text
from .firmware import firmware_difference
from .exporters import ExportOptions, Exported, Exporter, register


def _autopilot(target: str) -> Callable[[Calibration, Path, ExportOptions], Exported]:
    def write(calibration: Calibration, path: Path, options: ExportOptions) -> Exported:
        slot = (0 if target == "px4" else 1) if options.instance is None else options.instance
        if target == "px4":
            params = px4_parameters(
                calibration, instance=slot, device_id=options.device_id, accel_device_id=options.accel_device_id
            )
            text = px4_params_text(calibration, params)
        else:
            params = ardupilot_parameters(calibration, instance=slot)
            text = ardupilot_params_text(calibration, params)
        write_text_atomic(path, text)
        notes = []
        for line in text.splitlines()[1:]:  # the header comments after the title: what the file is, the steps
            if not line.startswith("#"):
                break
            notes.append(line.lstrip("# "))
        difference = None
        if options.judge_firmware and any(
            a in calibration.axes and calibration.axes[a].temperature is not None for a in GYRO_AXES
        ):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # the model continued past its range: that is the point here
                difference = firmware_difference(calibration, params.values, target, slot)
        return Exported(target, (path,), tuple(notes), difference)

    return write


register(
    Exporter(
        "px4",
        "PX4 TC_G*/TC_A* parameters for QGroundControl",
        "lag, hysteresis, g-sensitivity, gyro scale factor; a cubic held at TMIN/TMAX",
        _autopilot("px4"),
        suffixes=(".params",),
    )
)
register(
    Exporter(
        "ardupilot",
        "ArduPilot INS_TCAL* parameters",
        "lag, hysteresis, g-sensitivity, gyro scale factor, the constant; a cubic about 35 degC held at TMIN/TMAX",
        _autopilot("ardupilot"),
        suffixes=(".parm", ".param"),
    )
)

__all__: list[str] = []
