"""Scale factor and misalignment (#19): accelerometer multi-position and gyro rate-table calibration.

Truth from the simulator (known K and bias), imucal's published Ferraris result on its own session, and the
norm of gravity on real multi-position sessions (held-out recordings where the dataset has them).
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pandas as pd
import pytest

from gyrocomp import Calibration, Compensator, apply, evaluate
from gyrocomp.errors import DataQualityWarning, InputError
from gyrocomp.export.autopilot import px4_params_file
from gyrocomp.export.c_code import c_sources
from gyrocomp.io.schedule import apply_schedule, read_rate_schedule
from gyrocomp.io.tables import read_table, write_recording
from gyrocomp.models.fit import fit_channels
from gyrocomp.fitting.rate_table import fit_gyro_rate_table, rate_segments
from gyrocomp.fitting.triad_fit import Pose, find_poses, fit_accel_multiposition, rq_upper
from gyrocomp.recording import ACCEL_AXES, GYRO_AXES, Recording
from gyrocomp.simulation import AccelErrorModel, GyroErrorModel, get_profile, preset_model, simulate, tumble_positions
from gyrocomp.calibration.triad import TriadCalibration
from gyrocomp.models.options import FitOptions, Polynomial

from ..conftest import run, shared_dataset, xsens_session

#: a triad with 0.2-0.4 % scale errors and 1-2 mrad misalignments, 20-30 mg bias, 100 ug/sqrt(Hz) noise
ACCEL = AccelErrorModel(
    bias_g=(0.02, -0.015, 0.03),
    noise_density_g_per_sqrt_hz=100e-6,
    scale_misalignment=((2e-3, 1e-3, -2e-3), (0.5e-3, -3e-3, 1.5e-3), (-1e-3, 2e-3, 4e-3)),
)


def _tumble(positions, seed=1):
    prof = get_profile("tumble", positions_g=positions, position_s=30.0)
    return simulate(GyroErrorModel(accelerometer=ACCEL), profile=prof, rate_hz=20, seed=seed).recording


def _within(fitted, stderr, truth, sigmas=3.0):
    z = (np.asarray(fitted) - np.asarray(truth)) / np.asarray(stderr)
    assert np.all(np.abs(z) < sigmas), z


# -- the frozen result -------------------------------------------------------------------------------------
def test_correct_inverts_the_triad_model_with_temperature():
    k0 = np.eye(3) + [[1e-3, 2e-3, 0], [-1e-3, 3e-3, 1e-3], [0, 5e-4, -2e-3]]
    k1 = np.diag([3e-5, -2e-5, 1e-5])
    cal = TriadCalibration(
        tuple(map(tuple, k0)),
        (0.1, -0.2, 0.3),
        "rate-table",
        tuple(map(tuple, k0 * 0)),
        (0.0, 0.0, 0.0),
        "deg/s",
        reference_degc=25.0,
        sensitivity_per_degc=(tuple(map(tuple, k1)),),
        sensitivity_per_degc_stderr=(tuple(map(tuple, k1 * 0)),),
    )
    rng = np.random.default_rng(0)
    v, t = rng.normal(0, 200, (500, 3)), rng.uniform(-20, 70, 500)
    raw = np.einsum("nij,nj->ni", k0 + np.multiply.outer(t - 25.0, k1), v) + cal.bias
    np.testing.assert_allclose(cal.correct(raw, t), v, atol=1e-9)
    again = TriadCalibration.from_dict(json.loads(json.dumps(cal.to_dict())))
    assert again == cal
    assert np.array_equal(TriadCalibration.identity("g").correct(v), v) and TriadCalibration.identity().unit == "deg/s"
    with pytest.raises(InputError, match="depends on temperature; give the temperature"):
        cal.correct(raw)


def test_triad_file_entries_are_validated():
    good = TriadCalibration(
        tuple(map(tuple, np.eye(3))), (0.0, 0.0, 0.0), "norm", tuple(map(tuple, np.zeros((3, 3)))), (0.0, 0.0, 0.0), "g"
    ).to_dict()
    with pytest.raises(InputError, match=r"accel_triad.sensitivity: expected 3 rows of 3 finite numbers"):
        TriadCalibration.from_dict({**good, "sensitivity": [[1, 0], [0, 1]]}, "accel_triad")
    with pytest.raises(InputError, match="accel_triad: no 'bias_g' entry"):
        TriadCalibration.from_dict({k: v for k, v in good.items() if k != "bias_g"}, "accel_triad")
    with pytest.raises(InputError, match="singular"):
        TriadCalibration.from_dict({**good, "sensitivity": [[1, 0, 0], [1, 0, 0], [0, 0, 1]]}, "accel_triad")


# -- accelerometer, simulated ------------------------------------------------------------------------------
#: poses tilted between every pair of axes: with the tumble's, they determine all nine unknowns of the norm method
BETWEEN_AXES = ((0.7071, 0.7071, 0.0), (-0.5, 0.5, 0.7071), (0.5, -0.5, -0.7071), (0.0, -0.7071, 0.7071))


def test_norm_method_recovers_bias_scale_and_misalignment_within_three_standard_errors():
    rec = _tumble(tumble_positions() + BETWEEN_AXES)
    fit = fit_accel_multiposition(find_poses(rec))
    cal = fit.calibration
    assert cal.method == "norm" and len(fit.poses) == 31
    # the norm of gravity fixes K up to a rotation of the frame: compare with the upper-triangular factor
    _within(cal.sensitivity, np.maximum(cal.sensitivity_stderr, 1e-12), rq_upper(ACCEL.sensitivity))
    _within(cal.bias, cal.bias_stderr, ACCEL.bias_g)
    assert 0.3 < fit.reduced_chi_square < 3.0  # the poses scatter as their noise says
    assert fit.norm_rms_error_g < fit.norm_rms_error_before_g / 1000


def test_six_position_method_recovers_the_full_matrix_within_three_standard_errors():
    rec = _tumble(tumble_positions((1.0, -1.0)))
    fit = fit_accel_multiposition(find_poses(rec))
    cal = fit.calibration
    assert cal.method == "six-position" and len(fit.poses) == 6
    _within(cal.sensitivity, cal.sensitivity_stderr, ACCEL.sensitivity)
    _within(cal.bias, cal.bias_stderr, ACCEL.bias_g)


def _poses(vectors):
    return [Pose("test", 0.0, 1.0, 100, np.asarray(v, float), np.full(3, 1e-5), None, None) for v in vectors]


def test_too_few_or_one_sided_poses_are_refused_naming_what_is_missing():
    with pytest.raises(InputError, match="poses: 4 still poses found; .* needs at least 6"):
        fit_accel_multiposition(_poses(np.eye(3).tolist() + [[-1, 0, 0]]))
    up_only = [[0.6, 0, 0.8], [0, 0.6, 0.8], [-0.6, 0, 0.8], [0, -0.6, 0.8], [0, 0, 1], [0.3, 0.3, 0.9]]
    with pytest.raises(InputError, match="no pose has the z axis pointing down"):
        fit_accel_multiposition(_poses(up_only))
    tilted = tumble_positions((0.5, -0.5))
    with pytest.raises(InputError, match=r"no pose along \+x, -x, \+y, -y"):
        fit_accel_multiposition(_poses(tilted), method="six-position")
    with pytest.raises(InputError, match="6 distinct orientations .* needs at least 10"):
        fit_accel_multiposition(_poses(tumble_positions((1.0, -1.0)) * 2), method="norm")
    # the tumble turns gravity in the x-z and y-z planes only, never between x and y: that coupling is fixed
    with pytest.warns(
        DataQualityWarning,
        match="no pose has gravity between the x and y axes; that misalignment is not determined and is taken as zero",
    ):
        fit = fit_accel_multiposition(_poses(tumble_positions()), method="norm")
    assert fit.calibration.sensitivity[0][1] == 0.0 and fit.degrees_of_freedom == 27 - 8
    assert fit_accel_multiposition(_poses(tumble_positions())).calibration.method == "six-position"
    with pytest.raises(InputError, match="accelerations in g"):
        fit_accel_multiposition(_poses(np.array(tumble_positions((1.0, -1.0))) * 0.05))
    rec = Recording(np.arange(10.0), np.zeros((10, 1)), ("gyro_z",))
    with pytest.raises(InputError, match="needs the three accelerometer axes"):
        find_poses(rec)


#: a consumer part whose accelerometer's scale and misalignment change with temperature: 15-30 ppm/degC
ACCEL_TEMPCO = ((2e-5, 2e-6, 0.0), (0.0, -1.5e-5, -3e-6), (1e-6, 0.0, 3e-5))
DRIFTING = dataclasses.replace(
    preset_model("consumer"),
    accelerometer=dataclasses.replace(
        preset_model("consumer").accelerometer,
        scale_misalignment=ACCEL.scale_misalignment,
        scale_misalignment_per_degc=ACCEL_TEMPCO,
    ),
)


def test_accelerometer_triad_over_temperature_recovers_dk_dt_and_holds_on_another_run():
    """The combined profile (six faces visited through -20..70 degC): K(T) and its temperature coefficients within
    3 standard errors; on another run the norm of gravity per pose is 1 g within 1.3e-4 g RMS (measured), 7.6e-4 g
    with K held constant, 0.03 g raw."""
    cal = fit_channels(simulate(DRIFTING, profile="combined", rate_hz=1, seed=0).recording, ("accel",))
    triad = cal.accel_triad
    assert triad.method == "six-position" and triad.temperature_order == 1 and cal.accel_axes
    _within(triad.sensitivity_per_degc[0], triad.sensitivity_per_degc_stderr[0], ACCEL_TEMPCO)
    at_reference = ACCEL.sensitivity + np.asarray(ACCEL_TEMPCO) * (triad.reference_degc - DRIFTING.t_ref_degc)
    _within(triad.sensitivity, triad.sensitivity_stderr, at_reference)
    constant = dataclasses.replace(
        cal,
        accel_triad=dataclasses.replace(
            triad, sensitivity_per_degc=(), sensitivity_per_degc_stderr=(), reference_degc=None
        ),
    )
    other = simulate(DRIFTING, profile="combined", rate_hz=1, seed=5).recording

    def norm_rms_g(calibration):
        out = apply(calibration, other).accel_g
        return np.sqrt(
            np.mean(
                [(np.linalg.norm(out[p.start_index : p.stop_index].mean(axis=0)) - 1.0) ** 2 for p in find_poses(other)]
            )
        )

    assert norm_rms_g(cal) < 2.5e-4 and norm_rms_g(cal) < norm_rms_g(constant) / 3
    with pytest.raises(InputError, match="temperature_order: the norm method fits K constant"):
        fit_accel_multiposition(find_poses(other), method="norm", temperature_order=1)


# -- accelerometer, real sessions -------------------------------------------------------------------------
def test_six_position_equals_imucal_ferraris_on_its_annotated_session():
    """imucal's regression snapshot (tests/snapshots/example_cal.json, mad-lab-fau/imucal, MIT) for this session:
    K_a R_a [counts per m/s^2] and b_a [counts], gravity 9.81 m/s^2. With one pose per face our least squares
    is Ferraris's closed form for K; the bias differs by method (imucal: the mean of the two poses along each
    axis; ours: of all six), and agrees within our standard error."""
    data = pd.read_csv(shared_dataset("imucal-ferraris") / "annotated_session.csv")
    counts_per_g = 2048.0
    poses = []
    for part in ("x_p", "x_a", "y_p", "y_a", "z_p", "z_a"):
        a = data.loc[data.part == part, ["acc_x", "acc_y", "acc_z"]].to_numpy() / counts_per_g
        poses.append(
            Pose(part, 0.0, a.shape[0] / 204.8, a.shape[0], a.mean(0), a.std(0, ddof=1) / np.sqrt(len(a)), None, None)
        )
    cal = fit_accel_multiposition(poses).calibration
    k_a = np.diag([208.54567263762615, 208.0011341167055, 214.78455364603022])
    r_a = np.array(
        [
            [0.9999125214309234, 0.007122056140390757, -0.011145662922687352],
            [-0.007947378455060604, 0.9996887358297629, 0.023648903373787954],
            [0.021342900724016442, -0.010781879507682177, 0.9997140749549175],
        ]
    )
    b_a = np.array([-6.018868019671572, -48.287874016760156, -28.96636637224333])
    np.testing.assert_allclose(cal.sensitivity, k_a @ r_a * 9.81 / counts_per_g, rtol=1e-9)
    _within(np.array(cal.bias) * counts_per_g, np.array(cal.bias_stderr) * counts_per_g, b_a)


def test_imu_tk_xsens_session_gravity_norm_is_flat_after_calibration():
    """Tedaldi et al.'s own data (38 hand-placed poses): measured 1.0e-4 g RMS, 4.2e-4 g max-min after."""
    fit = fit_accel_multiposition(find_poses(xsens_session()))
    assert fit.calibration.method == "norm" and len(fit.poses) >= 35
    assert fit.norm_rms_error_g < 2e-4
    assert np.ptp(fit.norm_after_g) < 1e-3
    assert np.all(np.abs(fit.calibration.scale_factor_error - 3724 / 3700 + 1) < 0.1)  # the counts per g found


