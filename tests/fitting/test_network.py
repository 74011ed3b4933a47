"""The Levenberg-Marquardt network: its Jacobian, its training, and the network temperature model."""

import json
import warnings

import numpy as np
import pytest

from gyrocomp import Calibration, Network, Polynomial, apply, fit_calibration
from gyrocomp.errors import InputError, ModelError, NotFittedError
from gyrocomp.measures.merit import smoothed_residual_rms
from gyrocomp.curves.network import NetworkCurve, forward, layer_shapes
from gyrocomp.fitting.network_model import NetworkTemperatureModel, jacobian, nguyen_widrow, train_lm, validation_mask
from gyrocomp.cli.common import parse_hidden, parse_temperature_option
from gyrocomp.simulation import GyroErrorModel, get_profile, preset_model, simulate


@pytest.mark.parametrize("hidden", [(3,), (4, 2)])
def test_jacobian_matches_finite_differences(hidden):
    rng = np.random.default_rng(1)
    shapes = layer_shapes(2, hidden)
    theta = nguyen_widrow(shapes, rng)
    x = rng.uniform(-1, 1, (7, 2))
    _, acts = forward(theta, shapes, x)
    jac = jacobian(theta, shapes, acts)
    h = 1e-6
    numeric = np.column_stack(
        [
            (forward(theta + h * e, shapes, x)[0] - forward(theta - h * e, shapes, x)[0]) / (2 * h)
            for e in np.eye(theta.size)
        ]
    )
    np.testing.assert_allclose(jac, numeric, atol=1e-8)


def test_lm_recovers_a_network_it_could_represent():
    rng = np.random.default_rng(2)
    shapes = layer_shapes(1, (3,))
    truth = nguyen_widrow(shapes, rng) * 1.5
    x = np.linspace(-1, 1, 400)[:, None]
    y, _ = forward(truth, shapes, x)
    run = np.zeros(400, dtype=int)
    fits = [
        train_lm(x, y, np.ones(400), run, 1, np.ones(400, dtype=bool), shapes, np.random.default_rng([0, k]))
        for k in range(5)
    ]
    best = min(fits, key=lambda r: r.train_rmse)
    assert best.train_rmse < 1e-6 * np.std(y)


def test_validation_segments_are_spread_and_the_same_every_time():
    run = np.repeat([0, 1], 1000)
    train = validation_mask(run, 2)
    assert (~train).sum() == 400
    assert train[:100].all()  # never the first segment of a run (the turn-on transient stays in training)
    np.testing.assert_array_equal(train, validation_mask(run, 2))


@pytest.fixture(scope="module")
def chamber():
    """A cubic truth: four 1-hour chamber runs to fit on, one cycle held out (10 Hz)."""
    model = GyroErrorModel(
        axes=("gyro_z",),
        temperature_coefficients=((2e-3, 3e-5, -4e-7),),
        bias_instability_deg_per_h=2.0,
        accelerometer=None,
    )
    runs = [simulate(model, profile="chamber", duration_s=3600, rate_hz=10, seed=s).recording for s in range(4)]
    held = simulate(model, profile="cycle", duration_s=3600, rate_hz=10, seed=40)
    return runs, held


def test_network_reproduces_a_polynomial_truth_as_well_as_the_polynomial(chamber):
    runs, held = chamber
    w = 600  # 60 s moving average
    drift, left = {}, {}
    for option, model in (("auto", Polynomial()), ("mlp", Network())):
        cal = fit_calibration(runs, temperature=model)
        comp = apply(cal, held.recording).gyro_dps[:, 0]
        drift[option] = smoothed_residual_rms(comp, w)
        left[option] = smoothed_residual_rms(comp - held.truth.noise.total_dps[:, 0], w)
    assert drift["mlp"] == pytest.approx(drift["auto"], rel=0.1)
    # what each leaves of the truth: both far below the noise's own drift, the network within 2x the polynomial
    noise = smoothed_residual_rms(held.truth.noise.total_dps[:, 0], w)
    assert left["mlp"] < 2 * left["auto"] and left["mlp"] < 0.5 * noise


