"""The autopilots' corrections as their source computes them (gyrocomp.export.firmware), against values computed
by hand from the formulas in PX4's calc_thermal_offsets_3D and ArduPilot's TCal::correct_sensor, and the
firmware-versus-model difference the export prints."""

import math

import numpy as np
import pytest

from gyrocomp.errors import InputError
from gyrocomp.export.firmware import ardupilot_gyro_correction_dps, px4_as_run, px4_gyro_correction_dps
from gyrocomp.simulation import get_profile, simulate


DEG = 180.0 / math.pi
PX4 = {
    "TC_G0_TMIN": 10.0,
    "TC_G0_TMAX": 50.0,
    "TC_G0_TREF": 30.0,
    **{
        f"TC_G0_X{k}_{j}": c
        for j, coefs in enumerate(((1e-3, 2e-5, -3e-7, 4e-9), (0.0, 1e-4, 0.0, 0.0), (-2e-3, 0.0, 5e-7, 0.0)))
        for k, c in enumerate(coefs)
    },
}
ARDU = {
    "INS_TCAL1_TMIN": 0.0,
    "INS_TCAL1_TMAX": 60.0,
    **{
        f"INS_TCAL1_GYR{k}_{a}": c
        for a, coefs in zip("XYZ", ((100.0, -2.0, 0.03), (50.0, 0.0, 0.0), (0.0, 1.0, 0.0)))
        for k, c in zip((1, 2, 3), coefs)
    },
}


def test_px4_offsets_by_hand_inside_and_clamped_outside():
    out = px4_gyro_correction_dps(PX4, np.array([20.0, 40.0, 0.0, 70.0]))
    # x at 20 degC: d = -10: 1e-3 - 2e-4 - 3e-5 - 4e-6 rad/s
    assert out[0, 0] == pytest.approx((1e-3 - 2e-4 - 3e-7 * 100 - 4e-9 * 1000) * DEG, rel=1e-6)
    assert out[1, 1] == pytest.approx(1e-4 * 10 * DEG, rel=1e-6)
    assert out[1, 2] == pytest.approx((-2e-3 + 5e-7 * 100) * DEG, rel=1e-6)
    # below TMIN and above TMAX the temperature is clamped: the offsets at 10 and 50 degC
    np.testing.assert_allclose(out[2], px4_gyro_correction_dps(PX4, np.array([10.0]))[0], rtol=0, atol=0)
    np.testing.assert_allclose(out[3], px4_gyro_correction_dps(PX4, np.array([50.0]))[0], rtol=0, atol=0)


def test_px4_as_it_runs_publishes_at_1_hz_when_the_temperature_moved_by_more_than_1_degc():
    time_s = np.arange(0.0, 10.0, 0.25)  # 4 Hz samples, polls at 0, 1, 2, ... s
    temperature = 20.0 + 0.6 * time_s  # 0.6 degC per second
    out = px4_as_run(PX4, time_s, temperature)
    # published at 0 s (20 degC, first), 2 s (21.2: more than 1 degC from 20), 4 s (22.4), 6 s, 8 s
    published = {0.0: 20.0, 2.0: 21.2, 4.0: 22.4, 6.0: 23.6, 8.0: 24.8}
    for k, t in enumerate(time_s):
        last = max(p for p in published if p <= t)
        np.testing.assert_allclose(out[k], px4_gyro_correction_dps(PX4, np.array([published[last]]))[0])


def test_ardupilot_correction_by_hand_relative_to_the_calibration_temperature():
    out = ardupilot_gyro_correction_dps(ARDU, np.array([45.0, 80.0]), cal_temp_degc=25.0)

    def p(d, c):
        return (c[0] + (c[1] + c[2] * d) * d) * d * 1e-6

    x = (100.0, -2.0, 0.03)
    assert out[0, 0] == pytest.approx((p(10.0, x) - p(-10.0, x)) * DEG, rel=1e-5)
    assert out[0, 2] == pytest.approx((p(10.0, (0, 1, 0)) - p(-10.0, (0, 1, 0))) * DEG, rel=1e-5)
    assert out[1, 0] == pytest.approx((p(25.0, x) - p(-10.0, x)) * DEG, rel=1e-5)  # 80 clamped to TMAX 60
    # the calibration temperature is clamped too
    np.testing.assert_allclose(
        ardupilot_gyro_correction_dps(ARDU, np.array([30.0]), -20.0),
        ardupilot_gyro_correction_dps(ARDU, np.array([30.0]), 0.0),
    )


