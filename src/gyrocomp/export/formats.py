"""Every export format there is: importing this module registers each writer (:mod:`gyrocomp.export.exporters`),
in this order. A new format's module is named here, once."""

from __future__ import annotations

from . import params_files, c_code, model_file
from .exporters import EXPORTERS, ExportOptions, Exported, Exporter, export_to, format_of, register

#: the modules that register an export format
EXPORT_MODULES = (params_files, c_code, model_file)

__all__ = ["EXPORTERS", "EXPORT_MODULES", "ExportOptions", "Exported", "Exporter", "export_to", "format_of",
           "register"]
