"""Figures and reports for test reports. Needs matplotlib: ``pip install 'gyrocomp[plot]'``."""
