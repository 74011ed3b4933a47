"""The published schema of model files (gyrocomp/calibration/model.schema.json): the shipped file is the one the
builder makes, model files of every kind gyrocomp writes validate against it with an independent use of the
``jsonschema`` package, and what it refuses is refused on load naming the field; files of schema 5 upgrade, then
validate, and apply as their schema-6 copy does; every declared field is used or refused (units, temperature
column); a damaged fit report is refused on load, so that show never meets it."""

import json
import warnings
from importlib import resources
from pathlib import Path

import jsonschema
import numpy as np
import pytest

from gyrocomp import Calibration, FitOptions, Network, apply, fit
from gyrocomp.calibration import SCHEMA_VERSION
from gyrocomp.calibration.schema import SCHEMA_FILE, build_schema
from gyrocomp.errors import InputError
from gyrocomp.models.pipelines import fit_pipeline
from gyrocomp.recording import Recording
from gyrocomp.simulation import get_profile, simulate

from ..conftest import run


def _published() -> dict:
    return json.loads(resources.files("gyrocomp.calibration").joinpath(SCHEMA_FILE).read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def runs():
    return [
        simulate(
            "consumer", profile=get_profile("combined", set_points_degc=(-10, 50)), rate_hz=0.5, duration_s=5400, seed=s
        ).recording
        for s in range(3)
    ]


@pytest.fixture(scope="module")
def default_model(runs):
    """The default fit's model (polynomial, lag, memory, g-sensitivity), for the quick checks."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fit(runs)


@pytest.fixture(scope="module")
def models(runs, default_model):
    """A model of every kind the fitter writes: polynomial and lag, network, gyro and accelerometer, g x g terms,
    an acceleration network, turning-point hysteresis and table, heating/cooling branches, a bank of plays, a
    rate-table triad."""
    adx = [
        simulate("adxrs450", profile=get_profile("cycle", set_points_degc=sp, cycles=1), rate_hz=1.0, seed=s).recording
        for s, sp in ((0, (-30, 85)), (1, (-20, 80)))
    ]
    table = [simulate("mti10", profile="ratetable", rate_hz=20.0, seed=s).recording for s in range(2)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return {
            "default": default_model,
            "network": fit(runs, FitOptions(temperature=Network())),
            "gyro and accel": fit(runs, channels=("gyro", "accel")),
            "g x g": fit(runs, FitOptions(acceleration="matrix2")),
            "acceleration network": fit_pipeline(runs, "mlp>mlp-accel"),
            "turning-point": fit(adx),
            "branches": fit(adx, FitOptions(hysteresis="branch")),
            "turning-point table": fit(adx, FitOptions(hysteresis="turning-table")),
            "bank of plays": fit(adx, FitOptions(hysteresis="play-bank")),
            "triad": fit(table + runs[:1]),
        }


def test_the_shipped_schema_is_the_builders():
    assert _published() == json.loads(json.dumps(build_schema(SCHEMA_VERSION))), (
        "the shipped model.schema.json is stale: run python tools/model_schema.py"
    )


@pytest.mark.slow
def test_every_kind_of_model_gyrocomp_writes_validates(models, tmp_path):
    validator = jsonschema.Draft202012Validator(_published())
    kinds = {"polynomial": 0, "mlp": 0, "turning-point": 0, "turning-table": 0, "branch": 0, "play-bank": 0}
    for name, cal in models.items():
        cal.save(tmp_path / "m.json")
        document = json.loads((tmp_path / "m.json").read_text())
        errors = list(validator.iter_errors(document))
        assert not errors, (name, errors[0].message, list(errors[0].absolute_path))
        for ax in document["axes"].values():
            for curve in (ax["temperature"], ax["hysteresis"]):
                if curve is not None:
                    kinds[curve["type"]] = kinds.get(curve["type"], 0) + 1
    assert all(count > 0 for count in kinds.values()), kinds  # the schema's every kind met
    accel = models["gyro and accel"]
    assert models["triad"].gyro_triad is not None and (accel.accel_axes or accel.accel_triad is not None)


def _refusal(cal, change) -> str:
    document = json.loads(cal.to_json())
    change(document)
    with pytest.raises(InputError) as caught:
        Calibration.from_dict(document, "m.json")
    return str(caught.value)


@pytest.mark.parametrize(
    "change, message",
    [
        # what the deeper sweep found accepted (issue: nothing silently wrong, at depth)
        (
            lambda d: d["axes"]["gyro_x"]["temperature"].__setitem__("coefficients_dps", [True, False, True]),
            "m.json: axes.gyro_x.temperature.coefficients_dps[0]: True is not of type 'number'",
        ),
        (
            lambda d: d["axes"]["gyro_x"]["temperature"].__setitem__("t_scale_degc", 0),
            "m.json: axes.gyro_x.temperature.t_scale_degc: 0 is less than the minimum of 0.01",
        ),
        (
            lambda d: d["axes"]["gyro_x"]["temperature"].__setitem__("t_scale_degc", 1e-300),
            "m.json: axes.gyro_x.temperature.t_scale_degc: 1e-300 is less than the minimum of 0.01",
        ),
        (lambda d: d["units"].__setitem__("gyro", "rad/s"), "m.json: units.gyro: 'deg/s' was expected"),
        (
            lambda d: d["axes"]["gyro_x"].__setitem__("comment", "hi"),
            "m.json: axes.gyro_x: Additional properties are not allowed ('comment' was unexpected)",
        ),
        (
            lambda d: d.__setitem__("temperature_unit", "degF"),
            "m.json: Additional properties are not allowed ('temperature_unit' was unexpected)",
        ),
        (
            lambda d: d["axes"]["gyro_x"].__setitem__("lag_time_constant_s", "30"),
            "m.json: axes.gyro_x.lag_time_constant_s: '30' is not of type 'number'",
        ),
        (
            lambda d: d["axes"]["gyro_x"].__setitem__("temperature_column", "temp"),
            "m.json: axes.gyro_x.temperature_column: 'temp' is not one of ['temperature', 'temperature_x'",
        ),
    ],
)
def test_what_the_schema_refuses_is_refused_naming_the_field(default_model, change, message):
    assert _refusal(default_model, change).startswith(message)


@pytest.mark.slow
def test_the_other_kinds_fields_are_checked_too(models):
    network = models["network"]
    assert (
        _refusal(network, lambda d: d["axes"]["gyro_x"]["temperature"].__setitem__("activation", "relu"))
        == "m.json: axes.gyro_x.temperature.activation: 'tanh' was expected"
    )
    triad = models["triad"]
    assert (
        _refusal(triad, lambda d: d["gyro_triad"]["sensitivity"][0].__setitem__(0, "1.5"))
        == "m.json: gyro_triad.sensitivity[0][0]: '1.5' is not of type 'number'"
    )
    assert (
        _refusal(triad, lambda d: d["gyro_triad"]["sensitivity"][1].__setitem__(1, 1e300))
        == "m.json: gyro_triad.sensitivity[1][1]: 1e+300 is greater than the maximum of 10.0"
    )
    branches = models["branches"]
    axis = next(a for a, ax in branches.axes.items() if ax.hysteresis is not None)
    assert (
        _refusal(branches, lambda d: d["axes"][axis]["hysteresis"].__setitem__("transition_degc", 0))
        == f"m.json: axes.{axis}.hysteresis.transition_degc: 0 is less than or equal to the minimum of 0.0"
    )


def test_duplicate_keys_and_non_json_numbers_are_refused_in_the_file(default_model, tmp_path):
    text = default_model.to_json()
    twice = text.replace('"lag_time_constant_s"', '"lag_time_constant_s": 0.0, "lag_time_constant_s"', 1)
    (tmp_path / "m.json").write_text(twice)
    with pytest.raises(InputError, match=r"m\.json: the key 'lag_time_constant_s' appears twice in one object"):
        Calibration.load(tmp_path / "m.json")
    # NaN compares false with any bound: named with its field, in the fit report too (show formats it)
    document = json.loads(text)
    document["fit_report"]["selection"]["gyro_x"]["window_s"] = float("nan")
    (tmp_path / "m.json").write_text(json.dumps(document))
    with pytest.raises(InputError, match=r"m\.json: fit_report\.selection\.gyro_x\.window_s: nan is not a finite"):
        Calibration.load(tmp_path / "m.json")


@pytest.mark.slow
def test_an_edited_schema_version_is_refused_not_upgraded_into_other_numbers(models):
    """A file of the current schema whose schema_version was set back: the upgrades would put a lag of 0 and no
    hysteresis over the file's own (before: applied with other numbers, without a word)."""
    for version, field in ((1, "lag_time_constant_s"), (2, "g_sensitivity_dps_per_g"), (5, "gyro_triad")):
        message = _refusal(models["default"], lambda d, version=version: d.__setitem__("schema_version", version))
        assert message.startswith(f"m.json: schema_version {version}: the file holds ")
        assert field in message and "changed by hand?" in message


def test_schema_5_upgrades_then_validates_and_applies_as_its_schema_6_copy(tmp_path):
    folder = Path(__file__).parent / "data" / "schema5"
    old = Calibration.load(folder / "model.json")
    old.save(tmp_path / "six.json")
    six = json.loads((tmp_path / "six.json").read_text())
    assert six["schema_version"] == SCHEMA_VERSION
    assert not list(jsonschema.Draft202012Validator(_published()).iter_errors(six))
    new = Calibration.load(tmp_path / "six.json")
    rec = simulate(new.axes and "mti10", profile="cycle", duration_s=1800, rate_hz=1.0, seed=3).recording
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        np.testing.assert_allclose(apply(new, rec).gyro_dps, apply(old, rec).gyro_dps, rtol=0, atol=1e-9)


@pytest.mark.slow
def test_the_temperature_column_a_model_names_is_the_one_it_reads(models):
    """A model fitted on one temperature per axis (temperature_x ...) is not applied to data with one shared
    column without a word, nor a shared-temperature model to data with one per axis: the column the model names
    is honoured (before: it was never read, and the data's column was used whatever it was)."""
    cal = models["default"]
    per_axis = Calibration.from_dict(
        {
            **cal.to_dict(),
            "axes": {
                a: {**ax, "temperature_column": f"temperature_{a[-1]}"} for a, ax in cal.to_dict()["axes"].items()
            },
        }
    )
    rec = simulate("consumer", profile="cycle", duration_s=1200, rate_hz=1.0, seed=9).recording
    with pytest.raises(
        InputError,
        match=r"the model of gyro_x reads 'temperature_x' \(one temperature per axis\); "
        r"the data has one temperature column",
    ):
        apply(per_axis, rec)
    three = Recording(
        time_s=rec.time_s,
        gyro_dps=rec.gyro_dps,
        gyro_axes=rec.gyro_axes,
        temperature_degc=np.column_stack([rec.temperature_degc + d for d in (0.0, 1.0, 2.0)]),
        accel_g=rec.accel_g,
        accel_axes=rec.accel_axes,
        source="three",
    )
    with pytest.raises(
        InputError,
        match=r"three: the model of gyro_x reads one temperature column \('temperature'\); "
        r"the data has one per axis",
    ):
        apply(cal, three)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        out = apply(per_axis, three).gyro_dps
        shifted = apply(
            cal,
            Recording(
                time_s=rec.time_s,
                gyro_dps=rec.gyro_dps,
                gyro_axes=rec.gyro_axes,
                temperature_degc=rec.temperature_degc + 2.0,
                accel_g=rec.accel_g,
                accel_axes=rec.accel_axes,
            ),
        ).gyro_dps
    np.testing.assert_allclose(out[:, 2], shifted[:, 2], rtol=0, atol=1e-12)  # gyro_z read temperature_z


@pytest.mark.parametrize(
    "report, refusal",
    [
        (None, "fit_report: None is not of type 'object'"),
        ({"selection": {"gyro_x": None}}, "fit_report: malformed (AttributeError"),
        ({"axes": {"gyro_x": {"scores": 5}}}, "fit_report: malformed (AttributeError"),
        ({"selection": {"gyro_x": {"axis": "gyro_x"}}}, "fit_report: malformed (KeyError: 'fold_kind')"),
        ({}, None),  # an empty report: a model without its account, shown as such
    ],
)
def test_a_damaged_fit_report_is_refused_on_load_and_show_never_meets_it(default_model, tmp_path, report, refusal):
    """Nulls and wrong shapes in the fit report gave show internal errors; now the model file is refused in one
    line (exit 2) naming the report."""
    document = json.loads(default_model.to_json())
    document["fit_report"] = report
    (tmp_path / "m.json").write_text(json.dumps(document))
    done = run("show", tmp_path / "m.json")
    if refusal is None:
        assert done.returncode == 0, done.stderr
        return
    assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1, done.stderr
    assert done.stderr.startswith(f"gyrocomp: error: {tmp_path / 'm.json'}: {refusal}")


@pytest.mark.slow
def test_a_networks_ranges_and_the_provenance_are_what_the_loader_needs(models):
    """An MLP's input_min, input_max and reference hold one value per input, refused by the schema otherwise
    (apply met them with matmul and index errors); a temperature range that is no range is refused on load (the
    network would read no temperature); provenance.inputs is a list of files (show met null with a TypeError)."""
    accel = models["acceleration network"]
    axis, key = next(
        (a, k)
        for a, ax in accel.to_dict()["axes"].items()
        for k in ("temperature", "acceleration_network")
        if isinstance(ax.get(k), dict) and len(ax[k].get("inputs", ())) > 1
    )
    inputs = len(accel.to_dict()["axes"][axis][key]["inputs"])
    for field in ("input_min", "input_max", "reference"):
        for edit in (lambda v: v[:-1], lambda v: v + [0.0], lambda v: []):
            value = edit(accel.to_dict()["axes"][axis][key][field])

            def change(d, field=field, value=value):
                d["axes"][axis][key][field] = value

            message = _refusal(accel, change)
            assert message.startswith(f"m.json: axes.{axis}.{key}.{field}: "), message
    assert inputs > 1
    network = models["network"]
    assert _refusal(
        network,
        lambda d: d["axes"]["gyro_x"]["temperature"].__setitem__(
            "input_max", list(d["axes"]["gyro_x"]["temperature"]["input_min"])
        ),
    ).endswith("is no range; the network would read no temperature")
    assert _refusal(models["default"], lambda d: d["provenance"].__setitem__("inputs", None)).startswith(
        "m.json: provenance.inputs: None is not of type 'array'"
    )
