"""`gyrocomp evaluate`, run through the real entry point in a subprocess."""

import json
import re

import pytest

from ..conftest import run


def test_evaluate_json_shape(workdir):
    r = run("evaluate", workdir / "model.json", workdir / "run3.csv", "--json")
    assert r.returncode == 0, r.stderr
    data = json.loads(r.stdout)
    # model.json's order was asked for (poly:3): the selection still scored it on held-out folds and says so
    assert set(data) == {"runs", "expected_held_out_drift", "in_sample_files", "partly_in_sample_files"}
    assert data["in_sample_files"] == data["partly_in_sample_files"] == []  # run3 is not one of the model's inputs
    run0 = data["runs"][0]
    assert set(run0) == {"file", "window_s", "axes"}
    assert run0["window_s"] >= 1.0
    keys = {
        "bias_offset_raw_dps",
        "bias_offset_comp_dps",
        "offset_improvement",
        "bias_instability_raw_dph",
        "bias_instability_comp_dph",
        "integration_time_raw_s",
        "integration_time_comp_s",
        "residual_rms_dps",
    }
    for axis in ("gyro_x", "gyro_y", "gyro_z"):
        assert set(run0["axes"][axis]) == keys
        assert run0["axes"][axis]["offset_improvement"] > 1


def test_evaluate_table_and_window(workdir):
    r = run("evaluate", workdir / "model.json", workdir / "run3.csv", "--window", 20)
    assert r.returncode == 0, r.stderr
    assert "offset raw" in r.stdout and "[deg/s]" in r.stdout and "run3.csv" in r.stdout
    assert re.search(r"run3\.csv\s*\S\s*gyro_x\s*\S\s*20\s", r.stdout)  # the window column shows --window


@pytest.mark.slow
def test_evaluate_and_report_say_when_they_judge_the_data_the_model_was_fitted_on(workdir, tmp_path):
    """run1 is one of the model's inputs (its name and SHA-256 in the provenance), run3 is not: the figures on run1
    are said to be in-sample, on stderr, in the JSON and in the report; a copy of run3 renamed run1 is not taken
    for it (its digest differs)."""
    done = run("evaluate", workdir / "model.json", workdir / "run1.csv", workdir / "run3.csv", "--json")
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["in_sample_files"] == [str(workdir / "run1.csv")]
    said = f"{workdir / 'run1.csv'}: the model was fitted on these rows of the file, so its figures are in-sample"
    assert said in done.stderr
    assert "run3.csv: the model was fitted" not in done.stderr
    impostor = tmp_path / "run1.csv"
    impostor.write_bytes((workdir / "run3.csv").read_bytes())
    done = run("evaluate", workdir / "model.json", impostor, "--json")
    assert json.loads(done.stdout)["in_sample_files"] == [] and "in-sample" not in done.stderr
    page = tmp_path / "r.html"
    done = run("report", workdir / "model.json", workdir / "run1.csv", "-o", page)
    assert done.returncode == 0, done.stderr
    assert "<b>In-sample</b>: the model was fitted on these rows of run1.csv" in page.read_text()


def test_a_model_fitted_on_part_of_a_file_calls_only_those_rows_in_sample(workdir, tmp_path):
    """fit --time :X: the rows after X are held out (not in-sample), those before it in-sample, a window across X
    partly; in evaluate's note and JSON and in the report."""
    log, model = workdir / "run1.csv", tmp_path / "m.json"
    assert run("fit", log, "--time", ":600", "-o", model).returncode == 0
    cases = {"600:": ([], []), ":600": ([str(log)], []), "100:300": ([str(log)], []), "300:900": ([], [str(log)])}
    for window, (whole, part) in cases.items():
        done = run("evaluate", model, log, "--time", window, "--json")
        assert done.returncode == 0, done.stderr
        data = json.loads(done.stdout)
        assert (data["in_sample_files"], data["partly_in_sample_files"]) == (whole, part), window
        assert ("so its figures are in-sample" in done.stderr) == bool(whole), (window, done.stderr)
        assert ("partly in-sample" in done.stderr) == bool(part), (window, done.stderr)
    page = tmp_path / "r.html"
    assert run("report", model, log, "--time", "600:", "-o", page).returncode == 0
    assert "In-sample</b>" not in page.read_text() and "Partly in-sample" not in page.read_text()
    assert run("report", model, log, "--time", ":600", "-o", page).returncode == 0
    assert "<b>In-sample</b>: the model was fitted on these rows of run1.csv" in page.read_text()