def test_imucal_session_poses_found_and_flat_to_their_placement():
    """The six faces of imucal's example session, found without its annotation (13 still stretches, some
    the same face twice): six-position method, 1.1e-3 g RMS of the norm after (hand placement)."""
    folder = shared_dataset("imucal-ferraris")
    data = pd.read_csv(folder / "example_ferraris_session.csv")
    rec = Recording(
        data.n_samples.to_numpy() / 102.4,
        data[["gyr_x", "gyr_y", "gyr_z"]].to_numpy(),
        GYRO_AXES,
        accel_g=data[["acc_x", "acc_y", "acc_z"]].to_numpy() / 9.81,
        accel_axes=ACCEL_AXES,
        source="ferraris",
    )
    fit = fit_accel_multiposition(find_poses(rec))
    assert fit.calibration.method == "six-position"
    assert fit.norm_rms_error_g < 2e-3 < fit.norm_rms_error_before_g
    sections = json.loads((folder / "example_ferraris_session_list.json").read_text())
    annotated = fit_accel_multiposition(
        find_poses(
            rec, ranges=[(sections[k]["start"], sections[k]["end"]) for k in ("x_p", "x_a", "y_p", "y_a", "z_p", "z_a")]
        )
    )
    np.testing.assert_allclose(fit.calibration.sensitivity, annotated.calibration.sensitivity, atol=2e-3)


