"""Which runs belong to which unit, the input hash, limits and verdicts, robust outlier scores."""

from __future__ import annotations

import json
import math
import shutil
import warnings

import numpy as np
import pandas as pd
import pytest
from scipy.stats import norm

from gyrocomp.errors import DataQualityWarning, InputError
from gyrocomp.fleet import (
    AxisFigures,
    CalibrationRecord,
    CalibrationStore,
    Limits,
    UnitFigures,
    UnitRuns,
    expand_inputs,
    fleet_table,
    fleet_yield,
    input_hash,
    robust_z,
    units_from_manifest,
    units_from_pattern,
    utc_now,
)
from gyrocomp.fleet.population import MIN_UNITS_FOR_OUTLIERS


def _touch(root, *names):
    for name in names:
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(f"content of {name}")
    return root


def test_units_from_a_path_pattern(tmp_path):
    _touch(tmp_path, "lotA/SN1/run_0.csv", "lotA/SN1/run_1.csv", "lotB/SN2/run_0.csv", "lotA/notes.txt")
    files = expand_inputs([tmp_path])
    assert len(files) == 4  # notes.txt is a possible table too; the pattern leaves it out
    with pytest.warns(DataQualityWarning, match=r"1 file\(s\) do not match '\{lot\}/\{serial\}/run_\{n\}.csv'"):
        units = units_from_pattern(files, "{lot}/{serial}/run_{n}.csv")
    assert [(u.serial, len(u.paths), dict(u.metadata)) for u in units] == [
        ("SN1", 2, {"lot": "lotA"}),
        ("SN2", 1, {"lot": "lotB"}),
    ]
    with pytest.raises(InputError, match=r"unit_pattern: 'run_\{n\}.csv' names no \{serial\} field"):
        units_from_pattern(files, "run_{n}.csv")
    with pytest.raises(InputError, match=r"names \{serial\} twice"):
        units_from_pattern(files, "{serial}/{serial}.csv")
    with pytest.raises(InputError, match=r"matches none of the 4 files"):
        units_from_pattern(files, "{serial}.parquet")


def test_expand_inputs_reads_globs_and_refuses_what_is_not_there(tmp_path):
    _touch(tmp_path, "a/u1_r0.csv", "a/u1_r1.csv", "b/u2_r0.parquet")
    assert len(expand_inputs([str(tmp_path / "*" / "*.csv")])) == 2
    assert len(expand_inputs([tmp_path / "a", tmp_path / "a" / "u1_r0.csv"])) == 2  # each once
    with pytest.raises(InputError, match=r"nothing\*: the pattern matches no file"):
        expand_inputs([str(tmp_path / "nothing*")])
    with pytest.raises(InputError, match=r"missing: no such file or folder"):
        expand_inputs([tmp_path / "missing"])
    (tmp_path / "empty").mkdir()
    with pytest.raises(InputError, match=r"no run file found"):
        expand_inputs([tmp_path / "empty"])


def test_units_from_a_manifest(tmp_path):
    _touch(tmp_path, "r1.csv", "r2.csv", "r3.csv")
    manifest = tmp_path / "manifest.csv"
    manifest.write_text("path,serial,lot\nr1.csv,A7,L1\nr2.csv,A7,L1\nr3.csv,B2,L2\n")
    units = units_from_manifest(manifest)
    assert [(u.serial, [p.rsplit("/", 1)[1] for p in u.paths], u.metadata) for u in units] == [
        ("A7", ["r1.csv", "r2.csv"], {"lot": "L1"}),
        ("B2", ["r3.csv"], {"lot": "L2"}),
    ]
    pd.read_csv(manifest).to_parquet(tmp_path / "manifest.parquet")
    assert units_from_manifest(tmp_path / "manifest.parquet") == units
    manifest.write_text("file,serial\nr1.csv,A7\n")
    with pytest.raises(InputError, match=r"manifest.csv: the manifest has no 'path' column"):
        units_from_manifest(manifest)
    manifest.write_text("path,serial\nr1.csv,A7\nr9.csv,A7\n")
    with pytest.raises(InputError, match=r"manifest.csv: row 3: path r9.csv: no such file"):
        units_from_manifest(manifest)
    manifest.write_text("path,serial\nr1.csv,\n")
    with pytest.raises(InputError, match=r"row 2: empty serial"):
        units_from_manifest(manifest)
    manifest.write_text("path,serial,lot\nr1.csv,A7,L1\nr2.csv,A7,L2\n")
    with pytest.raises(InputError, match=r"unit A7: column 'lot' differs between its runs"):
        units_from_manifest(manifest)
    manifest.write_text("path,serial\nr1.csv,A7\n./r1.csv,A7\n")
    with pytest.raises(InputError, match=r"manifest.csv: row 3: path ./r1.csv is already a run of unit A7"):
        units_from_manifest(manifest)


