"""The model as C: compiled with the system compiler, fed simulated runs sample by sample, and compared
with gyrocomp apply to 1e-9."""

import dataclasses
import shutil
import subprocess
import warnings

import numpy as np
import pytest

from gyrocomp import Polynomial, apply, fit_calibration
from gyrocomp.errors import InputError
from gyrocomp.export.c_code import c_sources, write_c_sources
from gyrocomp.curves.lookup import LookupTableCurve
from gyrocomp.models.pipelines import fit_pipeline
from gyrocomp.simulation import GyroErrorModel, Hysteresis, get_profile, simulate
from gyrocomp.calibration.triad import TriadCalibration
from gyrocomp.models.options import FitOptions
from ..conftest import chamber_run

DRIVER = r"""
#include <stdio.h>
#include "gyrocomp.h"
int main(void) {
    gyrocomp_state s;
    gyrocomp_init(&s);
    double t, g[3], a[3], temp, out[3];
    while (scanf("%lf %lf %lf %lf %lf %lf %lf %lf", &t, &g[0], &g[1], &g[2], &a[0], &a[1], &a[2], &temp) == 8) {
        gyrocomp_step(&s, t, g, a, temp, out);
        printf("%.17g %.17g %.17g\n", out[0], out[1], out[2]);
    }
    return 0;
}
"""
CC = shutil.which("cc") or shutil.which("gcc")
pytestmark = pytest.mark.skipif(CC is None, reason="no C compiler (cc) on this machine")


def _run_c(calibration, recording, tmp_path):
    for name, text in c_sources(calibration, rate_hz=recording.rate_hz).items():
        (tmp_path / name).write_text(text)
    (tmp_path / "driver.c").write_text(DRIVER)
    exe = tmp_path / "driver"
    subprocess.run(
        [
            CC,
            "-std=c99",
            "-O2",
            "-Wall",
            "-Werror",
            "-o",
            str(exe),
            str(tmp_path / "driver.c"),
            str(tmp_path / "gyrocomp.c"),
            "-lm",
        ],
        check=True,
        capture_output=True,
        text=True,
    )
    gyro = np.zeros((recording.n_samples, 3))
    cols = {"gyro_x": 0, "gyro_y": 1, "gyro_z": 2}
    for j, axis in enumerate(recording.gyro_axes):
        gyro[:, cols[axis]] = recording.gyro_dps[:, j]
    accel = recording.accel_g if recording.accel_g is not None else np.zeros((recording.n_samples, 3))
    table = np.column_stack([recording.time_s, gyro, accel, recording.temperature_degc])
    text = "\n".join(" ".join(repr(float(v)) for v in row) for row in table) + "\n"
    done = subprocess.run([str(exe)], input=text, capture_output=True, text=True, check=True)
    out = np.loadtxt(done.stdout.splitlines())
    return out[:, [cols[a] for a in recording.gyro_axes]]


