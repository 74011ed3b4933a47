"""The HTML report and the single figures: structure, decodable images, no network, the real entry point."""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gyrocomp import fit_calibration
from gyrocomp.models.fit import fit_channels
from gyrocomp.report.figures import envelope
from gyrocomp.report.html import SECTIONS, build_report
from gyrocomp.rounding import with_error
from gyrocomp.simulation import get_profile, simulate
from gyrocomp.models.options import FitOptions

from ..conftest import check_report_page

pytest.importorskip("matplotlib.image", reason="the report tests draw with matplotlib")


def _quiet(func, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return func(*args, **kwargs)


def test_single_axis_report_with_hysteresis_has_every_section():
    prof = get_profile("cycle", set_points_degc=(-30.0, 80.0), cycles=1)
    runs = [simulate("adxrs450", profile=prof, rate_hz=0.5, seed=s).recording for s in range(3)]
    cal = _quiet(fit_calibration, runs[:2], hysteresis="turning-point")
    report = build_report(cal, [runs[2]])
    assert report.sections == ("summary", "evaluation", "axis-gyro_z", "firmware", "allan")
    page = check_report_page(report.html, list(report.sections))
    assert len(page.images) == 3  # bias against temperature, time series, Allan
    # the hysteresis is what the firmware cannot carry: its cost through a heat-cool cycle is shown
    assert "correction against the model" in report.html and "heat-cool cycle as run" in report.html
    assert "PX4 file (as run)" in report.html
    assert "stages of the compensation" in report.html  # the thesis's Table 4.4 shape with hysteresis
    assert "<th>window [s]</th>" in report.html  # each figure with the window it depends on
    assert "temperature + hysteresis" in report.html and "polynomial order" in report.html
    # the compensated gyro's noise model for an estimator, beside its IEEE 952 fit
    assert "noise model of the compensated gyro for an estimator" in report.html and "<th>bound K</th>" in report.html


@pytest.mark.slow
def test_three_axis_report_with_acceleration_and_accelerometer():
    runs = [simulate("consumer", profile="combined", duration_s=5400, rate_hz=1, seed=s).recording for s in range(3)]
    cal = _quiet(fit_channels, runs[:2], ("gyro", "accel"), options=FitOptions(hysteresis="none"))
    progress = []
    report = build_report(cal, [runs[2]], progress=progress.append)
    axes = [f"axis-{a}" for a in ("gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z")]
    # the combined profile visits the six faces: the accelerometer triad gets its section too
    assert cal.accel_triad is not None
    assert report.sections == ("summary", "evaluation", *axes, "firmware", "allan", "g-sensitivity", "scale-factor")
    check_report_page(report.html, list(report.sections))
    assert "g-sensitivity matrix G [deg/s/g] +- standard error" in report.html
    assert "temperature + acceleration" in report.html and "accelerometer" in report.html
    # chosen by held-out drift: the drift to expect on unseen data, per axis, with its standard error
    expected = cal.report.expected_drift()
    assert "drift to expect on unseen data: mean +- standard error over 4 held-out legs" in report.html
    assert f"{with_error(expected['gyro_x'].drift, expected['gyro_x'].standard_error)} deg/s" in report.html
    assert "thin evidence" not in report.html  # two runs that heat and cool: four legs
    assert progress == sorted(progress) and progress[-1] == 1.0
    assert set(SECTIONS) <= set(report.sections)


@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(-1e6, 1e6, allow_nan=False), min_size=1, max_size=3000), st.integers(1, 400))
def test_envelope_keeps_every_extreme_and_bounds_the_points(values, columns):
    v = np.asarray(values)
    t, e = envelope(np.arange(v.size, dtype=float), v, columns)
    assert e.size <= max(v.size, 2 * columns)
    assert e.min() == v.min() and e.max() == v.max()
    assert np.all(np.diff(t) >= 0)


def test_text_from_files_is_escaped_once():
    prof = get_profile("cycle", set_points_degc=(-30.0, 80.0), cycles=1)
    runs = [simulate("adxrs450", profile=prof, rate_hz=0.5, seed=s).recording for s in range(3)]
    cal = _quiet(fit_calibration, runs[:2], hysteresis="none")
    hostile = dataclasses.replace(runs[2], source="run&1<script>alert(1)<b>.csv")
    page = build_report(dataclasses.replace(cal, model="m<b>&amp;"), [hostile]).html
    assert "run&amp;1&lt;script&gt;alert(1)&lt;b&gt;.csv" in page and "<script>" not in page
    assert "&amp;amp;" not in page.replace("m&lt;b&gt;&amp;amp;", "")  # nothing escaped twice but the name's own
    assert "m&lt;b&gt;&amp;amp;" in page
