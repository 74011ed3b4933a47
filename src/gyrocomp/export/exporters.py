"""The export formats' registry: the record types a writer takes and returns, and :func:`register`.

A format is an :class:`Exporter`: its name, what it is, what it cannot carry, the file names that mean it, and its
writer ``(calibration, path, ExportOptions) -> Exported``. A writer lives in a module of its own that calls
:func:`register` once; :mod:`gyrocomp.export.formats` names every such module, so importing
:mod:`gyrocomp.export` registers them all. :func:`export_to` is the one entry point; the command line's
``--format`` choices and help are read from :data:`EXPORTERS`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from ..calibration import Calibration
from ..errors import InputError
from ..fitting.online import LearnerSettings
from .firmware import FirmwareDifference


@dataclass(frozen=True)
class ExportOptions:
    """What some formats need.

    Parameters
    ----------
    rate_hz : float, optional
        C: the sample rate the code runs at [Hz] (a model with thermal lag needs it).
    instance : int, optional
        PX4 gyro slot 0..3, ArduPilot IMU 1..3.
    device_id, accel_device_id : int, optional
        PX4: the gyro's and the accelerometer's device ids.
    learner : LearnerSettings, optional
        C: the online learner's settings.
    judge_firmware : bool
        PX4/ArduPilot: measure the firmware's correction against the model's.
    """

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
    """A registered format.

    Parameters
    ----------
    name : str
        What ``--format`` and :func:`export_to` call it.
    description : str
        What it is, one line (the ``--format`` help shows it).
    cannot_carry : str
        What of a model the format cannot hold.
    write : callable
        ``write(calibration, path, options) -> Exported``: writes the format atomically and says what it wrote.
    suffixes : tuple of str
        The file names that mean it when no format is named (none for a format written into a folder).
    folder : bool
        Written into a folder (``-o`` names a folder without a suffix).
    """

    name: str
    description: str
    cannot_carry: str
    write: Callable[[Calibration, Path, ExportOptions], Exported]
    suffixes: tuple[str, ...] = ()
    folder: bool = False

    def help(self) -> str:
        """``name (description; .suffix)``, as the command line lists it."""
        where = ", ".join(self.suffixes) if self.suffixes else "a folder" if self.folder else ""
        return f"{self.name} ({self.description}" + (f"; {where})" if where else ")")


#: every export format, by name, in the order registered
EXPORTERS: dict[str, Exporter] = {}


def register(exporter: Exporter) -> Exporter:
    """Add ``exporter`` to :data:`EXPORTERS` (a name registered twice is refused).

    Parameters
    ----------
    exporter : Exporter
        The format: its name, description, what it cannot carry, its writer and suffixes.

    Returns
    -------
    Exporter
        ``exporter``, registered.
    """
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
    raise InputError(
        f"fmt: not given, and {Path(path).name!r} names none; give it ({', '.join(offered)}), or "
        f"name the file {named}" + (f", or a folder without a suffix ({folders[0]})" if folders else "")
    )


def export_to(calibration: Calibration, fmt: str, path, options: ExportOptions = ExportOptions()) -> Exported:
    """Write ``calibration`` as ``fmt`` (a name in :data:`EXPORTERS`: ``px4``, ``ardupilot``, ``c``, ``json``, ...)
    to ``path`` (C: a folder), atomically; refuses an unknown format naming the known ones.

    Parameters
    ----------
    calibration : Calibration
        The model to write.
    fmt : str
        A name of :data:`EXPORTERS`.
    path : path
        The file (or folder) to write.
    options : ExportOptions
        What some formats need (a rate [Hz], a sensor slot, device ids).

    Returns
    -------
    Exported
        The files written, the notes for the user, and for an autopilot how far its correction is from the model's.
    """
    if fmt not in EXPORTERS:
        raise InputError(f"format: {fmt!r}; use one of {', '.join(EXPORTERS)}")
    return EXPORTERS[fmt].write(calibration, Path(path), options)


__all__ = ["EXPORTERS", "ExportOptions", "Exported", "Exporter", "export_to", "format_of", "register"]