def _mpu(path):
    m = np.loadtxt(path, delimiter=",", skiprows=5)
    return Recording(
        np.arange(len(m)) / 100.0,
        m[:, 3:] / 131.0,
        GYRO_AXES,
        accel_g=m[:, :3] / 16384.0,
        accel_axes=ACCEL_AXES,
        source=path.name,
    )


def test_mpu6050_calibration_holds_on_held_out_static_recordings():
    """Ten poses, none between x and y (that coupling is fixed at zero: two degrees of freedom), then two other
    static recordings of the same part: their norm of gravity is 1 g within 2e-3 after the calibration, 0.08-0.09 g
    off before."""
    folder = shared_dataset("tomisuarez2-mpu6050")
    with pytest.warns(DataQualityWarning, match="no pose has gravity between the x and y axes"):
        fit = fit_accel_multiposition(find_poses(_mpu(folder / "example_data_calibration.csv")))
    assert len(fit.poses) == 10 and fit.degrees_of_freedom == 2
    for name in ("imu_static_test.csv", "example_data_tinit_calc.csv"):
        mean = _mpu(folder / name).accel_g.mean(axis=0)
        assert abs(np.linalg.norm(mean) - 1.0) > 0.05
        assert abs(np.linalg.norm(fit.calibration.correct(mean[None])[0]) - 1.0) < 2e-3