def _compare(calibration, recording, tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ours = apply(calibration, recording).gyro_dps
    theirs = _run_c(calibration, recording, tmp_path)
    scale = np.maximum(np.abs(ours), 1.0)
    assert np.max(np.abs(theirs - ours) / scale) < 1e-9


def test_polynomial_lag_and_hysteresis(tmp_path):
    prof = get_profile("cycle", set_points_degc=(-30.0, 80.0), cycles=1)
    runs = [simulate("adxrs450", profile=prof, rate_hz=1, seed=s).recording for s in range(2)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_calibration(runs, hysteresis="turning-point+lag", hysteresis_band_degc=(55.0, 80.0))
    assert cal.axes["gyro_z"].lag_time_constant_s > 0 and cal.axes["gyro_z"].hysteresis is not None
    held = simulate(
        "adxrs450",
        profile=get_profile("cycle", set_points_degc=(-30.0, 80.0), cycles=2, ramp_rate_degc_per_min=3.0),
        rate_hz=1,
        seed=9,
    ).recording
    _compare(cal, held, tmp_path)


def test_g_sensitivity_with_time_gaps(tmp_path):
    runs = [simulate("consumer", profile="combined", duration_s=9000, rate_hz=1, seed=s).recording for s in range(2)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_calibration(runs, acceleration="matrix2")
    held = simulate("consumer", profile="combined", duration_s=9000, rate_hz=1, seed=5).recording
    assert held.gaps and cal.has_acceleration
    _compare(cal, held, tmp_path)


def test_joint_network_reading_temperature_and_accelerations(tmp_path):
    runs = [simulate("consumer", profile="combined", duration_s=9000, rate_hz=1, seed=s).recording for s in range(2)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_pipeline(runs, "joint-mlp")
    held = simulate("consumer", profile="combined", duration_s=9000, rate_hz=1, seed=5).recording
    _compare(cal, held, tmp_path)


def test_single_axis_model_passes_other_axes_through(tmp_path):
    runs = [simulate("mti10", profile="chamber", duration_s=2000, rate_hz=2, seed=s).recording for s in range(2)]
    cal = fit_calibration([r.take(slice(None)) for r in runs], temperature=Polynomial(2))
    cal = type(cal)(axes={"gyro_y": cal.axes["gyro_y"]}, model=cal.model)
    held = simulate("mti10", profile="chamber", duration_s=2000, rate_hz=2, seed=3).recording
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ours = apply(cal, held, axes=("gyro_y",)).gyro_dps  # named: the data has axes the model lacks
    theirs = _run_c(cal, held, tmp_path)
    np.testing.assert_array_equal(theirs[:, 0], held.gyro_dps[:, 0])
    np.testing.assert_allclose(theirs, ours, rtol=1e-9, atol=1e-12)


def test_temperature_network_then_acceleration_network(tmp_path):
    runs = [simulate("consumer", profile="combined", duration_s=9000, rate_hz=1, seed=s).recording for s in range(2)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_pipeline(runs, "mlp>mlp-accel")
    assert cal.axes["gyro_x"].acceleration_network is not None
    held = simulate("consumer", profile="combined", duration_s=9000, rate_hz=1, seed=5).recording
    _compare(cal, held, tmp_path)


DRIVER_ACCEL = DRIVER.replace(
    'printf("%.17g %.17g %.17g\\n", out[0], out[1], out[2]);',
    'printf("%.17g %.17g %.17g %.17g %.17g %.17g\\n", out[0], out[1], out[2], '
    "s.accel_out[0], s.accel_out[1], s.accel_out[2]);",
)


def _triad(k0, unit, bias=(0.0, 0.0, 0.0), k1=None):
    zeros = ((0.0,) * 3,) * 3
    k0 = tuple(map(tuple, np.eye(3) + np.asarray(k0)))
    per_degc = () if k1 is None else (tuple(map(tuple, k1)),)
    return TriadCalibration(
        k0,
        bias,
        "rate-table" if unit == "deg/s" else "norm",
        zeros,
        (0.0, 0.0, 0.0),
        unit,
        reference_degc=None if k1 is None else 25.0,
        sensitivity_per_degc=per_degc,
        sensitivity_per_degc_stderr=() if k1 is None else (zeros,),
    )


#: a gyro K(T) linear in temperature (0.5 % scale, 1 mrad misalignment, 50 ppm/degC) and an accelerometer triad
GYRO_TRIAD = _triad(
    [[5e-3, 1e-3, -1e-3], [-1e-3, -4e-3, 2e-3], [1e-3, -2e-3, 3e-3]], "deg/s", k1=np.diag([5e-5, -3e-5, 4e-5]) + 1e-6
)
ACCEL_TRIAD = _triad([[2e-3, 1e-3, -2e-3], [0.0, -3e-3, 1.5e-3], [0.0, 0.0, 4e-3]], "g", bias=(0.02, -0.015, 0.03))


@pytest.mark.slow
def test_accelerometer_temperature_models_g_sensitivity_and_both_triads(tmp_path):
    from gyrocomp.models.fit import fit_channels

    runs = [simulate("consumer", profile="combined", duration_s=9000, rate_hz=1, seed=s).recording for s in range(2)]
    chamber = [simulate("consumer", profile="cycle", rate_hz=0.5, seed=s).recording for s in range(2)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_channels(runs, ("gyro", "accel"))
        lagged = fit_channels(chamber, ("accel",), options=FitOptions(hysteresis="lag")).accel_axes
        cal = dataclasses.replace(cal, accel_axes=lagged, gyro_triad=GYRO_TRIAD, accel_triad=ACCEL_TRIAD)
        ours = apply(cal, runs[1])
        plain = apply(cal.without("scale-factor").without_accel_triad(), runs[1])
    assert cal.has_acceleration
    assert np.max(np.abs(ours.gyro_dps - plain.gyro_dps)) > 1e-4  # the triads really act (on residuals near 0)
    assert np.max(np.abs(ours.accel_g - plain.accel_g)) > 1e-3
    assert any(ax.lag_time_constant_s > 0 for ax in cal.accel_axes.values())
    for name, text in c_sources(cal, rate_hz=runs[1].rate_hz).items():
        (tmp_path / name).write_text(text)
    (tmp_path / "driver.c").write_text(DRIVER_ACCEL)
    exe = tmp_path / "driver"
    subprocess.run(
        [
            CC,
            "-std=c99",
            "-O2",
            "-Wall",
            "-Werror",
            "-o",
            str(exe),
            str(tmp_path / "driver.c"),
            str(tmp_path / "gyrocomp.c"),
            "-lm",
        ],
        check=True,
        capture_output=True,
        text=True,
    )
    rec = runs[1]
    table = np.column_stack([rec.time_s, rec.gyro_dps, rec.accel_g, rec.temperature_degc])
    text = "\n".join(" ".join(repr(float(v)) for v in row) for row in table) + "\n"
    out = np.loadtxt(
        subprocess.run([str(exe)], input=text, capture_output=True, text=True, check=True).stdout.splitlines()
    )
    for theirs, mine in ((out[:, :3], ours.gyro_dps), (out[:, 3:], ours.accel_g)):
        assert np.max(np.abs(theirs - mine) / np.maximum(np.abs(mine), 1.0)) < 1e-9
    assert np.max(np.abs(ours.accel_g - rec.accel_g)) > 1e-3  # the accelerometer really was compensated


def test_the_two_files_are_written_both_or_neither(tmp_path):
    runs = [simulate("mti10", profile="chamber", duration_s=1200, rate_hz=1, seed=s).recording for s in range(2)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_calibration(runs, temperature=Polynomial(2), hysteresis="none", acceleration="none")
    (tmp_path / "gyrocomp.h").write_text("old header\n")
    (tmp_path / "gyrocomp_learn.c").mkdir()  # the last file cannot be written
    with pytest.raises(InputError, match=r"gyrocomp_learn.c: is a folder"):
        write_c_sources(cal, tmp_path)
    assert (tmp_path / "gyrocomp.h").read_text() == "old header\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["gyrocomp.h", "gyrocomp_learn.c"]  # no temporary left
    written = write_c_sources(cal, tmp_path / "new")
    assert [p.name for p in written] == ["gyrocomp.h", "gyrocomp.c", "gyrocomp_learn.h", "gyrocomp_learn.c"]
    assert "#ifndef" in written[0].read_text() and "gyrocomp_learn_step" in written[3].read_text()
    assert [p.name for p in write_c_sources(cal, tmp_path / "alone", with_learner=False)] == [
        "gyrocomp.h",
        "gyrocomp.c",
    ]


HOSTILE_NAMES = [
    '*/ int gyrocomp_evil(void) { return system("id"); } /*',
    "a??/\nb",
    "\\\n#include <stdlib.h>",
    "*" * 300,
    "mod\u00e8le \u2028 */",
    "\x00\x1b[2J",
]


@pytest.mark.parametrize("hostile", HOSTILE_NAMES)
def test_a_hostile_model_name_compiles_to_the_same_code_as_a_plain_one(tmp_path, hostile):
    """A model file's text never reaches the generated C except inside comments, encoded for them: the objects
    compiled from a model named ``plain`` and from one named with a comment-closing, line-splicing, trigraph or
    control string are byte for byte the same."""
    run_ = simulate("consumer", profile="cycle", duration_s=3000, rate_hz=1, seed=1).recording
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_calibration([run_], temperature=Polynomial(2), hysteresis="none")
    objects = []
    for k, name in enumerate(("plain", hostile)):
        folder = tmp_path / str(k)
        folder.mkdir()
        for file, text in c_sources(dataclasses.replace(cal, model=name)).items():
            (folder / file).write_text(text)
        subprocess.run(
            [
                CC,
                "-std=c99",
                "-O2",
                "-Wall",
                "-Werror",
                "-c",
                "-o",
                str(folder / "gyrocomp.o"),
                str(folder / "gyrocomp.c"),
            ],
            check=True,
            capture_output=True,
            text=True,
            cwd=folder,
        )
        objects.append((folder / "gyrocomp.o").read_bytes())
    assert objects[0] == objects[1]


def test_heating_and_cooling_branches(tmp_path):
    part = GyroErrorModel(
        axes=("gyro_z",),
        temperature_coefficients=((0.01, 5e-5),),
        t_ref_degc=25.0,
        hysteresis=Hysteresis(((0.03, 0.0008),), transition_degc=5.0),
        noise_density_dps_per_sqrt_hz=0.005,
        turn_on_bias_sigma_dps=0.05,
    )
    runs = [
        simulate(part, profile=get_profile("cycle", set_points_degc=sp, cycles=1), rate_hz=1, seed=s).recording
        for s, sp in ((0, (-20.0, 70.0)), (1, (-10.0, 60.0)))
    ]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_calibration(runs, hysteresis="branch+lag")
    assert type(cal.axes["gyro_z"].hysteresis).__name__ == "BranchCurve" and cal.axes["gyro_z"].lag_time_constant_s > 0
    # past the calibrated range on both sides, two turns
    held = simulate(
        part,
        profile=get_profile("cycle", set_points_degc=(-30.0, 80.0), cycles=2, ramp_rate_degc_per_min=3.0),
        rate_hz=1,
        seed=9,
    ).recording
    _compare(cal, held, tmp_path)


def test_lookup_table_with_lag_and_branches_past_its_grid(tmp_path):
    """A table curve (every axis: 3, 8 and 16 intervals) under the lag and heating/cooling branches, on a run
    that goes past the table's grid at both ends: the C is apply's to 1e-9."""
    part = GyroErrorModel(
        axes=("gyro_x", "gyro_y", "gyro_z"),
        temperature_coefficients=((0.01,), (0.02,), (0.03,)),
        t_ref_degc=25.0,
        hysteresis=Hysteresis(((0.03,), (0.02,), (0.01,)), transition_degc=5.0),
        noise_density_dps_per_sqrt_hz=0.005,
    )
    runs = [
        simulate(part, profile=get_profile("cycle", set_points_degc=sp, cycles=1), rate_hz=1, seed=s).recording
        for s, sp in ((0, (-20.0, 70.0)), (1, (-10.0, 60.0)))
    ]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_calibration(runs, hysteresis="branch+lag")
    tables = {
        "gyro_x": LookupTableCurve((0.0, 0.4, -0.1, 0.2), -20.0, 70.0),
        "gyro_y": LookupTableCurve(tuple(np.sin(np.arange(9.0))), -20.0, 70.0),
        "gyro_z": LookupTableCurve(tuple(np.cos(np.arange(17.0))), -20.0, 70.0),
    }
    cal = dataclasses.replace(
        cal, axes={a: dataclasses.replace(ax, temperature=tables[a]) for a, ax in cal.axes.items()}
    )
    held = simulate(
        part,
        profile=get_profile("cycle", set_points_degc=(-30.0, 80.0), cycles=2, ramp_rate_degc_per_min=3.0),
        rate_hz=1,
        seed=9,
    ).recording
    _compare(cal, held, tmp_path)


def test_a_temperature_rate_term_with_lag(tmp_path):
    runs = [chamber_run([-10.0, 60.0, -10.0], 1.0, seed=s, rate_hz=1.0) for s in (1, 2)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_calibration(runs, hysteresis="rate+lag")
    assert all(ax.rate_term is not None for ax in cal.axes.values())
    _compare(cal, chamber_run([-5.0, 60.0, -5.0], 3.0, seed=3, rate_hz=1.0), tmp_path)


@pytest.mark.parametrize(
    "memory, curve", [("turning-table+lag", "TurningTableCurve"), ("play-bank+lag", "PlayBankCurve")]
)
def test_a_memory_of_any_shape_with_lag_past_the_fitted_range(memory, curve, tmp_path):
    """A turning-point table or a bank of plays fitted under the lag, applied to a run that turns three times and
    goes farther from its turns and past the range than the fit saw (the table held past its last knot, each play's
    state carried sample by sample): the C is apply's to 1e-9."""
    runs = [chamber_run([-10.0, 60.0, -10.0], 1.0, seed=s, rate_hz=1.0) for s in (1, 2)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_calibration(runs, hysteresis=memory)
    assert all(type(ax.hysteresis).__name__ == curve for ax in cal.axes.values())
    _compare(cal, chamber_run([-25.0, 75.0, -25.0, 40.0], 3.0, seed=3, rate_hz=1.0), tmp_path)
