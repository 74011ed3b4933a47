"""Every export format there is: importing this module registers each writer (:mod:`gyrocomp.export.exporters`),
in the order of the lines below. A new format is its module plus one line here."""

from __future__ import annotations

from . import params_files  # noqa: F401  px4, ardupilot
from . import c_code  # noqa: F401
from . import model_file  # noqa: F401  json
from .exporters import EXPORTERS, ExportOptions, Exported, Exporter, export_to, format_of, register

__all__ = ["EXPORTERS", "ExportOptions", "Exported", "Exporter", "export_to", "format_of", "register"]