# -- gyro, rate table --------------------------------------------------------------------------------------
#: the MTi-10 preset's scale factor (500 ppm, 30 ppm/degC) and misalignment (~0.05 deg); g-sensitivity off, as it
#: is its own stage and would otherwise be read as rate error between table orientations
RATE_PART = preset_model("mti10").without("g-sensitivity")


def _rate_run(temperature_degc, seed):
    prof = get_profile(
        "ratetable", set_points_degc=(temperature_degc,), rates_dps=(100.0, -100.0, 300.0, -300.0), position_s=60.0
    )
    return simulate(RATE_PART, profile=prof, rate_hz=50, seed=seed).recording


@pytest.fixture(scope="module")
def rate_fit():
    return fit_gyro_rate_table([_rate_run(t, s) for s, t in enumerate((-10.0, 25.0, 60.0))])


def test_rate_table_recovers_scale_misalignment_and_their_temperature_coefficients(rate_fit):
    cal = rate_fit.calibration
    assert cal.temperature_order == 1 and rate_fit.held_out_rms_dps[1] < rate_fit.held_out_rms_dps[0]
    scale = np.array(RATE_PART.scale_factor_error_ppm) * 1e-6
    tempco = np.array(RATE_PART.scale_factor_tempco_ppm_per_degc) * 1e-6
    truth = (
        np.eye(3) + np.diag(scale + tempco * (cal.reference_degc - RATE_PART.t_ref_degc)) + RATE_PART.misalignment_rad
    )
    _within(cal.sensitivity, cal.sensitivity_stderr, truth)
    _within(cal.sensitivity_per_degc[0], cal.sensitivity_per_degc_stderr[0], np.diag(tempco))


