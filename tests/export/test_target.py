"""A model fitted for a firmware (fit --target px4|ardupilot): through the exported file and the emulated firmware
(gyrocomp.export.firmware), the same correction as gyrocomp apply, at every sample of a held-out run that leaves
the calibrated range on both sides."""

import warnings

import numpy as np
import pytest

from gyrocomp import apply
from gyrocomp.errors import InputError
from gyrocomp.export.autopilot import ardupilot_parameters, px4_parameters
from gyrocomp.io.tables import write_recording
from gyrocomp.export.firmware import ardupilot_gyro_correction_dps, px4_gyro_correction_dps
from gyrocomp.models.options import FitOptions, Polynomial
from gyrocomp.models.joint import fit_calibration
from gyrocomp.simulation import get_profile, simulate

from ..conftest import run


@pytest.fixture(scope="module")
def runs_and_held_out():
    fit = [
        simulate(
            "consumer", profile=get_profile("cycle", set_points_degc=(0.0, 50.0), cycles=1), rate_hz=1, seed=s
        ).recording
        for s in range(2)
    ]
    held = simulate(
        "consumer", profile=get_profile("cycle", set_points_degc=(-20.0, 70.0), cycles=1), rate_hz=1, seed=9
    ).recording  # 20 degC past the calibrated range on both sides
    return fit, held


@pytest.mark.parametrize("target", ["px4", "ardupilot"])
def test_apply_computes_what_the_firmware_will(runs_and_held_out, target):
    fit, held = runs_and_held_out
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_calibration(fit, target=target)
        correction = held.gyro_dps - apply(cal, held).gyro_dps
    assert cal.fit_report["target"] == target and cal.model.endswith(f"for {target}")
    for ax in cal.axes.values():
        assert ax.lag_time_constant_s == 0 and ax.hysteresis is None and ax.g_sensitivity_dps_per_g is None
        assert ax.temperature is None or (ax.temperature.order <= 3 and ax.temperature.extrapolation == "hold")
    if target == "px4":
        firmware = px4_gyro_correction_dps(px4_parameters(cal, device_id=5).values, held.temperature_degc)
    else:  # relative to its calibration temperature, where the boot-time offset takes the constant
        firmware = ardupilot_gyro_correction_dps(ardupilot_parameters(cal).values, held.temperature_degc, 25.0)
        firmware = firmware - firmware.mean(axis=0) + correction.mean(axis=0)
    assert np.max(np.abs(firmware - correction)) < 1e-6


def test_a_firmware_target_refuses_what_the_firmware_cannot_carry():
    with pytest.raises(InputError, match=r"FitOptions.target: px4 carries a polynomial of order 3 at most"):
        FitOptions(temperature=Polynomial(5), target="px4")
    with pytest.raises(InputError, match=r"FitOptions.target: ardupilot has no lag or hysteresis term"):
        FitOptions(hysteresis="lag", target="ardupilot")
    with pytest.raises(InputError, match=r"FitOptions.target: 'betaflight'; use one of model, px4, ardupilot"):
        FitOptions(target="betaflight")


def test_the_command_line_fits_for_a_firmware(tmp_path, runs_and_held_out):
    paths = [tmp_path / f"r{k}.csv" for k in range(2)]
    for rec, path in zip(runs_and_held_out[0], paths):
        write_recording(rec, path)
    r = run("fit", *paths, "-o", tmp_path / "m.json", "--target", "px4")
    assert r.returncode == 0, r.stderr
    assert "for px4" in r.stdout
    r = run("fit", *paths, "-o", tmp_path / "m.json", "--target", "px4", "--hysteresis", "lag")
    assert r.returncode == 2 and "--target: px4 has no lag or hysteresis term" in r.stderr


def test_a_run_corrected_as_the_firmware_would_keeps_what_apply_leaves(runs_and_held_out):
    """firmware_corrected (what the report's "On the autopilot" shows): with a --target ardupilot model, ArduPilot
    leaves what apply leaves but a constant (its boot-time offset), so the same bias offset; PX4 as it runs adds
    its 1 degC steps to a --target px4 model, never less than apply leaves."""
    from gyrocomp.export.firmware import firmware_corrected
    from gyrocomp.measures.merit import evaluate_run

    fit, held = runs_and_held_out
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for target in ("ardupilot", "px4"):
            cal = fit_calibration(fit, target=target)
            model = evaluate_run(held, apply(cal, held), window_s=60.0).axes
            vehicle = evaluate_run(held, firmware_corrected(cal, held, target), window_s=60.0).axes
            for axis, m in model.items():
                if target == "ardupilot":
                    assert vehicle[axis].bias_offset_comp_dps == pytest.approx(m.bias_offset_comp_dps, rel=1e-4)
                else:
                    assert vehicle[axis].bias_offset_comp_dps >= 0.99 * m.bias_offset_comp_dps
                    assert vehicle[axis].bias_offset_comp_dps < m.bias_offset_raw_dps / 2
