"""The data check: every injected fault found with its own reason on simulated runs read from files, clean runs
left alone, refusals and warnings as documented (a named curve refuses what the automatic choice only warns of),
accepted checks reported and never refusing, the noise-density estimate recovering the simulated truth, and the
check at the start of ``gyrocomp check``, ``fit`` and ``fleet fit``."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

from gyrocomp.errors import InputError, TimeOrderWarning
from gyrocomp.fleet import CalibrationStore
from gyrocomp.files.check import ask_for, check_files, enforce, read_checked
from gyrocomp.io.tables import write_recording
from gyrocomp.measures.data_check import MIN_SPAN_DEGC, Ask, CheckedRun, check_runs, time_findings, white_noise_density
from gyrocomp.models.options import FitOptions, Network, Polynomial
from gyrocomp.simulation import preset_model, simulate
from gyrocomp.simulation.faults import FAULTS, inject

from ..conftest import burst_stamped_recording, chamber_run, run

PRESETS = ("adxrs450", "consumer")


@pytest.fixture(scope="module")
def clean_columns(tmp_path_factory) -> dict[str, dict[str, np.ndarray]]:
    """A clean 1 Hz chamber run of each preset, as its table's columns."""
    folder = tmp_path_factory.mktemp("clean")
    out = {}
    for preset in PRESETS:
        path = folder / f"{preset}.parquet"
        write_recording(simulate(preset, profile="chamber", rate_hz=1.0, seed=5).recording, path)
        table = pd.read_parquet(path)
        out[preset] = {c: table[c].to_numpy() for c in table.columns}
    return out


@pytest.mark.parametrize("preset", PRESETS)
def test_every_fault_is_found_with_its_reason_and_clean_runs_are_left_alone(clean_columns, preset, tmp_path):
    columns = clean_columns[preset]
    path = tmp_path / "run.parquet"
    pd.DataFrame(columns).to_parquet(path)
    (clean,) = check_files([path])[1]
    # the consumer part reads its temperature in whole degrees (the preset's temperature_quantization_degc)
    expected_clean = ("temperature-quantized",) if preset_model(preset).temperature_quantization_degc >= 0.25 else ()
    assert clean.reasons == expected_clean, clean.line()
    rng = np.random.default_rng(3)
    for fault, check in FAULTS.items():
        pd.DataFrame(inject(columns, fault, rng)).to_parquet(path)
        ask = Ask(hysteresis=True) if fault == "no-reversal" else Ask()
        (found,) = check_runs([read_checked(path)], ask)
        assert check in found.reasons, (fault, found.line())
        assert found.line().startswith(f"{path}: ") and "\n" not in found.line()


def test_refusals_and_warnings_follow_what_is_asked(clean_columns, tmp_path):
    path = tmp_path / "flat.parquet"
    pd.DataFrame(inject(clean_columns["adxrs450"], "temperature-span", np.random.default_rng(0))).to_parquet(path)
    run_ = read_checked(path)
    (auto,) = check_runs([run_], ask_for())
    assert auto.verdict == "warning" and "the automatic choice fits a constant bias" in auto.line()
    (named,) = check_runs([run_], ask_for(FitOptions(temperature=Polynomial(3))))
    # 0.5 degC holds 6 levels of 0.1 degC, fewer than a cubic's 8
    assert named.verdict == "refused" and named.reasons == ("temperature-span", "too-short")
    (accepted,) = check_runs(
        [run_], ask_for(FitOptions(temperature=Polynomial(3))), accept=["temperature-span", "too-short"]
    )
    assert accepted.verdict == "ok" and [f.check for f in accepted.accepted] == ["temperature-span", "too-short"]
    assert "accepted: temperature-span, too-short" in accepted.line()
    (none,) = check_runs([run_], ask_for(FitOptions(temperature=None)))
    assert none.verdict == "ok"
    with pytest.raises(
        InputError,
        match=r"flat.parquet: the runs span 0.5 degC, less than 1 degC.*refused by the "
        r"data check \(accept=temperature-span fits it anyway\)",
    ):
        enforce([named])
    # a run at one temperature beside a chamber run: the set spans enough, the flat run is fine
    full = tmp_path / "full.parquet"
    pd.DataFrame(clean_columns["adxrs450"]).to_parquet(full)
    both = check_runs([run_, read_checked(full)], ask_for(FitOptions(temperature=Polynomial(3))))
    assert [c.verdict for c in both] == ["ok", "ok"]
    assert ask_for(FitOptions(temperature=Network())).parameters == 10  # 1-3-1: 3 + 3 weights, 3 + 1 biases