def test_rate_table_cuts_the_held_out_rate_error_tenfold(rate_fit):
    held_out = rate_segments([_rate_run(40.0, 9)])
    ref = np.array([s.reference_dps for s in held_out])
    gyro = np.array([s.gyro_dps for s in held_out])
    temp = np.array([s.temperature_degc for s in held_out])
    bias = gyro[np.all(ref == 0, axis=1)].mean(axis=0)  # bias-only compensation: the run's own bias at rest
    fast = np.linalg.norm(ref, axis=1) >= 100
    bias_only = np.sqrt(np.mean(((gyro - bias) - ref)[fast] ** 2))
    full = np.sqrt(np.mean((rate_fit.calibration.correct(gyro - bias, temp) - ref)[fast] ** 2))
    assert bias_only > 0.1  # 500 ppm and 0.05 deg at 100-300 deg/s
    assert full < bias_only / 10


def test_rate_table_bad_input_is_refused_naming_what_is_missing():
    still = simulate(RATE_PART, profile="static", duration_s=60, rate_hz=10, seed=0).recording
    with pytest.raises(InputError, match=r"no reference rates \(ref_rate_x"):
        fit_gyro_rate_table([still])
    prof = get_profile("ratetable", rates_dps=(100.0, 300.0), position_s=10.0)
    one_way = simulate(RATE_PART, profile=prof, rate_hz=10, seed=0).recording
    with pytest.raises(InputError, match="no constant-rate stretch turning about x in both directions"):
        fit_gyro_rate_table([one_way])
    run = _rate_run(25.0, 0)
    with pytest.raises(InputError, match="temperature_order: 1 needs runs at 2 or more temperatures"):
        fit_gyro_rate_table([run], temperature_order=1)


def test_reference_rate_columns_round_trip_and_all_three_are_required(tmp_path):
    run = _rate_run(25.0, 0).take(slice(0, 2000))
    path = tmp_path / "table.csv"
    write_recording(run, path)
    back = read_table(path).recording
    np.testing.assert_allclose(back.reference_rate_dps, run.reference_rate_dps)
    text = path.read_text().replace("ref_rate_z", "other")
    path.write_text(text)
    with pytest.raises(InputError, match=r"table.csv: reference rate column\(s\) ref_rate_z missing"):
        read_table(path)


