"""One entry point for every export format, and the registry it reads (the extension point for a new format).

:func:`export_to` writes a calibration in a registered format and says what it wrote (:class:`Exported`); the
command line (``gyrocomp export``, ``gyrocomp fleet export``) only renders that. A format is an
:class:`Exporter`: its name, what it is, what it cannot carry, and its writer; :func:`register` adds one, so a new
format is its own module plus one registration line.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from ..calibration import Calibration
from ..errors import InputError
from ..io import write_text_atomic
from ..fitting.online import LearnerSettings
from ..recording import GYRO_AXES
from .autopilot import ardupilot_parameters, ardupilot_params_text, px4_parameters, px4_params_text
from .c_code import write_c_sources
from .firmware import FirmwareDifference, firmware_difference


@dataclass(frozen=True)
class ExportOptions:
    """What some formats need: ``rate_hz`` [Hz] (C, a model with thermal lag), ``instance`` (PX4 gyro slot 0..3,
    ArduPilot IMU 1..3), ``device_id`` / ``accel_device_id`` (PX4), ``learner`` (C: the online learner's
    settings), ``judge_firmware`` (PX4/ArduPilot: measure the firmware's correction against the model's)."""

    rate_hz: float | None = None
    instance: int | None = None
    device_id: int | None = None
    accel_device_id: int | None = None
    learner: LearnerSettings | None = None
    judge_firmware: bool = True


@dataclass(frozen=True)
class Exported:
    """What :func:`export_to` wrote: the format, the paths, the file's own notes to the user (the steps on the
    vehicle) and, for an autopilot, how far its firmware's correction is from the model's."""

    format: str
    written: tuple[Path, ...]
    notes: tuple[str, ...] = ()
    firmware: FirmwareDifference | None = None


@dataclass(frozen=True)
class Exporter:
    """A registered format: ``write(calibration, path, options)`` writes it and says what it wrote; ``suffixes``:
    the file names that mean it when no format is named (none for a format written into a folder, ``folder``)."""

    name: str
    description: str
    cannot_carry: str
    write: Callable[[Calibration, Path, ExportOptions], Exported]
    suffixes: tuple[str, ...] = ()
    folder: bool = False


EXPORTERS: dict[str, Exporter] = {}


def register(exporter: Exporter) -> Exporter:
    """Add ``exporter`` to :data:`EXPORTERS` (a name registered twice is refused)."""
    if exporter.name in EXPORTERS:
        raise InputError(f"export format {exporter.name!r} is registered already")
    EXPORTERS[exporter.name] = exporter
    return exporter


def format_of(path, offered: tuple[str, ...] | None = None) -> str:
    """The export format a path names, among ``offered`` (default every registered one): the one whose
    ``suffixes`` hold its suffix, or the one written into a folder when it has none; refuses a name that says
    none, naming the suffixes there are."""
    offered = tuple(EXPORTERS) if offered is None else offered
    suffix = Path(path).suffix.lower()
    for name in offered:
        exporter = EXPORTERS[name]
        if (suffix and suffix in exporter.suffixes) or (not suffix and exporter.folder):
            return name
    named = ", ".join(f"{s} ({n})" for n in offered for s in EXPORTERS[n].suffixes)
    folders = [n for n in offered if EXPORTERS[n].folder]
    raise InputError(f"fmt: not given, and {Path(path).name!r} names none; give it ({', '.join(offered)}), or "
                     f"name the file {named}" + (f", or a folder without a suffix ({folders[0]})" if folders else ""))


def export_to(calibration: Calibration, fmt: str, path, options: ExportOptions = ExportOptions()) -> Exported:
    """Write ``calibration`` as ``fmt`` (a name in :data:`EXPORTERS`: ``px4``, ``ardupilot``, ``c``, ``json``) to
    ``path`` (C: a folder), atomically; refuses an unknown format naming the known ones."""
    if fmt not in EXPORTERS:
        raise InputError(f"format: {fmt!r}; use one of {', '.join(EXPORTERS)}")
    return EXPORTERS[fmt].write(calibration, Path(path), options)


def _json(calibration: Calibration, path: Path, options: ExportOptions) -> Exported:
    calibration.save(path)
    return Exported("json", (path,))


def _c(calibration: Calibration, path: Path, options: ExportOptions) -> Exported:
    return Exported("c", tuple(write_c_sources(calibration, path, rate_hz=options.rate_hz, learner=options.learner)))


def _autopilot(target: str) -> Callable[[Calibration, Path, ExportOptions], Exported]:
    def write(calibration: Calibration, path: Path, options: ExportOptions) -> Exported:
        slot = (0 if target == "px4" else 1) if options.instance is None else options.instance
        if target == "px4":  # the parameters computed once, the file written from them
            params = px4_parameters(calibration, instance=slot, device_id=options.device_id,
                                    accel_device_id=options.accel_device_id)
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
        if options.judge_firmware and any(a in calibration.axes and calibration.axes[a].temperature is not None
                                          for a in GYRO_AXES):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # the model continued past its range: that is the point here
                difference = firmware_difference(calibration, params.values, target, slot)
        return Exported(target, (path,), tuple(notes), difference)

    return write


register(Exporter("px4", "PX4 TC_G*/TC_A* parameters (QGroundControl .params)",
                  "lag, hysteresis, g-sensitivity, gyro scale factor; a cubic held at TMIN/TMAX", _autopilot("px4"),
                  suffixes=(".params",)))
register(Exporter("ardupilot", "ArduPilot INS_TCAL* parameters (.parm)",
                  "lag, hysteresis, g-sensitivity, gyro scale factor, the constant; a cubic about 35 degC held at "
                  "TMIN/TMAX", _autopilot("ardupilot"), suffixes=(".parm", ".param")))
register(Exporter("c", "the whole model as C99 (gyrocomp.h, gyrocomp.c) with the online learner beside it",
                  "a temperature from each axis's own sensor (the C interface takes one)", _c, folder=True))
register(Exporter("json", "the model file itself", "nothing", _json, suffixes=(".json",)))

__all__ = ["EXPORTERS", "ExportOptions", "Exported", "Exporter", "export_to", "format_of", "register"]
