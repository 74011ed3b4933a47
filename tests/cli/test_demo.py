"""`gyrocomp demo`, run through the real entry point in a subprocess."""

import json
import re
import sys

import numpy as np
import pytest

from ..conftest import browser, run


@pytest.mark.slow
def test_demo(tmp_path):
    r = run("demo", "-o", tmp_path / "demo")
    assert r.returncode == 0, r.stderr
    names = {p.name for p in (tmp_path / "demo").iterdir()}
    assert {
        "model.json",
        "heldout_compensated.csv",
        "metrics.json",
        "heldout_run.csv",
        "effects.json",
        "heldout_truth.json",
    } <= names
    metrics = json.loads((tmp_path / "demo" / "metrics.json").read_text())
    assert all(a["offset_improvement"] > 1.0 for a in metrics["runs"][0]["axes"].values())
    assert "held-out run, raw vs compensated" in r.stdout
    # the preset's three effects are shown; what the compensation leaves is less than the temperature drift
    effects = json.loads((tmp_path / "demo" / "effects.json").read_text())
    sizes = effects["effects_peak_to_peak_dps"]
    assert set(sizes) == {"temperature (with thermal lag)", "hysteresis", "g-sensitivity"}
    for axis, left in effects["residual_peak_to_peak_dps"].items():
        assert left < sizes["temperature (with thermal lag)"][axis]
        assert sizes["hysteresis"][axis] > 0.001 and sizes["g-sensitivity"][axis] > 0.0005
    assert "hysteresis" in r.stdout and "g-sensitivity" in r.stdout
    # every compensation leaves less deterministic error than raw on every axis
    left = effects["deterministic_error_left_rms_dps_by_method"]
    assert list(left)[0] == "raw (no compensation)" and list(left)[1].startswith("gyrocomp: ")
    assert all(axes[a] < left["raw (no compensation)"][a] for axes in list(left.values())[1:] for a in axes)
    # the validation table of the calibration runs: every method, by leave-one-run-out; averaged over the axes,
    # the default is no worse than the plain cubic by more than the standard error of the cubic's folds (this
    # part's drift is mostly noise: the table shows the default and the cubic within it of each other)
    validation = json.loads((tmp_path / "demo" / "validation.json").read_text())
    assert validation["fold_kind"] == "runs" and len(validation["folds"]) == 3
    assert "held-out drift [deg/s]" in r.stdout and "gyrocomp default" in r.stdout and "PX4 cubic" in r.stdout
    by = {(s["method"], s["axis"]): s for s in validation["scores"]}
    axes = ("gyro_x", "gyro_y", "gyro_z")
    mean = {
        m: np.mean([by[(m, a)][k] for a in axes])
        for m in ("gyrocomp default", "cubic + run constants")
        for k in ("mean_drift_dps",)
    }
    cubic_se = np.mean([by[("cubic + run constants", a)]["standard_error_dps"] for a in axes])
    assert mean["gyrocomp default"] <= mean["cubic + run constants"] + cubic_se
    assert all(by[("gyrocomp default", a)]["mean_drift_dps"] < by[("raw", a)]["mean_drift_dps"] for a in axes)
    # temperature drift makes the raw Allan deviation rise at long averaging times; compensated, it stays near
    # what the sensor's noise alone gives (within the scatter of a few independent averages)
    allan = json.loads((tmp_path / "demo" / "allan.json").read_text())
    assert "Allan deviation of the held-out run" in r.stdout
    for c in allan.values():
        raw, comp, noise = (np.array(c[k]) for k in ("raw_deg_per_h", "compensated_deg_per_h", "noise_alone_deg_per_h"))
        assert c["tau_s"][-1] >= 2000 and raw[-1] > 2.0 * noise[-1] and raw[-1] > 1.5 * comp[-1]
        assert comp[-1] < 1.5 * noise[-1]
        np.testing.assert_allclose(comp[0], noise[0], rtol=0.01)  # at 1 s it is the white noise, untouched
    assert "ArduPilot cubic (tempcal_IMU.py)" in r.stdout
    assert re.search(r"g-sensitivity .*\(compensated: 3x3 G fitted jointly\)", r.stdout)
    truth = json.loads((tmp_path / "demo" / "heldout_truth.json").read_text())
    assert truth["preset"] == "mti10" and truth["profile"]["name"] == "cycle"
    assert "warning" not in r.stderr
    report = (tmp_path / "demo" / "report.html").read_text()
    assert report.startswith("<!DOCTYPE html>") and "heldout_run.csv" in report and "data:image/png;base64," in report
    assert "report.html (open it in a browser)" in r.stdout
    # the page opens with what this model bought on its own held-out run (raw, gyrocomp and the cubics), then the
    # case where compensation matters, its factor against PX4's cubic read from the page itself, every ratio
    # written the same way round ("N x less drift than ...")
    first = report[report.index("<section") :]
    assert first.startswith('<section id="this-model"><h2>This model on its held-out run</h2>')
    case = report[report.index('<section id="case">') :]
    assert case.startswith('<section id="case"><h2>Another part, where compensation matters: the consumer</h2>')
    opening = re.search(r"gyrocomp's default leaves <b>([0-9.]+)x less drift than PX4 cubic", case)
    assert opening and float(opening.group(1)) >= 5.0, case[:400]  # measured 12.1x
    # the g-sensitivity of a held-out run at one attitude is not drawn as panels of one point each
    assert "hold their static positions at one attitude" in report
    assert not re.search(r"\d\.\d+x (?!less drift than|more drift than)", report[: report.index('id="summary"')])
    # the case where gyrocomp's models matter, against the simulator's truth, and the one where they do not
    cases = json.loads((tmp_path / "demo" / "cases.json").read_text())
    matters, not_matters = cases
    assert matters["part"].startswith("consumer") and not_matters["part"].startswith("mti10")
    assert all(f > 2.0 for f in matters["gyrocomp_factor_vs"].values())  # measured 11-12x
    assert all(0.5 < f < 2.0 for f in not_matters["gyrocomp_factor_vs"].values())  # as good as a cubic
    for case in cases:
        assert case["drift_dps"]["gyrocomp"] < case["drift_dps"]["raw"]
    assert "Where gyrocomp's models matter" in r.stdout and "Where they do not" in r.stdout
    assert (
        f"{matters['gyrocomp_factor_vs']['PX4 cubic (process_sensor_caldata.py)']:.1f}x less drift than PX4 cubic"
        in r.stdout
    )
    assert "case_consumer.png" in names
    if browser.chromium() is not None:  # the first screen, as a browser lays the page out
        seen = browser.open_page(tmp_path / "demo" / "report.html")
        shown = seen.on_first_screen()
        tables = [e for e in shown if e["tag"] == "TABLE" and e["section"] == "this-model"]
        assert tables, seen.layout[:4]
        drift = tables[0]["text"]
        assert all(name in drift for name in ("raw", "gyrocomp", "PX4 cubic", "ArduPilot cubic")), drift
        assert not any(e["section"] == "case" and e["tag"] == "TABLE" for e in shown)


def test_demo_without_matplotlib_says_why_there_is_no_report(tmp_path, monkeypatch):
    from gyrocomp.report import demo

    monkeypatch.setitem(sys.modules, "matplotlib", None)  # import matplotlib now fails, as when not installed
    why = demo._write_report(None, None, tmp_path / "report.html")
    assert why is not None and "[plot]" in why and not (tmp_path / "report.html").exists()