def test_the_span_threshold_is_the_documented_one(clean_columns, tmp_path):
    columns = dict(clean_columns["adxrs450"])
    t = columns["temperature"]
    for span, refused in ((0.9 * MIN_SPAN_DEGC, True), (1.1 * MIN_SPAN_DEGC, False)):
        columns["temperature"] = 20.0 + span * (t - t.min()) / np.ptp(t)
        path = tmp_path / "run.parquet"
        pd.DataFrame(columns).to_parquet(path)
        (c,) = check_runs([read_checked(path)], Ask(temperature="asked", parameters=4))
        assert ("temperature-span" in c.reasons) == refused


def test_time_going_back_far_is_refused_and_a_loggers_reordering_said():
    far = TimeOrderWarning("x.ulg: 5 sample(s) out of time order", moved=5, dropped=0, largest_back_s=3600.0)
    near = TimeOrderWarning("x.ulg: 2 sample(s) out of time order", moved=2, dropped=0, largest_back_s=0.004)
    (refusal,) = time_findings("x.ulg", [far], rate_hz=100.0)
    (note,) = time_findings("x.ulg", [near], rate_hz=100.0)
    assert refusal.severity == "refuse" and "goes back by 3600 s" in refusal.message
    assert note.severity == "warn" and note.cost.startswith("none")


def test_the_noise_density_is_recovered_and_the_unit_mistake_is_57_times_off():
    model = preset_model("adis16488")
    rec = simulate(model, profile="chamber", rate_hz=10.0, seed=2, duration_s=3600).recording
    nd = model.noise_density_dps_per_sqrt_hz
    # 1080 windows of 20 differences: the 10th percentile's own spread is a few percent
    assert white_noise_density(rec) == pytest.approx(nd, rel=0.1)
    for factor, words in ((math.pi / 180, "rad/s read as deg/s"), (180 / math.pi, "deg/s read as rad/s")):
        scaled = CheckedRun("r", rec.with_gyro(rec.gyro_dps * factor))
        (c,) = check_runs([scaled], Ask(temperature="none"))
        assert c.reasons == ("unit",) and words in c.line()


@pytest.mark.slow
def test_check_fit_and_fleet_fit_run_the_check(clean_columns, tmp_path):
    good, flat, bare = tmp_path / "good.csv", tmp_path / "flat.csv", tmp_path / "bare.csv"
    pd.DataFrame(clean_columns["adxrs450"]).to_csv(good, index=False)
    pd.DataFrame(inject(clean_columns["adxrs450"], "temperature-span", np.random.default_rng(0))).to_csv(
        flat, index=False
    )
    pd.DataFrame(inject(clean_columns["adxrs450"], "temperature-missing", np.random.default_rng(0))).to_csv(
        bare, index=False
    )
    checked = run("check", good, flat, bare)  # one unit's runs: together they span enough
    assert checked.returncode == 1, checked.stderr
    lines = checked.stdout.splitlines()
    assert lines[:2] == [f"{good}: ok", f"{flat}: ok"] and len(lines) == 3
    assert lines[2].startswith(f"{bare}: refused (temperature-missing)")
    alone = run("check", flat)
    assert alone.returncode == 0 and alone.stdout.startswith(f"{flat}: warning (temperature-span")
    as_json = json.loads(run("check", flat, "--temperature", "poly:3", "--json").stdout)
    assert as_json[0]["verdict"] == "refused" and as_json[0]["findings"][0]["check"] == "temperature-span"
    refused = run("fit", flat, "--temperature", "poly:3", "-o", tmp_path / "m.json")
    assert refused.returncode == 2 and refused.stderr.count("\n") == 1 and not (tmp_path / "m.json").exists()
    assert "--accept temperature-span fits it anyway" in refused.stderr
    accepted = run(
        "fit",
        flat,
        "--temperature",
        "poly:3",
        "--accept",
        "temperature-span",
        "--accept",
        "too-short",
        "-o",
        tmp_path / "m.json",
    )
    assert accepted.returncode == 0, accepted.stderr
    manifest = tmp_path / "units.csv"
    manifest.write_text(f"path,serial\n{good},A\n{bare},B\n")
    fleet = run("fleet", "fit", "--manifest", manifest, "-o", tmp_path / "FLEET", "--scheduler", "serial")
    assert fleet.returncode == 0, fleet.stderr
    with CalibrationStore(tmp_path / "FLEET") as db:
        (b,) = db.history("B")
        assert b.status == "failed" and "no temperature column" in b.error and "data check" in b.error
        assert db.history("A")[0].status == "ok"


