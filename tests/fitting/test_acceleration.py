"""g-sensitivity fitted jointly with temperature, lag and hysteresis on simulated multi-position runs,
tested on a held-out run with other orientations and temperatures."""

import dataclasses
import json
import warnings

import numpy as np
import pytest

from gyrocomp import Calibration, Compensator, Polynomial, apply, fit, fit_calibration
from gyrocomp.errors import DataQualityWarning, InputError
from gyrocomp.evaluation import evaluate_stages
from gyrocomp.measures.merit import smoothed_residual_rms
from gyrocomp.fitting.acceleration import excited_columns, turned_between_positions
from gyrocomp.effects import G_SQUARED_TERMS, g_squared_products
from gyrocomp.simulation import get_profile, preset_model, simulate, tumble_positions

RATE_HZ = 1.0


@pytest.fixture(scope="module")
def consumer():
    """Three 'combined' runs of the consumer preset (tempco, lag, hysteresis, 0.1 deg/s/g) to fit on, and a
    held-out run at other temperatures (-10..60 degC) and other orientations (+-0.5 g on each axis)."""
    model = preset_model("consumer")
    prof = get_profile("combined", set_points_degc=(-20.0, 70.0), ramp_rate_degc_per_min=1.0, dwell_s=900.0)
    runs = [simulate(model, profile=prof, rate_hz=RATE_HZ, seed=s) for s in range(3)]
    held = simulate(
        model,
        profile=get_profile(
            "combined", set_points_degc=(-10.0, 60.0), positions_g=tumble_positions((0.5, -0.5)), position_s=600.0
        ),
        rate_hz=RATE_HZ,
        seed=77,
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_calibration([r.recording for r in runs])
    return model, runs, held, cal


def test_default_is_within_15_percent_of_perfect_on_every_axis(consumer):
    model, runs, held, cal = consumer
    assert "g-sensitivity" in cal.model
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        comp = apply(cal, held.recording).gyro_dps
        cubic = apply(
            fit_calibration(
                [r.recording for r in runs], temperature=Polynomial(3), hysteresis="none", acceleration="none"
            ),
            held.recording,
        ).gyro_dps
    w = int(60 * RATE_HZ)
    for j in range(3):
        perfect = smoothed_residual_rms(held.truth.noise.total_dps[:, j], w)
        ours = smoothed_residual_rms(comp[:, j] - held.truth.true_rate_dps[:, j], w)
        assert ours < 1.15 * perfect
        assert smoothed_residual_rms(cubic[:, j] - held.truth.true_rate_dps[:, j], w) > 2 * ours


def test_fitted_g_matches_the_truth_within_its_standard_errors(consumer):
    model, _, _, cal = consumer
    acc = cal.fit_report["acceleration"]
    assert acc["mode"] == "matrix" and acc["excited_axes"] == ["accel_x", "accel_y", "accel_z"]
    truth = np.asarray(model.g_sensitivity_dps_per_g)
    z = []
    for i, axis in enumerate(("gyro_x", "gyro_y", "gyro_z")):
        g = np.asarray(acc["axes"][axis]["g_sensitivity_dps_per_g"])
        se = np.asarray(acc["axes"][axis]["standard_error_dps_per_g"])
        assert np.all(se > 0) and np.all(se < 0.01)
        z.extend((g - truth[i]) / se)
        np.testing.assert_array_equal(cal.axes[axis].g_sensitivity_dps_per_g, g)
    z = np.abs(z)
    assert z.max() < 3.5 and np.mean(z < 2) >= 7 / 9


def test_stage_table_shows_each_stage(consumer):
    _, _, held, cal = consumer
    staged = evaluate_stages(cal, held.recording, window_s=100.0)
    names = list(staged.stages)
    assert names[0] == "temperature only" and names[1] == "temperature + acceleration"
    for axis in ("gyro_x", "gyro_y", "gyro_z"):
        temp_only = staged.stages["temperature only"][axis]
        with_g = staged.stages["temperature + acceleration"][axis]
        assert temp_only.bias_offset_comp_dps < temp_only.bias_offset_raw_dps
        assert with_g.bias_offset_comp_dps < 0.6 * temp_only.bias_offset_comp_dps
    d = staged.to_dict()
    assert set(d["stages"]["temperature only"]["gyro_x"]) >= {"bias_offset_comp_dps", "bias_instability_comp_dph"}


def test_streaming_with_accelerations_equals_batch(consumer):
    _, _, held, cal = consumer
    rec = held.recording
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        batch = apply(cal, rec).gyro_dps
        comp = Compensator(cal, rec.gyro_axes, rate_hz=rec.rate_hz)
        parts = [
            comp.update(rec.time_s[a:b], rec.gyro_dps[a:b], rec.temperature_degc[a:b], rec.accel_g[a:b])
            for a, b in [(0, 777), (777, 5000), (5000, rec.n_samples)]
        ]
    np.testing.assert_allclose(np.concatenate(parts), batch, rtol=0, atol=1e-12)
    with pytest.raises(InputError, match="the model has g-sensitivity; the data needs accel_x, accel_y and accel_z"):
        Compensator(cal, rec.gyro_axes, rate_hz=rec.rate_hz).update(
            rec.time_s[:10], rec.gyro_dps[:10], rec.temperature_degc[:10]
        )


def test_model_file_keeps_g_and_old_files_upgrade(consumer, tmp_path):
    _, _, held, cal = consumer
    cal.save(tmp_path / "m.json")
    assert Calibration.load(tmp_path / "m.json").axes == cal.axes
    d = json.loads((tmp_path / "m.json").read_text())
    d["schema_version"] = 2  # what schema 3 and later added, taken out (a file of schema 2 holds none of it)
    for ax in d["axes"].values():
        del (
            ax["g_sensitivity_dps_per_g"],
            ax["g_squared_dps_per_g2"],
            ax["acceleration_network"],
            ax["temperature_rate"],
        )
    for key in ("accel_axes", "accel_reference_degc", "gyro_triad", "accel_triad"):
        del d[key]
    (tmp_path / "v2.json").write_text(json.dumps(d))
    old = Calibration.load(tmp_path / "v2.json")
    assert not old.has_acceleration and old.axes["gyro_x"].temperature == cal.axes["gyro_x"].temperature


def test_g_x_g_terms_recovered_with_matrix2():
    base = preset_model("consumer").without("hysteresis", "lag", "temperature")
    q = ((0.02, 0.0, 0.0, 0.01, 0.0, 0.0), (0.0, 0.0, 0.0, 0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 0.0, 0.0, 0.03))
    model = dataclasses.replace(
        base, g_squared_dps_per_g2=q, bias_instability_deg_per_h=2.0, rate_random_walk_dps_per_sqrt_s=0.0
    )
    runs = [simulate(model, profile="tumble", rate_hz=2, seed=s).recording for s in range(2)]
    cal = fit_calibration(runs, acceleration="matrix2")
    acc = cal.fit_report["acceleration"]["axes"]
    # |f| = 1 makes zz = 1 - xx - yy: zz is folded into xx, yy and the constant, so compare the effect itself;
    # the model reads the measured specific force, which carries the accelerometer's bias
    f = np.array(tumble_positions())
    a = f + np.asarray(model.accelerometer.bias_g)
    p, pa = g_squared_products(f), g_squared_products(a)
    for i, axis in enumerate(("gyro_x", "gyro_y", "gyro_z")):
        fitted = pa @ np.asarray(acc[axis]["g_squared_dps_per_g2"]) + a @ np.asarray(
            acc[axis]["g_sensitivity_dps_per_g"]
        )
        true = p @ np.asarray(q[i]) + f @ np.asarray(model.g_sensitivity_dps_per_g[i])
        # 13 coefficients from 2 x 27 five-minute positions, each mean good to ~5e-4 deg/s: within 2e-3
        # of an effect of up to 0.1 deg/s
        np.testing.assert_allclose(fitted - fitted.mean(), true - true.mean(), atol=2e-3)
    assert "g x g" in cal.model


def test_rank_deficient_positions_warn_and_leave_the_columns_unfitted():
    # rotations about z only: accel_z never changes, so G's third column cannot be found
    positions = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (-1.0, 0.0, 0.0), (0.0, -1.0, 0.0), (0.7071, 0.7071, 0.0))
    prof = get_profile("tumble", positions_g=positions, position_s=600.0)
    runs = [simulate("consumer", profile=prof, rate_hz=2, seed=s).recording for s in range(2)]
    with pytest.warns(
        DataQualityWarning,
        match=r"the positions do not excite accel_z \(\d[.\de-]* g\): within-run spread below 0.1 g; .*not fitted",
    ):
        cal = fit_calibration(runs, acceleration="matrix")
    for _axis, info in cal.fit_report["acceleration"]["axes"].items():
        assert info["g_sensitivity_dps_per_g"][2] == 0.0 and info["standard_error_dps_per_g"][2] is None
        assert info["standard_error_dps_per_g"][0] is not None
    assert cal.fit_report["acceleration"]["excited_axes"] == ["accel_x", "accel_y"]