# -- in the model file, the compensation and the CLI ------------------------------------------------------
def test_fit_with_rate_table_runs_stores_k_and_apply_corrects_the_held_out_rates(tmp_path, rate_fit):
    chamber = [
        simulate(RATE_PART, profile="chamber", duration_s=3600, rate_hz=2, seed=20 + s).recording for s in range(3)
    ]
    rate_runs = [_rate_run(t, s) for s, t in enumerate((-10.0, 25.0, 60.0))]
    cal = fit_channels(rate_runs + chamber, options=FitOptions(hysteresis="none"))
    assert cal.gyro_triad is not None and cal.gyro_triad == rate_fit.calibration
    path = tmp_path / "model.json"
    cal.save(path)
    loaded = Calibration.load(path)
    assert loaded.gyro_triad == cal.gyro_triad and loaded.to_json() == cal.to_json()
    held = _rate_run(40.0, 9)
    out = apply(loaded, held, turn_on_window_s=50)
    plain = apply(loaded.without("scale-factor"), held, turn_on_window_s=50)

    def rate_error_dps(rec):  # RMS over the 100-300 deg/s stretches of their mean error
        segs = [s for s in rate_segments([rec]) if np.linalg.norm(s.reference_dps) >= 100]
        return np.sqrt(np.mean([(s.gyro_dps - s.reference_dps) ** 2 for s in segs]))

    assert rate_error_dps(out) < rate_error_dps(plain) / 5
    (rates,) = [t for t in evaluate(loaded, held, turn_on_window_s=50).triads if t.figure == "rate_error_dps"]
    assert rates.rms_compensated < rates.rms_raw / 5 and rates.raw.size == 12  # 100 and 300 deg/s, both ways, 3 axes
    # streaming: any chunking gives the batch result
    comp = Compensator(loaded, held.gyro_axes, turn_on_window_s=50, rate_hz=held.rate_hz)
    edges = np.r_[0, np.sort(np.random.default_rng(3).choice(held.n_samples, 7, replace=False)), held.n_samples]
    chunks = [
        comp.update(held.time_s[a:b], held.gyro_dps[a:b], held.temperature_degc[a:b], held.accel_g[a:b])
        for a, b in zip(edges[:-1], edges[1:])
    ]
    np.testing.assert_allclose(np.concatenate([*chunks, comp.finish()]), out.gyro_dps, rtol=0, atol=1e-12)
    with pytest.raises(InputError, match="couples gyro_x, gyro_y and gyro_z"):
        apply(loaded, held, axes=("gyro_z",))


def test_accel_channel_on_a_multi_position_session_without_temperature(tmp_path):
    rec = xsens_session()
    cal = fit_channels(rec, ("accel",))
    assert cal.accel_triad is not None and not cal.accel_axes and cal.accel_triad.method == "norm"
    path = tmp_path / "accel.json"
    cal.save(path)
    out = apply(Calibration.load(path), rec)
    norms = [np.linalg.norm(out.accel_g[p.start_s <= rec.time_s][: p.samples].mean(axis=0)) for p in find_poses(rec)]
    assert np.sqrt(np.mean((np.array(norms) - 1.0) ** 2)) < 2e-4
    with pytest.raises(InputError, match="no temperature .* and do not turn every accelerometer axis"):
        fit_channels(rec.take(slice(0, 5000)), ("accel",))


@pytest.mark.slow
def test_cli_fits_the_scale_factor_from_rate_table_files(tmp_path):
    # several set points of a one-temperature profile: one run per set point
    result = run(
        "simulate",
        "--preset",
        "mti10",
        "--profile",
        "ratetable",
        "--set-points",
        "-10,25,60",
        "--rates",
        "100,-100,300,-300",
        "--position-time",
        "30",
        "--rate",
        "20",
        "--disable",
        "g-sensitivity",
        "--seed",
        1,
        "-o",
        tmp_path / "rt.csv",
    )
    assert result.returncode == 0, result.stderr
    for i, seed in enumerate((1, 2, 3)):
        (tmp_path / f"rt_{i}.csv").rename(tmp_path / f"rt{seed}.csv")
    temperatures = [pd.read_csv(tmp_path / f"rt{s}.csv")["temperature"].mean() for s in (1, 2, 3)]
    assert np.allclose(temperatures, (-10, 25, 60), atol=0.5), temperatures
    result = run(
        "-q",
        "simulate",
        "--preset",
        "mti10",
        "--profile",
        "chamber",
        "--duration",
        "3600",
        "--rate",
        "2",
        "--runs",
        "3",
        "--disable",
        "g-sensitivity",
        "-o",
        tmp_path / "ch.csv",
    )
    assert result.returncode == 0, result.stderr
    files = [tmp_path / f"rt{s}.csv" for s in (1, 2, 3)] + [tmp_path / f"ch_{i}.csv" for i in range(3)]
    result = run("fit", *files, "-o", tmp_path / "model.json", "--hysteresis", "none")
    assert result.returncode == 0, result.stderr
    assert "gyro scale factor and misalignment (rate-table" in result.stdout
    assert Calibration.load(tmp_path / "model.json").gyro_triad is not None
    # the same rates as a schedule file beside runs without the columns: the same K
    lines = ["file,start_s,end_s,ref_rate_x,ref_rate_y,ref_rate_z"]
    for seed in (1, 2, 3):
        table = pd.read_csv(tmp_path / f"rt{seed}.csv")
        ref, t = table[["ref_rate_x", "ref_rate_y", "ref_rate_z"]].to_numpy(), table["time"].to_numpy()
        edges = np.r_[0, np.flatnonzero(np.any(np.diff(ref, axis=0) != 0, axis=1)) + 1, len(t)]
        lines += [
            ",".join([f"bare{seed}.csv"] + [repr(float(v)) for v in (t[a] - t[0], t[b - 1] - t[0] + 0.025, *ref[a])])
            for a, b in zip(edges[:-1], edges[1:])
            if np.any(ref[a] != 0)
        ]
        table.drop(columns=["ref_rate_x", "ref_rate_y", "ref_rate_z"]).to_csv(tmp_path / f"bare{seed}.csv", index=False)
    (tmp_path / "schedule.csv").write_text("\n".join(lines) + "\n")
    bare = [tmp_path / f"bare{s}.csv" for s in (1, 2, 3)] + files[3:]
    result = run(
        "fit",
        *bare,
        "-o",
        tmp_path / "scheduled.json",
        "--hysteresis",
        "none",
        "--rate-schedule",
        tmp_path / "schedule.csv",
    )
    assert result.returncode == 0, result.stderr
    assert (
        Calibration.load(tmp_path / "scheduled.json").gyro_triad == Calibration.load(tmp_path / "model.json").gyro_triad
    )
    result = run("fit", tmp_path / "ch_0.csv", "-o", tmp_path / "m.json", "--scale-factor", "matrix")
    assert result.returncode == 2 and not (tmp_path / "m.json").exists()
    assert result.stderr.strip() == (
        "gyrocomp: error: --scale-factor 'matrix': no run carries reference rates "
        "(ref_rate_x, ref_rate_y, ref_rate_z [deg/s]) or turns between still poses; a "
        "scale-factor calibration needs rate-table runs or a multi-position session with "
        "the turns recorded"
    )