def test_input_hash_follows_content_and_settings_not_names(tmp_path):
    _touch(tmp_path, "a.csv", "b.csv")
    first = input_hash([tmp_path / "a.csv", tmp_path / "b.csv"], {"pipeline": "joint"})
    shutil.copy(tmp_path / "a.csv", tmp_path / "renamed.csv")
    assert input_hash([tmp_path / "b.csv", tmp_path / "renamed.csv"], {"pipeline": "joint"}) == first
    assert input_hash([tmp_path / "a.csv", tmp_path / "b.csv"], {"pipeline": "poly>matrix"}) != first
    (tmp_path / "b.csv").write_text("changed")
    assert input_hash([tmp_path / "a.csv", tmp_path / "b.csv"], {"pipeline": "joint"}) != first


def _axis(**values) -> AxisFigures:
    base = dict(
        held_out_drift_dps=0.005,
        raw_drift_dps=0.9,
        temperature_sensitivity_dps_per_degc=0.03,
        tempco_1_dps_per_degc=0.03,
        tempco_2_dps_per_degc2=1e-4,
        tempco_3_dps_per_degc3=0.0,
        bias_span_dps=2.8,
        turn_on_bias_dps=0.01,
        turn_on_repeatability_dps=0.05,
        g_sensitivity_dps_per_g=math.nan,
        noise_density_dps_per_sqrt_hz=0.005,
        bias_instability_deg_per_h=15.0,
    )
    return AxisFigures(**{**base, **values})


def _unit(**z_values) -> UnitFigures:
    return UnitFigures({"gyro_x": _axis(), "gyro_y": _axis(), "gyro_z": _axis(**z_values)}, -20.0, 70.0, 3)


LIMITS = """
[noise_density_dps_per_sqrt_hz]
max = 0.01

[temperature_sensitivity_dps_per_degc]
abs_max = 0.05

[gyro_z_held_out_drift_dps]
max = 0.02

[temperature_max_degc]
min = 60
"""


def test_limits_give_verdicts_naming_the_failing_figures():
    limits = Limits.from_mapping(__import__("tomllib").loads(LIMITS), "limits.toml")
    assert limits.check(_unit()).passed
    verdict = limits.check(_unit(temperature_sensitivity_dps_per_degc=-0.06, held_out_drift_dps=0.03))
    assert verdict.label == "fail"
    assert [f.figure for f in verdict.failures] == [
        "gyro_z_temperature_sensitivity_dps_per_degc",
        "gyro_z_held_out_drift_dps",
    ]
    assert "|-0.06| > abs_max 0.05" in verdict.summary()
    hot_range = UnitFigures(_unit().axes, -20.0, 45.0, 3)
    assert limits.check(hot_range).failures[0].reason == "45 < min 60"
    unmeasured = Limits.from_mapping({"g_sensitivity_dps_per_g": {"max": 0.2}})
    assert {f.reason for f in unmeasured.check(_unit()).failures} == {"not measured"}


@pytest.mark.parametrize(
    "text, message",
    [
        ("[noise]\nmax = 1", r"limits.toml: \[noise\]: unknown figure; use one of held_out_drift_dps"),
        ("[noise_density_dps_per_sqrt_hz]\nbelow = 1", r"\[noise_density_dps_per_sqrt_hz\]: unknown bound 'below'"),
        ("[bias_span_dps]\nmin = 2\nmax = 1", r"\[bias_span_dps\]: min 2 is above max 1"),
        ("[bias_span_dps]\nmax = 'big'", r"\[bias_span_dps\]: max = 'big' is not a finite number"),
        ("bias_span_dps = 3", r"\[bias_span_dps\]: give bounds as a table"),
        ("[bias_span_dps\nmax = 1", r"limits.toml: not a TOML file"),
    ],
)
def test_bad_limits_files_are_refused_in_one_line(tmp_path, text, message):
    path = tmp_path / "limits.toml"
    path.write_text(text)
    with pytest.raises(InputError, match=message):
        Limits.load(path)


