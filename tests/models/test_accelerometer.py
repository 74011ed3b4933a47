"""Accelerometer temperature compensation (``--channels accel``): simulate, fit, recover the truth."""

from __future__ import annotations

import dataclasses
import json
import warnings

import numpy as np
import pytest

from gyrocomp import apply
from gyrocomp.calibration import Calibration
from gyrocomp.calibration.compensate import Compensator
from gyrocomp.errors import InputError
from gyrocomp.calibration.fit_report import FitReport
from gyrocomp.measures.merit import evaluate_run, moving_average
from gyrocomp.cli.common import parse_channels
from gyrocomp.models.accelerometer import fit_accelerometer
from gyrocomp.models.fit import fit_channels
from gyrocomp.simulation import get_profile, simulate
from gyrocomp.models.options import FitOptions, Network, Polynomial

from ..conftest import run


def _quiet(func, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return func(*args, **kwargs)


@pytest.fixture(scope="module")
def cycles():
    """Consumer-grade part (tempco up to 7.5e-4 g/degC, 30 s thermal lag) through cold-hot-cold cycles."""
    prof = get_profile("cycle", cycles=1)
    return [simulate("consumer", profile=prof, rate_hz=0.5, seed=s) for s in range(4)]


def test_recovers_the_tempco_and_removes_the_drift_on_a_held_out_run(cycles):
    cal = _quiet(fit_channels, [s.recording for s in cycles[:3]], ("accel",))
    assert not cal.axes and set(cal.accel_axes) == {"accel_x", "accel_y", "accel_z"}
    held = cycles[3]
    out = _quiet(apply, cal, held.recording)
    truth = held.truth
    tempco = np.asarray(truth.model.accelerometer.bias_tempco_g_per_degc)
    # what perfect compensation leaves: the specific force, the constant bias, the tempco at the reference
    structure = truth.structure_temperature_degc
    perfect = held.recording.accel_g - np.outer(structure - cal.accel_reference_degc, tempco)
    w = int(60 * held.recording.rate_hz)  # 60-s moving average: noise 400 ug/sqrt(Hz) -> ~50 ug, LSB 61 ug
    for j in range(3):
        raw_drift = np.ptp(moving_average(held.recording.accel_g[:, j] - perfect[:, j], w))
        left = np.max(np.abs(moving_average(out.accel_g[:, j] - perfect[:, j], w)))
        assert raw_drift > 0.03  # 0.035 .. 0.075 g over -20..70 degC
        assert left < 0.03 * raw_drift, (j, left, raw_drift)
    # the gyro is not touched by an accelerometer-only model
    np.testing.assert_array_equal(out.gyro_dps, held.recording.gyro_dps)


@pytest.mark.slow
def test_gyro_and_accel_together_fit_g_on_compensated_accelerations():
    runs = [simulate("consumer", profile="combined", duration_s=9000, rate_hz=1, seed=s) for s in range(3)]
    both = _quiet(fit_channels, [s.recording for s in runs[:2]], ("accel", "gyro"))  # any order
    assert both.accel_axes and both.has_acceleration
    assert "accel" in both.fit_report and "acceleration" in both.fit_report
    # G matches the truth within a few standard errors
    truth_g = np.asarray(runs[0].truth.model.g_sensitivity_dps_per_g)
    acc = both.fit_report["acceleration"]["axes"]
    for i, axis in enumerate(("gyro_x", "gyro_y", "gyro_z")):
        g = np.asarray(acc[axis]["g_sensitivity_dps_per_g"])
        se = np.asarray(acc[axis]["standard_error_dps_per_g"])
        assert np.all(np.abs(g - truth_g[i]) < 4 * se + 2e-3), (axis, g, truth_g[i], se)
    held = runs[2].recording
    out = _quiet(apply, both, held)
    assert np.max(np.abs(out.accel_g - held.accel_g)) > 1e-3
    evaluation = _quiet(evaluate_run, held, out, accel=True)
    assert set(evaluation.accel_axes) == {"accel_x", "accel_y", "accel_z"}
    assert "accel_axes" in evaluation.to_dict()


def test_round_trip_names_accelerometer_values_in_g(cycles, tmp_path):
    cal = _quiet(
        fit_channels,
        [s.recording for s in cycles[:2]],
        ("gyro", "accel"),
        options=FitOptions(temperature=Polynomial(2), hysteresis="none"),
    )
    path = tmp_path / "model.json"
    cal.save(path)
    text = path.read_text()
    assert '"turn_on_biases_g"' in text and '"coefficients_g"' in text
    loaded = Calibration.load(path)
    assert loaded.accel_axes == cal.accel_axes and loaded.accel_reference_degc == cal.accel_reference_degc
    a = _quiet(apply, cal, cycles[3].recording)
    b = _quiet(apply, loaded, cycles[3].recording)
    np.testing.assert_array_equal(a.accel_g, b.accel_g)
    np.testing.assert_array_equal(a.gyro_dps, b.gyro_dps)


def _keys(d) -> list[str]:
    """Every key of a nested JSON object."""
    if isinstance(d, dict):
        return [k for key, value in d.items() for k in (key, *_keys(value))]
    return [k for value in d for k in _keys(value)] if isinstance(d, list) else []


def _renamed(d, old: str, new: str):
    """``d`` with every key ending in ``old`` ending in ``new`` instead."""
    if isinstance(d, dict):
        return {(k[: -len(old)] + new if k.endswith(old) else k): _renamed(v, old, new) for k, v in d.items()}
    return [_renamed(v, old, new) for v in d] if isinstance(d, list) else d


@pytest.mark.parametrize("temperature", [Polynomial(), Network((2,))], ids=["selected", "network"])
def test_the_accelerometer_fit_report_names_its_figures_in_g(cycles, temperature):
    """The accelerometer's held-out drifts, thermal-memory scores, fit and network residuals are in g: the model
    file says so (``_g``, never ``_dps``), the typed report carries the unit and refuses the deg/s names, and a file
    written before (the same values under ``_dps``) reads into the same records."""
    cal = _quiet(
        fit_channels, [s.recording for s in cycles[:3]], ("accel",), options=FitOptions(temperature=temperature)
    )
    section = cal.fit_report["accel"]
    keys = _keys(section)
    assert not [k for k in keys if k.endswith("_dps")]
    expected = (
        {"fit_rms_g", "validation_rmse_g"}
        if isinstance(temperature, Network)
        else {"raw_drift_g", "chosen_drift_g", "mean_drift_g", "fold_drift_g"}
    )
    assert expected <= set(keys)
    report = cal.report.accel
    if isinstance(temperature, Network):
        assert report.network.unit == "g" and set(report.network.validation_rmse) == set(cal.accel_axes)
        assert all(fit.unit == "g" and fit.fit_rms > 0 for fit in report.axes.values())
    for axis, sel in report.selection.items():
        assert sel.unit == "g" and sel.raw_drift == section["selection"][axis]["raw_drift_g"]
        with pytest.raises(InputError, match=r"raw_drift_dps: the axis's values are in g, not deg/s; read raw_drift"):
            _ = sel.raw_drift_dps
    older = FitReport.from_dict({"accel": _renamed(section, "_g", "_dps")})
    assert older.accel == report


def test_streaming_equals_batch_with_lag(cycles):
    cal = _quiet(fit_channels, [s.recording for s in cycles[:2]], ("accel",), options=FitOptions(hysteresis="lag"))
    assert any(ax.lag_time_constant_s > 0 for ax in cal.accel_axes.values())
    rec = cycles[3].recording
    batch = _quiet(apply, cal, rec).accel_g
    comp = Compensator(cal, rec.gyro_axes, rate_hz=rec.rate_hz)
    edges = [0, 7, 500, 501, 3000, rec.n_samples]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for a, b in zip(edges[:-1], edges[1:]):
            comp.update(rec.time_s[a:b], rec.gyro_dps[a:b], rec.temperature_degc[a:b], rec.accel_g[a:b])
    np.testing.assert_allclose(comp.take_accel(), batch, rtol=0, atol=1e-12)


def test_bad_channels_and_missing_accelerometer(cycles):
    with pytest.raises(InputError, match=r"--channels: mag: use gyro, accel or gyro,accel"):
        parse_channels("gyro,mag")
    assert parse_channels(" ACCEL, gyro") == ("gyro", "accel")
    with pytest.raises(InputError, match=r"channels: 'mag': use 'gyro', 'accel' or both"):
        fit_channels([cycles[0].recording], ("gyro", "mag"))
    with pytest.raises(
        InputError,
        match=r"channels: a tuple of 'gyro' and/or 'accel', e.g. \('gyro', 'accel'\); "
        r"got 'gyro,accel'",
    ):
        fit_channels([cycles[0].recording], "gyro,accel")
    bare = dataclasses.replace(cycles[0].recording, accel_g=None, accel_axes=())
    with pytest.raises(InputError, match=r"channels=accel needs accel_x, accel_y and accel_z columns"):
        fit_accelerometer([bare])
    cal = _quiet(
        fit_channels,
        [s.recording for s in cycles[:2]],
        ("accel",),
        options=FitOptions(temperature=Polynomial(1), hysteresis="none"),
    )
    with pytest.raises(InputError, match=r"the model compensates the accelerometer; the data needs accel_x"):
        apply(cal, bare)
    with pytest.raises(
        InputError,
        match=r"channels=accel: the accelerometer model is a temperature model; "
        r"temperature=None leaves nothing to fit",
    ):
        fit_accelerometer([cycles[0].recording], FitOptions(temperature=None))


def test_the_gyro_only_options_do_not_change_the_accelerometer_model(cycles):
    """``FitOptions.acceleration`` and ``folds`` are the gyro's: ``fit_channels(..., ("gyro", "accel"))`` passes the
    same options to both, and the accelerometer's model does not read them."""
    runs = [s.recording for s in cycles[:2]]
    plain = _quiet(fit_accelerometer, runs, FitOptions(temperature=Polynomial(2), hysteresis="none"))
    gyro_only = _quiet(
        fit_accelerometer,
        runs,
        FitOptions(temperature=Polynomial(2), hysteresis="none", acceleration="matrix", folds="blocks"),
    )
    assert gyro_only.accel_axes == plain.accel_axes


@pytest.mark.slow
def test_cli_accelerometer_channel_end_to_end(tmp_path):
    for seed in (1, 2, 3):
        r = run(
            "simulate",
            "--preset",
            "consumer",
            "--profile",
            "cycle",
            "--rate",
            0.5,
            "--seed",
            seed,
            "-o",
            tmp_path / f"run{seed}.csv",
        )
        assert r.returncode == 0, r.stderr
    r = run(
        "fit",
        tmp_path / "run1.csv",
        tmp_path / "run2.csv",
        "--channels",
        "accel",
        "--hysteresis",
        "none",
        "-o",
        tmp_path / "acc.json",
    )
    assert r.returncode == 0, r.stderr
    assert "accelerometer (correction relative to" in r.stdout and "constants [g]" in r.stdout
    r = run("evaluate", tmp_path / "acc.json", tmp_path / "run3.csv", "--json")
    assert r.returncode == 0, r.stderr
    import json

    accel = json.loads(r.stdout)["runs"][0]["accel_axes"]
    assert all(m["offset_improvement"] > 10 for m in accel.values())
    r = run("evaluate", "--stages", tmp_path / "acc.json", tmp_path / "run3.csv")
    assert r.returncode == 2 and "--stages: " in r.stderr and "has no gyro axes" in r.stderr
    r = run("apply", tmp_path / "acc.json", tmp_path / "run3.csv", "-o", tmp_path / "out.csv")
    assert r.returncode == 0 and "accel_x, accel_y, accel_z compensated" in r.stdout, r.stderr
    r = run("fit", tmp_path / "run1.csv", "--channels", "gyro,mag", "-o", tmp_path / "x.json")
    assert r.returncode == 2 and "--channels: mag: use gyro, accel or gyro,accel" in r.stderr


@pytest.mark.slow
def test_an_accelerometer_axis_left_without_a_curve_is_left_uncorrected():
    """The MTi-10's accelerometer tempco is small: on two multi-position chamber runs no curve beats accel_x's
    constants, so the fit leaves it none while fitting y and z. Applying such a model used to fail inside the
    compensator (it read the missing curve at the reference temperature); that axis is now passed through."""
    runs = [simulate("mti10", profile="combined", duration_s=6 * 3600, rate_hz=2, seed=s).recording for s in range(2)]
    cal = _quiet(fit_accelerometer, runs)
    without = [a for a, ax in cal.accel_axes.items() if ax.temperature is None]
    assert without and len(without) < 3, {a: ax.temperature for a, ax in cal.accel_axes.items()}
    out = _quiet(apply, cal, runs[0])
    for j, axis in enumerate(("accel_x", "accel_y", "accel_z")):
        same = np.array_equal(out.accel_g[:, j], runs[0].accel_g[:, j])
        assert same == (axis in without), axis
    again = Calibration.from_dict(json.loads(cal.to_json()))  # the file keeps it, and applies the same
    np.testing.assert_array_equal(_quiet(apply, again, runs[0]).accel_g, out.accel_g)