def test_a_parameter_left_out_has_the_firmwares_default():
    """PX4 without TMIN/TMAX/TREF clamps at 0 and 100 degC about 25 degC; ArduPilot at 0 and 70 degC; a slot the
    parameters hold nothing of is refused by name."""
    from gyrocomp.calibration.installed import installed_calibration

    bare = {k: v for k, v in PX4.items() if not k.endswith(("TMIN", "TMAX", "TREF"))}
    full = {**bare, "TC_G0_TMIN": 0.0, "TC_G0_TMAX": 100.0, "TC_G0_TREF": 25.0}
    temps = np.array([-10.0, 0.0, 40.0, 100.0, 130.0])
    np.testing.assert_array_equal(px4_gyro_correction_dps(bare, temps), px4_gyro_correction_dps(full, temps))
    np.testing.assert_array_equal(px4_gyro_correction_dps(bare, temps[:1]), px4_gyro_correction_dps(bare, temps[1:2]))
    curve = installed_calibration({**bare, "TC_G_ENABLE": 1}, "px4").axes["gyro_x"].temperature
    assert (curve.t_min_degc, curve.t_max_degc, curve.t_ref_degc, curve.extrapolation) == (0.0, 100.0, 25.0, "hold")
    ardu = {k: v for k, v in ARDU.items() if not k.endswith(("TMIN", "TMAX"))}
    out = ardupilot_gyro_correction_dps(ardu, np.array([70.0, 90.0, -5.0]), 0.0)
    np.testing.assert_array_equal(out[0], out[1])
    assert np.all(out[2] == 0.0)  # clamped to TMIN 0, the calibration temperature
    curve = installed_calibration({**ardu, "INS_TCAL1_ENABLE": 1}, "ardupilot").axes["gyro_x"].temperature
    assert (curve.t_min_degc, curve.t_max_degc) == (0.0, 70.0)
    with pytest.raises(InputError, match=r"parameters: no TC_G1_\*; the file does not hold that sensor's"):
        px4_gyro_correction_dps(PX4, np.array([20.0]), instance=1)


def test_ardupilot_as_installed_takes_its_calibration_temperature_from_the_parameters():
    from gyrocomp.calibration.installed import ardupilot_cal_temp_degc, installed_correction_dps

    params = {**ARDU, "INS_GYR_CALTEMP": 22.0, "INS_GYR2_CALTEMP": 31.0}
    assert ardupilot_cal_temp_degc(params, 1) == 22.0 and ardupilot_cal_temp_degc(params, 2) == 31.0
    assert ardupilot_cal_temp_degc(ARDU, 1) == -300.0  # never calibrated: the firmware clamps it to TMIN
    temps = np.array([10.0, 40.0])
    np.testing.assert_array_equal(
        installed_correction_dps(params, "ardupilot", np.arange(2.0), temps, 1),
        ardupilot_gyro_correction_dps(ARDU, temps, 22.0),
    )
    np.testing.assert_array_equal(
        installed_correction_dps(ARDU, "ardupilot", np.arange(2.0), temps, 1),
        ardupilot_gyro_correction_dps(ARDU, temps, 0.0),
    )
    with pytest.raises(InputError, match=r"autopilot: 'betaflight'; use px4 or ardupilot"):
        installed_correction_dps(ARDU, "betaflight", np.arange(2.0), temps, 1)


def test_the_firmwares_cost_is_measured_for_a_model_with_g_sensitivity():
    """Neither firmware has a g-term: the temperature correction is what is compared (a model with G used to fail
    there, after the file was written; the three-axis report test covers accelerometer axes)."""
    import dataclasses

    from gyrocomp.export.firmware import firmware_costs
    from gyrocomp.models.joint import fit_calibration

    sims = [
        simulate(
            "adxrs450", profile=get_profile("cycle", set_points_degc=(-30.0, 80.0), cycles=1), rate_hz=0.2, seed=s
        ).recording
        for s in range(2)
    ]
    plain = fit_calibration(sims, hysteresis="none")
    axis = plain.axes["gyro_z"]
    with_g = dataclasses.replace(
        plain, axes={"gyro_z": dataclasses.replace(axis, g_sensitivity_dps_per_g=(0.1, 0.2, 0.3))}
    )
    costs, costs_plain = firmware_costs(with_g), firmware_costs(plain)
    assert set(costs) == {"px4", "ardupilot"}
    for target in costs:  # the g-term is not the temperature correction's: the same figures
        assert costs[target].in_range_max_dps == pytest.approx(costs_plain[target].in_range_max_dps, abs=1e-12)
        assert costs[target].beyond_max_dps[0] > 0