def test_a_run_at_one_temperature_is_fine_beside_runs_that_span_enough(clean_columns, tmp_path):
    still, full = tmp_path / "still.parquet", tmp_path / "full.parquet"
    pd.DataFrame(inject(clean_columns["adxrs450"], "temperature-constant", np.random.default_rng(0))).to_parquet(still)
    pd.DataFrame(clean_columns["adxrs450"]).to_parquet(full)
    asked = ask_for(FitOptions(temperature=Polynomial(3)))
    assert [c.verdict for c in check_runs([read_checked(still), read_checked(full)], asked)] == ["ok", "ok"]
    (alone,) = check_runs([read_checked(still)], asked)
    assert alone.verdict == "refused" and alone.reasons[0] == "temperature-constant"
    # on the command line the message reads as written (its "one temperature:" once became "one --temperature:")
    refused = run("fit", still, "--temperature", "poly:3", "-o", tmp_path / "m.json")
    assert (
        refused.returncode == 2 and "runs that all stay at one set point: refused by the data check" in refused.stderr
    )
    assert "--temperature:" not in refused.stderr


def test_gaps_between_bursts_of_stamps_are_not_called_missing_samples():
    """Stamps taken as buffered samples arrived (100 Hz, five at a time, 2 ms apart) leave a gap every five
    samples: the check says the stamps come in bursts and that no sample is missing, not that 80 % are; real
    gaps (a pause) are still counted as missing time."""
    from gyrocomp.measures.data_check import gap_findings

    (finding,) = gap_findings(burst_stamped_recording(100.0, 10_000, 5, 2e-3))
    assert finding.check == "gaps" and finding.message.startswith("b.csv: the time stamps come in bursts")
    assert finding.cost == "no sample missing; what uses the rate (500 Hz from the median step) is 5 times off"
    paused = simulate("consumer", profile="static", duration_s=600.0, rate_hz=10.0, seed=3).recording
    cut = paused.take(np.r_[0:2000, 4000:6001])
    (finding,) = gap_findings(cut)
    assert "1 gap(s), 200 s in all (33 % of the run" in finding.message and finding.cost.startswith("33 % fewer")


