"""Sensor presets: error models of real parts, with where each value comes from.

Datasheet figures are typical values; where a datasheet is silent (turn-on repeatability,
thermal time constant, hysteresis) the value is an assumption, marked as such, chosen to
produce the behaviour the reference thesis (M. Ali, METU, 2014) shows for that part.
Each preset also names the chamber range the thesis (or the part's rating) used, which the
``chamber``, ``cycle`` and ``combined`` profiles take unless set points are given.

:func:`preset_model` gives the nominal part, or with ``unit=N`` one unit of a production
spread (temperature, hysteresis and g-sensitivity coefficients each varied by
``UNIT_SPREAD``), so a batch of simulated parts is not all alike.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from .error_model import AccelErrorModel, GyroErrorModel, Hysteresis

#: relative unit-to-unit spread (1 sigma) of the deterministic coefficients
UNIT_SPREAD = 0.2


@dataclass(frozen=True)
class Preset:
    """A named part: its error model and the chamber range it is tested over [degC]."""

    name: str
    description: str
    model: GyroErrorModel
    set_points_degc: tuple[float, float]


def _adxrs450() -> Preset:
    # Analog Devices ADXRS450 data sheet, Rev. B (2011), Table 1:
    #   rate noise density 0.015 deg/s/sqrt(Hz); in-run bias stability 25 deg/h (typ.);
    #   sensitivity 80 LSB/(deg/s) -> LSB 0.0125 deg/s; temperature output 5 LSB/degC -> 0.2 degC.
    # Thesis 2.1.4 and 3.1.2: no internal temperature compensation, a nearly linear drift of a few
    #   tenths of deg/s to deg/s over -30..80 degC (Fig. 3.9; the OCR loses the exact figure, we take
    #   0.0135 deg/s/degC, 1.5 deg/s over the range); 3.2.1: hysteresis only on cooling, between
    #   55 and 80 degC, adding up to 0.2 deg/s (Table 3.x), back on the heating path below 55 degC.
    #   The polynomial h1 d + h2 d^2 = 0.00128 d (25 - d) peaks at 0.2 deg/s 12.5 degC below an
    #   80 degC turn and returns to zero at 55 degC.
    # Thesis 3.3.3: no dependence on acceleration was found, so no g-sensitivity.
    # Assumed: turn-on repeatability 0.05 deg/s, thermal time constant 60 s, temperature noise 0.1 degC.
    model = GyroErrorModel(
        axes=("gyro_z",),
        temperature_coefficients=((0.0135, 2.0e-5),),
        t_ref_degc=25.0,
        thermal_time_constant_s=60.0,
        hysteresis=Hysteresis(((0.032, -0.00128),), direction="descending", band_degc=(55.0, 80.0)),
        turn_on_bias_sigma_dps=0.05,
        noise_density_dps_per_sqrt_hz=0.015,
        bias_instability_deg_per_h=25.0,
        quantization_dps=1.0 / 80.0,
        temperature_noise_degc=0.1,
        temperature_quantization_degc=0.2,
        accelerometer=None,
    )
    return Preset(
        "adxrs450",
        "Analog Devices ADXRS450: single-axis, strong linear tempco, "
        "hysteresis on cooling between 55 and 80 degC, 25 deg/h class",
        model,
        (-30.0, 80.0),
    )


def _mti10() -> Preset:
    # Xsens MTi 10-series data sheet (MTi 10-series, document MT0503P, 2014), gyroscopes:
    #   in-run bias stability 18 deg/h; noise density 0.03 deg/s/sqrt(Hz); g-sensitivity
    #   (calibrated) 0.006 deg/s/g; full range 450 deg/s, 16-bit raw output -> LSB 450/32768 deg/s.
    #   Accelerometers: noise density 80 ug/sqrt(Hz); full range 50 m/s^2 (5.1 g) 16-bit -> LSB 1.6e-4 g.
    # Thesis 3.1.3 and 3.2.2 (raw, uncalibrated output): drift about 0.05 deg/s over -25..90 degC;
    #   hysteresis on cooling up to 0.005 deg/s at the bottom of a -20..90 cycle (Table 3.x), growing
    #   with |T - T_turn| (quadratic, Fig. 3.34); thesis 3.3.1: g-sensitivity about 0.005 deg/s/g.
    # Assumed: turn-on repeatability 0.02 deg/s, thermal time constant 120 s (housed IMU), scale
    #   factor 500 ppm with 30 ppm/degC, misalignment 0.05 deg (8.7e-4 rad), accel bias 5 mg with
    #   0.1 mg/degC, temperature noise 0.05 degC with a 0.0625 degC LSB.
    model = GyroErrorModel(
        axes=("gyro_x", "gyro_y", "gyro_z"),
        temperature_coefficients=((4e-4, 6e-6, -8e-8), (-3e-4, 4e-6, 5e-8), (5e-4, -5e-6, 6e-8)),
        t_ref_degc=25.0,
        thermal_time_constant_s=120.0,
        hysteresis=Hysteresis(((0.0, 3.8e-7), (0.0, -3.0e-7), (0.0, 3.4e-7)), direction="descending"),
        g_sensitivity_dps_per_g=((0.004, 0.002, -0.003), (-0.002, 0.005, 0.001), (0.001, -0.003, 0.004)),
        scale_factor_error_ppm=(500.0, -400.0, 300.0),
        scale_factor_tempco_ppm_per_degc=(30.0, -20.0, 25.0),
        misalignment_rad=((0.0, 8.7e-4, -5.0e-4), (-6.0e-4, 0.0, 8.7e-4), (4.0e-4, -7.0e-4, 0.0)),
        turn_on_bias_sigma_dps=0.02,
        noise_density_dps_per_sqrt_hz=0.03,
        bias_instability_deg_per_h=18.0,
        quantization_dps=450.0 / 32768.0,
        temperature_noise_degc=0.05,
        temperature_quantization_degc=0.0625,
        accelerometer=AccelErrorModel(
            bias_g=(0.005, -0.003, 0.004),
            bias_tempco_g_per_degc=(1e-4, -1e-4, 1.5e-4),
            noise_density_g_per_sqrt_hz=80e-6,
            quantization_g=1.6e-4,
        ),
    )
    return Preset(
        "mti10",
        "Xsens MTi-10 raw output: 3-axis, ~0.05 deg/s drift over -25..90 degC, g-sensitivity ~0.005 deg/s/g, 18 deg/h",
        model,
        (-25.0, 90.0),
    )


def _adis16488() -> Preset:
    # Analog Devices ADIS16488A data sheet, Rev. F, Table 1, gyroscopes: in-run bias stability
    #   5.1 deg/h; angular random walk 0.26 deg/sqrt(h) = 0.26/60 deg/s/sqrt(Hz); linear acceleration
    #   effect on bias 0.009 deg/s/g; 32-bit output, 0.02 deg/s per 2^16 LSB -> 3.05e-7 deg/s.
    #   Accelerometers: noise density 0.063 mg/sqrt(Hz). Temperature: 0.00565 degC/LSB.
    # Factory temperature compensated: only a small residual tempco (assumed 5e-5 deg/s/degC).
    # Thesis 2.1.3: operation limited to below 50 degC; no hysteresis could be measured.
    # Assumed: turn-on repeatability 0.005 deg/s, thermal time constant 300 s (aluminium housing),
    #   scale factor 100 ppm, cross-axis g-sensitivity a quarter of the on-axis value.
    model = GyroErrorModel(
        axes=("gyro_x", "gyro_y", "gyro_z"),
        temperature_coefficients=((5e-5, 1e-6), (-4e-5, 8e-7), (6e-5, -1e-6)),
        t_ref_degc=25.0,
        thermal_time_constant_s=300.0,
        g_sensitivity_dps_per_g=((0.009, 0.002, -0.002), (0.002, 0.009, 0.002), (-0.002, 0.002, 0.009)),
        scale_factor_error_ppm=(100.0, -80.0, 120.0),
        turn_on_bias_sigma_dps=0.005,
        noise_density_dps_per_sqrt_hz=0.26 / 60.0,
        bias_instability_deg_per_h=5.1,
        quantization_dps=0.02 / 65536.0,
        temperature_noise_degc=0.02,
        temperature_quantization_degc=0.00565,
        accelerometer=AccelErrorModel(bias_g=(0.001, -0.001, 0.0005), noise_density_g_per_sqrt_hz=63e-6),
    )
    return Preset(
        "adis16488",
        "Analog Devices ADIS16488A: 0.26 deg/sqrt(h), 5.1 deg/h, small residual tempco, g-sensitivity ~0.01 deg/s/g",
        model,
        (-20.0, 50.0),
    )


def _consumer() -> Preset:
    # InvenSense MPU-6050 product specification PS-MPU-6000A-00 rev. 3.4, Table 6.1: rate noise
    #   spectral density 0.005 deg/s/sqrt(Hz); zero-rate output variation over -40..85 degC +-20 deg/s
    #   (a limit; we take a typical 0.03 deg/s/degC); linear acceleration sensitivity 0.1 deg/s/g;
    #   131 LSB/(deg/s) -> LSB 1/131 deg/s. Table 6.2: accelerometer noise 400 ug/sqrt(Hz), 16384 LSB/g,
    #   zero-g tempco +-0.35 mg/degC (x, y), +-0.75 mg/degC (z).
    # Whole-degree temperature: many drivers (and BMI-class parts' integer registers) report degC as
    #   integers, which gives stepped curves.
    # Assumed (not specified): bias instability 20 deg/h, rate random walk 5e-5 deg/s/sqrt(s), turn-on
    #   repeatability 0.1 deg/s, thermal time constant 30 s, a small hysteresis on both branches
    #   (0.01 deg/s 90 degC after a turn).
    model = GyroErrorModel(
        axes=("gyro_x", "gyro_y", "gyro_z"),
        temperature_coefficients=((0.03, 1.5e-4), (-0.025, -1.0e-4), (0.035, 2.0e-4)),
        t_ref_degc=25.0,
        thermal_time_constant_s=30.0,
        hysteresis=Hysteresis(((0.0, 1.2e-6), (0.0, -1.0e-6), (0.0, 1.1e-6)), direction="both"),
        g_sensitivity_dps_per_g=((0.1, 0.03, -0.02), (-0.03, 0.1, 0.02), (0.02, -0.03, 0.1)),
        turn_on_bias_sigma_dps=0.1,
        noise_density_dps_per_sqrt_hz=0.005,
        bias_instability_deg_per_h=20.0,
        rate_random_walk_dps_per_sqrt_s=5e-5,
        quantization_dps=1.0 / 131.0,
        temperature_noise_degc=0.1,
        temperature_quantization_degc=1.0,
        accelerometer=AccelErrorModel(
            bias_g=(0.02, -0.015, 0.03),
            bias_tempco_g_per_degc=(3.5e-4, -3.5e-4, 7.5e-4),
            noise_density_g_per_sqrt_hz=400e-6,
            quantization_g=1.0 / 16384.0,
        ),
    )
    return Preset(
        "consumer",
        "MPU-6050/BMI-class consumer part: large tempco, whole-degree temperature, 0.1 deg/s/g",
        model,
        (-20.0, 70.0),
    )


def _drifting() -> Preset:
    # A consumer-class triad (the consumer preset's tempcos) that drifts as the real one-cycle chamber log of
    #   ../shared/datasets/tofupilot-imu-thermal does: after a cubic in temperature fitted on that whole run its axes
    #   keep 0.05-0.23 deg/s of drift (120 s moving average) correlated over 200-500 s, and its white noise is
    #   0.009-0.021 deg/s per sample at 2 Hz. Here, on a one-cycle run at 2.7 degC/min: 0.04-0.10 deg/s, correlated
    #   over 200-600 s, white 0.015 deg/s per sample (noise density 0.01 deg/s/sqrt(Hz)).
    # The drift: a smooth non-repeatable process (0.08 deg/s, 300 s) and a temperature relation of its own in each
    #   run that wanders within it (0.002 deg/s/degC); a warm-up transient of 0.1 deg/s over 300 s after power-on.
    # Heating and cooling follow one curve: no lag, no hysteresis, no temperature-rate term (what a part of this
    #   kind must not be given memory terms for).
    model = GyroErrorModel(
        axes=("gyro_x", "gyro_y", "gyro_z"),
        temperature_coefficients=((0.03, 1.5e-4), (-0.025, -1.0e-4), (0.035, 2.0e-4)),
        t_ref_degc=25.0,
        turn_on_bias_sigma_dps=0.1,
        noise_density_dps_per_sqrt_hz=0.01,
        bias_instability_deg_per_h=20.0,
        run_drift_dps=0.08,
        run_tempco_sigma_dps_per_degc=0.002,
        run_drift_time_s=300.0,
        warm_up_sigma_dps=0.1,
        warm_up_time_s=300.0,
        accelerometer=None,
    )
    return Preset(
        "drifting",
        "consumer-class triad with the non-repeatable drift and warm-up of a real chamber log, "
        "one curve heating and cooling",
        model,
        (-20.0, 70.0),
    )


PRESETS: dict[str, Preset] = {p.name: p for p in (_adxrs450(), _mti10(), _adis16488(), _consumer(), _drifting())}


def get_preset(name: str) -> Preset:
    try:
        return PRESETS[name]
    except KeyError:
        raise InputError(f"preset: unknown preset {name!r}; use one of {', '.join(PRESETS)}") from None


def _vary(rows, rng: np.random.Generator):
    """Each coefficient of a per-axis tuple of tuples times (1 + UNIT_SPREAD z)."""
    if rows is None:
        return None
    return tuple(tuple(float(v * (1.0 + UNIT_SPREAD * rng.standard_normal())) for v in row) for row in rows)


def preset_model(name: str, unit: int | None = None) -> GyroErrorModel:
    """The error model of a preset: nominal, or unit number ``unit`` of a production spread.

    The same (name, unit) always gives the same part; each deterministic coefficient is the
    nominal one times (1 + UNIT_SPREAD z), z standard normal.
    """
    model = get_preset(name).model
    if unit is None:
        return model
    if unit < 0:
        raise InputError(f"unit: must be a whole number >= 0, got {unit}")
    rng = np.random.default_rng([unit, sum(map(ord, name))])
    hyst = model.hysteresis
    if hyst is not None:
        hyst = dataclasses.replace(hyst, coefficients_dps=_vary(hyst.coefficients_dps, rng))
    return dataclasses.replace(
        model,
        temperature_coefficients=_vary(model.temperature_coefficients, rng),
        hysteresis=hyst,
        g_sensitivity_dps_per_g=_vary(model.g_sensitivity_dps_per_g, rng),
    )