def test_acceleration_needs_accelerometer_columns():
    runs = [simulate(preset_model("adxrs450"), profile="tumble", duration_s=2000, rate_hz=1, seed=0).recording]
    with pytest.raises(InputError, match="acceleration: the runs need accel_x, accel_y and accel_z columns"):
        fit_calibration(runs, acceleration="matrix")
    cal = fit_calibration(runs)  # auto: no accelerometer, no g-sensitivity
    assert cal.fit_report["acceleration"]["mode"] == "none"
    with pytest.raises(InputError, match="acceleration: 'cube'; use one of auto, none, matrix, matrix2"):
        fit_calibration(runs, acceleration="cube")


@pytest.fixture(scope="module")
def pipelines(consumer):
    from gyrocomp.models.pipelines import PIPELINES, fit_pipeline

    _, runs, held, joint = consumer
    out = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for name in PIPELINES:
            cal = joint if name == "joint" else fit_pipeline([r.recording for r in runs], name)
            comp = apply(cal, held.recording).gyro_dps
            ratio = [
                smoothed_residual_rms(comp[:, j] - held.truth.true_rate_dps[:, j], 60)
                / smoothed_residual_rms(held.truth.noise.total_dps[:, j], 60)
                for j in range(3)
            ]
            out[name] = (cal, float(np.mean(ratio)))
    return out