def test_exports_say_what_they_leave_out_of_a_triad(rate_fit):
    chamber = [
        simulate(RATE_PART, profile="chamber", duration_s=1800, rate_hz=1, seed=40 + s).recording for s in range(2)
    ]
    cal = dataclasses.replace(
        fit_channels(chamber, options=FitOptions(temperature=Polynomial(2), hysteresis="none", acceleration="none")),
        gyro_triad=rate_fit.calibration,
    )
    with pytest.warns(DataQualityWarning, match="scale-factor and misalignment"):
        px4_params_file(cal, device_id=5)
    assert "solve3(k, out);" in c_sources(cal)["gyrocomp.c"]  # the C code carries K(T) (parity: tests/export)
    assert "solve3(k, out);" not in c_sources(cal.without("scale-factor"))["gyrocomp.c"]


def test_a_rate_schedule_file_gives_the_reference_rates_instead_of_columns(tmp_path):
    """The rates as a separate schedule (rate-table software logs them apart): the same K as the columns give,
    and every malformed schedule refused naming the row."""
    run_ = _rate_run(25.0, 0)
    plain = dataclasses.replace(run_, reference_rate_dps=None)
    write_recording(plain, tmp_path / "rt.csv")
    ref = run_.reference_rate_dps
    change = np.r_[0, np.flatnonzero(np.any(np.diff(ref, axis=0) != 0, axis=1)) + 1, run_.n_samples]
    t = run_.time_s - run_.time_s[0]
    rows = [
        f"rt.csv,{float(t[a])!r},{float(t[b - 1] + 1 / run_.rate_hz)!r},{ref[a][0]},{ref[a][1]},{ref[a][2]}"
        for a, b in zip(change[:-1], change[1:])
        if np.any(ref[a] != 0)
    ]
    (tmp_path / "schedule.csv").write_text(
        "file,start_s,end_s,ref_rate_x,ref_rate_y,ref_rate_z\n" + "\n".join(rows) + "\n"
    )
    schedule = read_rate_schedule(tmp_path / "schedule.csv")
    (back,) = apply_schedule(schedule, [read_table(tmp_path / "rt.csv").recording], [tmp_path / "rt.csv"])
    np.testing.assert_array_equal(back.reference_rate_dps, ref)
    with pytest.raises(InputError, match=r"has ref_rate_x/_y/_z columns and the schedule .* names it too"):
        schedule.apply(run_, "rt.csv")
    bad = {
        "file,start_s,end_s,ref_rate_x,ref_rate_y\nrt.csv,0,1,1,1\n": r"schedule column\(s\) ref_rate_z missing",
        "file,start_s,end_s,ref_rate_x,ref_rate_y,ref_rate_z\nrt.csv,0,x,1,1,1\n": r"row 2: end_s 'x' is not a finite",
        "file,start_s,end_s,ref_rate_x,ref_rate_y,ref_rate_z\nrt.csv,5,2,1,1,1\n": "row 2: start_s 5, end_s 2",
        "file,start_s,end_s,ref_rate_x,ref_rate_y,ref_rate_z\nrt.csv,0,10,1,0,0\nrt.csv,5,20,2,0,0\n": "rows 2 and 3: the stretches of rt.csv overlap",
    }
    for text, message in bad.items():
        (tmp_path / "bad.csv").write_text(text)
        with pytest.raises(InputError, match=message):
            read_rate_schedule(tmp_path / "bad.csv")
    (tmp_path / "other.csv").write_text("file,start_s,end_s,ref_rate_x,ref_rate_y,ref_rate_z\nelse.csv,0,10,1,0,0\n")
    with pytest.raises(InputError, match=r"other.csv, row 2: file 'else.csv' is not among the runs given"):
        apply_schedule(read_rate_schedule(tmp_path / "other.csv"), [plain], [tmp_path / "rt.csv"])
    result = run("fit", tmp_path / "rt.csv", "-o", tmp_path / "m.json", "--rate-schedule", tmp_path / "nothere.csv")
    assert result.returncode == 2 and "nothere.csv: no such file" in result.stderr
    assert not (tmp_path / "m.json").exists()


