"""Noise analysis of recordings: axes, accelerometers, time gaps."""

import math
import warnings

import numpy as np
import pytest

from gyrocomp.allan import allan_deviation, allan_deviation_segments
from gyrocomp.errors import DataQualityWarning, InputError
from gyrocomp.measures.noise import analyse_noise
from gyrocomp.recording import Recording

from ..conftest import burst_stamped_recording, static_recording


def test_every_gyro_axis_by_default_and_accelerometers_on_request():
    rec = static_recording()
    analysis = analyse_noise(rec)
    assert list(analysis.axes) == ["gyro_x", "gyro_z"]
    gyro = analysis.axes["gyro_z"]
    assert gyro.sensor == "gyro" and gyro.unit == "deg/s"
    assert gyro.noise.noise_density_dps_per_sqrt_hz == pytest.approx(0.01, rel=0.03)
    accel = analyse_noise(rec, ["accel_z"]).axes["accel_z"]
    assert accel.sensor == "accel" and accel.unit == "g"
    # white accelerometer noise of 1e-3 g per sample at 50 Hz: N = 1e-3 / sqrt(50) [g/sqrt(Hz)]
    assert accel.noise.noise_density_g_per_sqrt_hz == pytest.approx(1e-3 / math.sqrt(50), rel=0.03)
    with pytest.raises(InputError, match=r"axes: 'gyro_y' is not in static.csv; it has gyro_x, gyro_z, accel_x"):
        analyse_noise(rec, ["gyro_y"])
    # with_accel (Kalibr's file): the named axes, then every accelerometer axis not named already
    assert list(analyse_noise(rec, ["accel_y", "gyro_z"], with_accel=True).axes) == [
        "accel_y",
        "gyro_z",
        "accel_x",
        "accel_z",
    ]


def test_other_kinds_keep_noise_terms_from_the_overlapping_curve():
    rec = static_recording()
    analysis = analyse_noise(rec, ["gyro_x"], kind="mdev", taus="decade")
    axis = analysis.axes["gyro_x"]
    assert axis.curve.kind == "mdev" and axis.allan.kind == "oadev"
    np.testing.assert_allclose(axis.allan.deviation, allan_deviation(rec.gyro("gyro_x"), rec.rate_hz).deviation)


def test_gaps_are_refused_unless_split():
    rec = static_recording(gap_after=40_000)
    with pytest.raises(
        InputError,
        match=r"static.csv: time gap of 10.02 s after row 40000 \(t = 799.98 s\); "
        r"Allan deviations need evenly spaced samples: use split_gaps=True",
    ):
        analyse_noise(rec)
    assert [(s.start, s.stop) for s in rec.contiguous_stretches()] == [(0, 40_000), (40_000, 60_000)]
    analysis = analyse_noise(rec, split_gaps=True)
    assert analysis.stretches == 2
    assert "pooled 2 contiguous stretches split at 1 gap(s)" in analysis.how
    pooled = allan_deviation_segments([rec.gyro("gyro_x")[:40_000], rec.gyro("gyro_x")[40_000:]], rec.rate_hz)
    np.testing.assert_allclose(analysis.axes["gyro_x"].curve.deviation, pooled.deviation, rtol=1e-12)
    # no term spans the gap: the count is what the two stretches have on their own
    assert analysis.axes["gyro_x"].curve.n[0] == (40_000 - 1) + (20_000 - 1)
    total = analyse_noise(rec, ["gyro_x"], kind="totdev", split_gaps=True)
    assert "TOTDEV on the longest of 2 contiguous stretches (800 s, rows 1-40000)" in total.how


def test_gaps_of_burst_stamped_samples_are_refused_with_the_samples_mean_rate_not_the_pooling():
    """Stamps taken as buffered samples arrived (100 Hz, five at a time, 2 ms apart): the gaps are between bursts,
    and pooling the stretches between them (five samples each) would leave no Allan deviation to speak of; the
    refusal gives the samples' mean rate and the way to read them at it instead."""
    rec = burst_stamped_recording(100.0, 10_000, 5, 2e-3)
    with pytest.raises(
        InputError,
        match=r"^b.csv: time gap of 0.042 s after row 5 \(t = 0.048 s\) \(and 1998 more\); Allan deviations need "
        r"evenly spaced samples: the stamps come in bursts, so the stretches between them hold 5 samples on average; "
        r"if the sensor samples evenly, read the samples at their mean rate, the stamps left unread "
        r"\(columns=\{'time': ''\} and rate_hz=100\)$",
    ):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DataQualityWarning)  # the time-bursts check says it first
            analyse_noise(rec)


def test_json_document_has_the_documented_shape_and_no_nan():
    rec = static_recording(n=2000)
    doc = analyse_noise(rec, ["gyro_z", "accel_x"]).to_dict()
    assert set(doc) == {"rate_hz", "axes"}
    z = doc["axes"]["gyro_z"]
    assert set(z) == {"tau_s", "adev", "n", "ci_low", "ci_high", "noise"}
    assert set(z["noise"]) == {
        "noise_density_dps_per_sqrt_hz",
        "arw_deg_per_sqrt_h",
        "bias_instability_deg_per_h",
        "integration_time_s",
        "rrw_deg_per_h_per_sqrt_h",
        "quantization_deg",
        "rate_ramp_deg_per_h2",
    }
    assert "noise_density_g_per_sqrt_hz" in doc["axes"]["accel_x"]["noise"]
    flat = [v for axis in doc["axes"].values() for key in ("adev", "ci_low", "ci_high") for v in axis[key]]
    assert all(v is None or math.isfinite(v) for v in flat)


def test_a_noise_model_that_misses_the_curve_is_warned_about_in_the_library():
    """A periodic disturbance (50 s sine) bends the Allan curve where no power-law term can follow: the library
    warns, naming the parameter that restricts the fit; white noise alone fits and stays silent."""
    rng = np.random.default_rng(0)
    t = np.arange(200_000) / 100.0
    white = Recording(t, rng.normal(0, 0.01, t.size)[:, None], ("gyro_z",))
    with warnings.catch_warnings():
        warnings.simplefilter("error", DataQualityWarning)
        analyse_noise(white)
    periodic = Recording(t, (rng.normal(0, 0.01, t.size) + 0.5 * np.sin(2 * np.pi * t / 50.0))[:, None], ("gyro_z",))
    with pytest.warns(
        DataQualityWarning,
        match=r"gyro_z: the five-term noise model misses the curve by \d+% RMS.*"
        r"fit_taus_s: \(low, high\) \[s\]",
    ):
        analyse_noise(periodic)