@pytest.mark.slow
def test_joint_fit_beats_every_cascade(pipelines):
    # the thesis's point (2.8): fitting temperature and acceleration together keeps the drift during the
    # tumble out of G and the orientation offsets out of the temperature curve
    joint = pipelines["joint"][1]
    assert joint < 1.15
    for name in ("poly>matrix", "matrix>poly", "mlp>matrix", "mlp>mlp-accel", "joint-mlp"):
        assert joint <= pipelines[name][1], name
        assert "stages" in pipelines[name][0].fit_report or name == "joint-mlp"
    # a network of the accelerations learns the six calibration orientations and nothing between them:
    # at the held-out run's +-0.5 g orientations it is far worse than the linear G
    assert pipelines["mlp>mlp-accel"][1] > pipelines["mlp>matrix"][1]


@pytest.mark.slow
def test_a_cascade_applies_as_its_stages_in_turn(consumer, pipelines):
    from gyrocomp.models.joint import fit_calibration

    _, runs, held, _ = consumer
    chained = pipelines["matrix>poly"][0]
    recs = [r.recording for r in runs]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        first = fit_calibration(recs, temperature=None, acceleration="matrix")
        second = fit_calibration([apply(first, r) for r in recs], acceleration="none")
        step = apply(second, apply(first, held.recording)).gyro_dps
        np.testing.assert_allclose(apply(chained, held.recording).gyro_dps, step, rtol=0, atol=1e-12)