@pytest.mark.slow
def test_rate_table_runs_alone_give_k_and_apply_cuts_the_rate_error_tenfold(tmp_path):
    """Three rate-table runs alone (no chamber run), --temperature none: K(T) from the rates, one constant per run
    from their still stretches; applied with --turn-on-window to a held-out run at 40 degC, the rate error of its
    constant-rate stretches at 100-300 deg/s (means, settled) falls at least tenfold against raw."""
    common = [
        "--preset",
        "mti10",
        "--profile",
        "ratetable",
        "--rates",
        "100,-100,300,-300",
        "--position-time",
        "60",
        "--rate",
        "20",
        "--disable",
        "g-sensitivity",
    ]
    assert (
        run("-q", "simulate", *common, "--set-points", "-10,25,60", "--seed", 1, "-o", tmp_path / "rt.csv").returncode
        == 0
    )
    assert (
        run("-q", "simulate", *common, "--set-points", "40", "--seed", 9, "-o", tmp_path / "held.csv").returncode == 0
    )
    fitted = run(
        "fit", *(tmp_path / f"rt_{i}.csv" for i in range(3)), "-o", tmp_path / "k.json", "--temperature", "none"
    )
    assert fitted.returncode == 0, fitted.stderr
    assert "gyro scale factor and misalignment (rate-table" in fitted.stdout
    applied = run(
        "apply", tmp_path / "k.json", tmp_path / "held.csv", "-o", tmp_path / "out.csv", "--turn-on-window", 30
    )
    assert applied.returncode == 0, applied.stderr
    raw, out = pd.read_csv(tmp_path / "held.csv"), pd.read_csv(tmp_path / "out.csv")
    ref = raw[["ref_rate_x", "ref_rate_y", "ref_rate_z"]].to_numpy()
    edges = np.r_[0, np.flatnonzero(np.any(np.diff(ref, axis=0) != 0, axis=1)) + 1, len(ref)]
    errors = {"raw": [], "out": []}
    for a, b in zip(edges[:-1], edges[1:]):
        if 100 <= np.abs(ref[a]).max() <= 300 and b - a > 200:
            for name, table in (("raw", raw), ("out", out)):
                errors[name].append(
                    table[["gyro_x", "gyro_y", "gyro_z"]].to_numpy()[a + 40 : b - 40].mean(axis=0) - ref[a]
                )
    raw_rms, out_rms = (np.sqrt(np.mean(np.square(errors[k]))) for k in ("raw", "out"))
    assert len(errors["raw"]) == 12 and raw_rms > 0.1
    assert out_rms < raw_rms / 10