def test_robust_z_identities():
    z = robust_z(np.array([1.0, 2.0, 3.0, 4.0, 100.0]))
    assert z[2] == 0.0 and z[4] == pytest.approx(0.6745 * 97)  # median 3, MAD 1
    tied = robust_z(np.array([5.0, 5.0, 5.0, 5.0, 9.0]))  # MAD 0: mean absolute deviation 0.8
    assert tied[4] == pytest.approx(4 / (1.253314 * 0.8))
    assert np.array_equal(robust_z(np.array([2.0, 2.0, np.nan])), [0.0, 0.0, np.nan], equal_nan=True)
    # location and scale invariant
    x = np.random.default_rng(1).normal(size=50)
    assert np.allclose(robust_z(3 * x + 7), robust_z(x))


def _records(units: list[UnitFigures]) -> list[CalibrationRecord]:
    return [CalibrationRecord(f"U{i:03d}", utc_now(), "ok", "0" * 64, "0.1.0", figures=f) for i, f in enumerate(units)]


def test_fleet_table_scores_only_a_population():
    n = MIN_UNITS_FOR_OUTLIERS + 10
    spread = norm.ppf((np.arange(n) + 0.5) / n)  # a normal population's quantiles: 3 % spread, no extreme
    units = [_unit(noise_density_dps_per_sqrt_hz=0.005 * (1 + 0.03 * z)) for z in spread]
    units[4] = _unit(noise_density_dps_per_sqrt_hz=0.02)
    units[5] = _unit(noise_density_dps_per_sqrt_hz=0.001)  # quieter than the rest: not suspect
    table = fleet_table(_records(units))
    assert list(table.loc[table["outlier"], "serial"]) == ["U004"]
    assert table.loc[4, "outlier_figures"] == "gyro_z_noise_density_dps_per_sqrt_hz"
    few = fleet_table(_records(units[: MIN_UNITS_FOR_OUTLIERS - 1]))
    assert not few["outlier"].any() and few["outlier_score"].isna().all()
    assert fleet_yield(table).yield_fraction == 1.0


def test_units_given_twice_are_refused(tmp_path):
    from gyrocomp.fleet import fit_fleet

    _touch(tmp_path, "a.csv")
    with pytest.raises(InputError, match=r"units: serial 'X' is given twice"):
        fit_fleet(
            [UnitRuns("X", (str(tmp_path / "a.csv"),)), UnitRuns("X", (str(tmp_path / "a.csv"),))],
            tmp_path / "out",
            scheduler="serial",
        )
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(InputError, match=r"units: no unit to fit"):
            fit_fleet([], tmp_path / "out", scheduler="serial")


@pytest.mark.slow
def test_a_running_dask_cluster_is_used_by_its_address(tmp_path):
    """``scheduler=ADDRESS``: the units go to a cluster someone else started, which stays up after the fleet."""
    from dask.distributed import Client, LocalCluster

    from gyrocomp.fleet import FleetSettings, fit_fleet, fit_unit
    from gyrocomp.io.tables import write_recording
    from gyrocomp.simulation import simulate

    units = []
    for k in range(3):
        path = tmp_path / f"u{k}.parquet"
        write_recording(
            simulate("consumer", profile="chamber", duration_s=600, rate_hz=5, seed=k, unit=k).recording, path
        )
        units.append(UnitRuns(f"U{k}", (str(path),)))
    with LocalCluster(n_workers=1, threads_per_worker=1, dashboard_address=":0") as cluster, Client(cluster) as client:
        summary = fit_fleet(units, tmp_path / "FLEET", scheduler=cluster.scheduler_address)
        assert sorted(summary.fitted) == ["U0", "U1", "U2"]
        assert len(client.scheduler_info()["workers"]) == 1  # still running
    serial = fit_unit(units[1], FleetSettings())
    with CalibrationStore(tmp_path / "FLEET") as db:
        stored = json.loads(db.valid_at("U1").model_json)
    alone = json.loads(serial.model_json)
    for document in (stored, alone):
        document["provenance"].pop("created_utc")
    assert stored == alone