@pytest.mark.slow
def test_joint_network_reads_the_accelerations(consumer, pipelines, tmp_path):
    _, _, held, _ = consumer
    cal = pipelines["joint-mlp"][0]
    ax = cal.axes["gyro_x"]
    assert ax.temperature.inputs == ("temperature", "accel_x", "accel_y", "accel_z")
    assert ax.g_sensitivity_dps_per_g is None and ax.needs_accel
    assert cal.model.startswith("joint-mlp: mlp:4-3-1")
    cal.save(tmp_path / "j.json")
    loaded = Calibration.load(tmp_path / "j.json")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        np.testing.assert_array_equal(apply(loaded, held.recording).gyro_dps, apply(cal, held.recording).gyro_dps)
    with pytest.raises(InputError, match="the data needs accel_x, accel_y and accel_z"):
        Compensator(cal, ("gyro_x", "gyro_y", "gyro_z"), rate_hz=1.0).update(
            held.recording.time_s[:5], held.recording.gyro_dps[:5], held.recording.temperature_degc[:5]
        )


def test_unknown_pipeline():
    from gyrocomp.models.pipelines import fit_pipeline

    with pytest.raises(InputError, match=r"pipeline: 'poly>net'; use one of joint, poly>matrix, matrix>poly"):
        fit_pipeline([simulate("mti10", profile="static", duration_s=100, rate_hz=1).recording], "poly>net")


def test_excited_columns_from_the_spread_of_the_positions():
    """Positions that tilt x and y but leave z near 1 g excite two columns; with all three excited the zz
    term is left out of the g x g set (xx + yy + zz = 1 g^2 at rest makes it the run constant)."""
    rng = np.random.default_rng(4)
    tilted = np.column_stack(
        [rng.choice([-0.5, 0.0, 0.5], 200), rng.choice([-0.5, 0.5], 200), 0.95 + 0.01 * rng.standard_normal(200)]
    )
    weights = [np.ones(200), np.ones(200)]
    with pytest.warns(
        DataQualityWarning,
        match=r"the positions do not excite accel_z \(0\.01 g\): within-run spread "
        r"below 0\.1 g",
    ):
        excited, squares, names = excited_columns([tilted, tilted[::-1]], weights, squares=True)
    assert excited == (0, 1) and names == ("accel_x", "accel_y")
    assert [G_SQUARED_TERMS[m] for m in squares] == ["xx", "yy", "xy"]
    tumble = np.vstack([np.eye(3), -np.eye(3)]).repeat(20, axis=0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # every axis excited: no warning
        excited, squares, _ = excited_columns([tumble], [np.ones(len(tumble))], squares=True)
    assert excited == (0, 1, 2) and "zz" not in [G_SQUARED_TERMS[m] for m in squares] and len(squares) == 5


def test_an_accelerometer_drifting_with_temperature_at_one_orientation_is_no_turn():
    """A real one-cycle log's accelerometer moved 0.05 g with the chamber's temperature at one orientation: its still
    segments, split by moments of motion, read as several orientations, and the default fit warned that the
    positions excite no axis. A turn now needs what the g-sensitivity fit needs, a spread beyond 0.1 g."""
    rec = simulate("consumer", profile="chamber", rate_hz=5.0, seed=4).recording
    t = rec.temperature_degc
    accel = rec.accel_g.copy()
    accel[:, 2] += 0.08 * (t - t.min()) / np.ptp(t)
    gyro = rec.gyro_dps.copy()
    every = int(1200 * rec.rate_hz)
    for start in range(every, rec.n_samples, every):  # a moment of motion every 20 min splits the still stretches
        gyro[start : start + 10] += 30.0
    drifting = dataclasses.replace(rec.with_gyro(gyro), accel_g=accel)
    assert not turned_between_positions([drifting], 20.0)
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        calibration = fit([drifting])
    assert not [w for w in said if "do not excite" in str(w.message)]
    assert calibration.fit_report["acceleration"] == {
        "mode": "none",
        "why": "the runs do not turn the unit between positions",
    }
    tumbled = simulate("consumer", profile="tumble", rate_hz=5.0, seed=4).recording
    assert turned_between_positions([tumbled], 20.0)