def test_a_run_given_twice_copied_or_beside_its_log_is_refused_naming_the_first(clean_columns, tmp_path):
    """The same file twice (a glob that names it again), a copy, or a run split from a log given with the log
    would hold samples out against themselves."""
    one, copy, other = tmp_path / "one.csv", tmp_path / "copy.csv", tmp_path / "other.csv"
    pd.DataFrame(clean_columns["adxrs450"]).to_csv(one, index=False)
    pd.DataFrame(clean_columns["adxrs450"]).to_csv(copy, index=False)
    pd.DataFrame(clean_columns["consumer"]).to_csv(other, index=False)
    _, checks = check_files([one, other, copy, one])
    assert [c.verdict for c in checks[:2]] == ["ok", "warning"]  # the consumer part's whole degrees
    for check, path in zip(checks[2:], (copy, one)):
        assert check.verdict == "refused" and check.reasons == ("repeated",), check.line()
        assert check.line().startswith(f"{path}: refused (repeated): the same samples as {one} (a run given twice)")
    with pytest.raises(InputError, match=r"copy.csv: the same samples as .*one.csv .*accept=repeated fits it anyway"):
        enforce(checks)
    (_, accepted) = check_files([one, copy], accept=["repeated"])[1]
    assert accepted.verdict == "ok" and [f.check for f in accepted.accepted] == ["repeated"]
    shifted = dict(clean_columns["adxrs450"])
    axis = next(c for c in shifted if c.startswith("gyro_"))
    shifted[axis] = shifted[axis].copy()
    shifted[axis][len(shifted[axis]) // 2] += 1e-6  # one sample apart: another run
    pd.DataFrame(shifted).to_csv(copy, index=False)
    assert [c.verdict for c in check_files([one, copy])[1]] == ["ok", "ok"]
    log, part = tmp_path / "log.csv", tmp_path / "part.csv"  # a run split from a log, given beside the log
    pd.DataFrame(clean_columns["adxrs450"]).to_csv(log, index=False)
    pd.DataFrame(clean_columns["adxrs450"]).iloc[100:600].to_csv(part, index=False)
    for first, second, said in (
        (log, part, f"its rows 0..499 are rows 100..599 of {log}, the same samples (a run given twice in part"),
        (part, log, f"its rows 100..599 are rows 0..499 of {part}, the same samples"),
    ):
        checks = check_files([first, second])[1]
        assert checks[0].verdict == "ok" and checks[1].reasons == ("repeated",), checks[1].line()
        assert checks[1].line().startswith(f"{second}: refused (repeated): {said}"), checks[1].line()
    fitted = run("fit", one, one, "-o", tmp_path / "m.json")
    assert fitted.returncode == 2 and fitted.stderr.count("\n") == 1 and not (tmp_path / "m.json").exists()
    assert "the same samples as" in fitted.stderr and "--accept repeated fits it anyway" in fitted.stderr


def test_runs_that_share_one_boundary_sample_are_two_runs(clean_columns, tmp_path):
    """Windows cut at inclusive ends (MATLAB's data(1:1000), data(1000:2000)) share one sample: no repeat."""
    table = pd.DataFrame(clean_columns["adxrs450"])
    first, second = tmp_path / "first.csv", tmp_path / "second.csv"
    table.iloc[:1000].to_csv(first, index=False)
    table.iloc[999:2000].to_csv(second, index=False)
    assert all("repeated" not in c.reasons for c in check_files([first, second])[1])
    table.iloc[998:2000].to_csv(second, index=False)  # two samples: a run given twice in part
    assert check_files([first, second])[1][1].reasons == ("repeated",)


def _physics_run(tmp_path, edit, name="run.csv"):
    """A chamber run written from the physics (conftest.chamber_run, 2 Hz), its columns changed by ``edit``."""
    rec = chamber_run([20, 50, 20], ramp_degc_per_min=2, hold_s=300, rate_hz=2, seed=4)
    table = pd.DataFrame({"time": rec.time_s, "temperature": rec.temperature_degc})
    for j, axis in enumerate(rec.gyro_axes):
        table[axis] = rec.gyro_dps[:, j]
    edit(table)
    path = tmp_path / name
    table.to_csv(path, index=False)
    return path


def _dead(table):
    for axis in ("gyro_x", "gyro_y", "gyro_z"):
        table[axis] = 0.0


def _one_dead(table):
    table["gyro_y"] = 0.0


def _same_column(table):
    table["gyro_y"] = table["gyro_x"]


def _spikes(table):
    table.loc[::100, "temperature"] = -40.0


def _saturated(table):
    table["gyro_z"] = np.clip(table["gyro_z"] + 300.0 * np.sign(np.sin(np.arange(len(table)) / 300.0)), -250, 250)


def _counts(table):
    for axis in ("gyro_x", "gyro_y", "gyro_z"):
        table[axis] = np.round(table[axis] * 131.0 + 40.0)


@pytest.mark.parametrize(
    "edit, check, severity, words",
    [
        (_dead, "gyro-constant", "refused", r"gyro_x \(0 deg/s\), gyro_y \(0 deg/s\), gyro_z \(0 deg/s\): every"),
        (_one_dead, "gyro-constant", "warning", r"gyro_y \(0 deg/s\): every sample the same value"),
        (_same_column, "axes-identical", "warning", r"gyro_x and gyro_y hold the same samples"),
        (_spikes, "temperature-spikes", "warning", r"temperature sample\(s\) jump 2 degC or more .*rows 1, 101, 201"),
        (_saturated, "rail", "warning", r"gyro_z sits at 250 deg/s"),
        (_counts, "counts", "warning", r"every gyro sample is a whole number"),
    ],
)
def test_a_gyro_that_says_nothing_spikes_a_rail_or_counts_is_named_by_check_and_fit(
    tmp_path, edit, check, severity, words
):
    import re

    path = _physics_run(tmp_path, edit)
    checked = run("check", path)
    line = checked.stdout.strip()
    assert line.startswith(f"{path}: {severity} (") and check in line.split(":", 2)[1], line
    (verdict,) = json.loads(run("check", path, "--json").stdout)
    found = next(f for f in verdict["findings"] if f["check"] == check)
    assert re.search(words, found["message"]) and found["message"].startswith(f"{path}: "), found
    fitted = run("fit", path, "-o", tmp_path / "m.json")
    said = fitted.stderr
    if severity == "refused" or check == "counts":  # counts: read as deg/s they move, and nothing is still
        assert fitted.returncode == 2 and re.search(words, said) and not (tmp_path / "m.json").exists(), said
    else:
        assert fitted.returncode == 0 and re.search(words, said), said


def test_a_clean_physics_run_raises_none_of_these_checks(tmp_path):
    checked = run("check", _physics_run(tmp_path, lambda table: None))
    assert checked.returncode == 0 and ": ok" in checked.stdout, checked.stdout
