"""The model file itself as an export format (``json``: what ``gyrocomp fleet export`` writes of a stored unit)."""

from __future__ import annotations

from pathlib import Path

from ..calibration import Calibration
from .exporters import ExportOptions, Exported, Exporter, register


def _json(calibration: Calibration, path: Path, options: ExportOptions) -> Exported:
    calibration.save(path)
    return Exported("json", (path,))


register(Exporter("json", "the model file itself", "nothing", _json, suffixes=(".json",)))

__all__: list[str] = []
