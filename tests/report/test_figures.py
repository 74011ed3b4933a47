"""Figures: written atomically, clear message without matplotlib."""

import sys

import pytest

from gyrocomp.errors import MissingDependencyError
from gyrocomp.measures.noise import analyse_noise
from gyrocomp.report.figures import allan_figure

from ..conftest import static_recording


def test_allan_figure_is_a_png_with_both_sensor_panels(tmp_path):
    analysis = analyse_noise(static_recording(n=5000), ["gyro_x", "gyro_z", "accel_z"])
    allan_figure(analysis, tmp_path / "allan.png")
    assert (tmp_path / "allan.png").read_bytes()[:4] == b"\x89PNG"
    allan_figure(analysis, tmp_path / "allan.svg")
    assert b"<svg" in (tmp_path / "allan.svg").read_bytes()[:500]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["allan.png", "allan.svg"]  # no temporary left


def test_missing_matplotlib_names_the_extra(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    with pytest.raises(
        MissingDependencyError,
        match=r"^plots need the optional package matplotlib; install it with: "
        r"pip install 'gyrocomp\[plot\]' \(from a clone of the repository: "
        r"pip install -e '\.\[plot\]'\)$",
    ):
        allan_figure(analyse_noise(static_recording(n=2000)), tmp_path / "a.png")
    assert not (tmp_path / "a.png").exists()