def test_network_is_deterministic_for_a_seed_and_saved_as_json(chamber, tmp_path):
    runs, held = chamber
    a = fit_calibration(runs, temperature=Network((3,), seed=7))
    b = fit_calibration(runs, temperature=Network((3,), seed=7))
    assert a.axes == b.axes
    a.save(tmp_path / "m.json")
    d = json.loads((tmp_path / "m.json").read_text())
    t = d["axes"]["gyro_z"]["temperature"]
    assert t["type"] == "mlp" and t["hidden"] == [3] and [len(v) for v in t["weights"]] == [6, 4]
    assert len(d["fit_report"]["network"]["axes"]["gyro_z"]["validation_rmse_dps"]) == 5
    loaded = Calibration.load(tmp_path / "m.json")
    np.testing.assert_array_equal(apply(loaded, held.recording).gyro_dps, apply(a, held.recording).gyro_dps)
    curve = loaded.axes["gyro_z"].temperature
    assert curve.shape(np.array([curve.t_ref_degc]))[0] == pytest.approx(0.0, abs=1e-15)


@pytest.mark.slow
def test_network_with_lag_and_hysteresis_generalizes_to_a_faster_ramp():
    rng_c = (-30.0, 80.0)
    model = preset_model("adxrs450")
    runs = [
        simulate(model, profile=get_profile("cycle", set_points_degc=rng_c, cycles=1), rate_hz=1.0, seed=s)
        for s in range(3)
    ]
    held = simulate(
        model,
        profile=get_profile("cycle", set_points_degc=rng_c, cycles=1, ramp_rate_degc_per_min=3.0),
        rate_hz=1.0,
        seed=50,
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_calibration([r.recording for r in runs], temperature=Network(), hysteresis_band_degc=(55.0, 80.0))
        comp = apply(cal, held.recording).gyro_dps[:, 0]
    assert cal.model == "mlp:1-3-1 + turning-point+lag"
    perfect = smoothed_residual_rms(held.truth.noise.total_dps[:, 0], 60)
    assert smoothed_residual_rms(comp - held.truth.true_rate_dps[:, 0], 60) < 1.35 * perfect


def test_network_options_and_errors():
    assert parse_hidden("mlp") == (3,) and parse_hidden("mlp:5") == (5,) and parse_hidden("mlp:4x2") == (4, 2)
    assert parse_temperature_option("mlp:5") == Network((5,)) and parse_temperature_option("mlp", 4) == Network(seed=4)
    for bad in ("mlp:0", "mlp:x", "mlp:2x2x2x2"):
        with pytest.raises(InputError, match=r"--temperature: .*use mlp, mlp:H \(H hidden tanh neurons, 1..50\)"):
            parse_hidden(bad)
    with pytest.raises(InputError, match=r"--temperature: 'net': use auto, poly, poly:N, .*mlp, mlp:H or none"):
        parse_temperature_option("net")
    with pytest.raises(InputError, match="mlp weights do not fit a 1-3-1 network"):
        NetworkCurve.from_dict(
            {
                "type": "mlp",
                "hidden": [3],
                "weights": [[0.0] * 6, [0.0] * 3],
                "output_mean_dps": 0,
                "output_scale_dps": 1,
                "t_ref_degc": 25,
                "t_min_degc": 0,
                "t_max_degc": 50,
            }
        )
    model = NetworkTemperatureModel()
    with pytest.raises(
        NotFittedError,
        match=r"NetworkTemperatureModel is not fitted yet; call fit_blocks\(axis, ...\) "
        r"first \(curves_ is learned by the fit\)",
    ):
        _ = model.curves_
    assert not hasattr(model, "epochs_")  # hasattr reads a NotFittedError as absent
    flat = [np.full(100, 25.0)]
    with pytest.raises(ModelError, match="gyro_z: the temperature does not vary"):
        model.fit_blocks("gyro_z", flat, [np.zeros(100)], [np.ones(100)], 25.0)
    short = [np.linspace(0, 10, 8)]
    with pytest.raises(ModelError, match="gyro_z: 8 training points for 10 parameters"):
        model.fit_blocks("gyro_z", short, [np.zeros(8)], [np.ones(8)], 5.0)
