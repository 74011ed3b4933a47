"""The typed fit report (`Calibration.report`): what the selection, the thermal memory and the g-sensitivity fit
chose, read back as dataclasses from a fresh fit and from its saved file, and from an older file that wrote the
chosen memory only as text."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from gyrocomp.calibration import Calibration
from gyrocomp.calibration.candidate import MEMORIES
from gyrocomp.calibration.fit_report import AxisFit, FitReport, MemoryChoice
from gyrocomp.models.options import FitOptions, Network, Polynomial
from gyrocomp.models.joint import fit_calibration
from gyrocomp.models.pipelines import fit_pipeline
from gyrocomp.fitting.selection import Candidate
from gyrocomp.simulation import simulate

_CACHE = {}


def _turning_fit():
    """The default fit of consumer-part runs that heat, cool and turn between positions (memory and G chosen)."""
    if "fit" not in _CACHE:
        runs = [
            simulate("consumer", profile="combined", rate_hz=5, duration_s=3 * 3600, seed=s, unit=2).recording
            for s in range(3)
        ]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            _CACHE["fit"] = fit_calibration(runs)
    return _CACHE["fit"]


def test_the_report_of_a_default_fit_is_typed_and_says_what_the_model_holds():
    cal = _turning_fit()
    report = cal.report
    assert report.method == "polynomial"
    assert set(report.selection) == set(cal.axes)
    for axis, sel in report.selection.items():
        # the chosen candidate is one of those scored, and the held-out drift quoted is its mean over the folds
        chosen = sel.result(sel.chosen.label)
        assert chosen.mean_drift == pytest.approx(sel.chosen_drift_dps)
        assert len(chosen.fold_drift) == len(sel.folds) >= 3
        assert sel.result("constant (time)").mean_drift == pytest.approx(sel.raw_drift_dps)
        # the memory the report names is the model's: a lag exactly when the axis has a time constant, a
        # turning-point curve of the order named exactly when the axis has one
        choice = report.hysteresis.axes[axis]
        assert choice.memory in MEMORIES and choice.memory == sel.chosen.memory
        ax = cal.axes[axis]
        assert (ax.lag_time_constant_s > 0) == ("lag" in choice.memory)
        assert choice.lag_time_constant_s == ax.lag_time_constant_s
    for axis, written in cal.fit_report["axes"].items():  # each axis's entry was written from its record
        assert report.axes[axis].to_dict() == written and report.axes[axis].unit == "deg/s"
        assert choice.hysteresis_order == (0 if ax.hysteresis is None else ax.hysteresis.order)
        assert choice.label == (
            choice.memory + (f" (order {choice.hysteresis_order})" if choice.hysteresis_order else "")
        )
    # the runs turn between positions: G is fitted, and the report's rows are the model's
    assert report.acceleration is not None and report.acceleration.excited_axes
    for axis, row in report.acceleration.axes.items():
        np.testing.assert_allclose(row.g_sensitivity_dps_per_g, cal.axes[axis].g_sensitivity_dps_per_g)
        assert all(e is None or e > 0 for e in row.standard_error_dps_per_g)


def test_the_report_reads_back_the_same_from_the_saved_file(tmp_path):
    cal = _turning_fit()
    cal.save(tmp_path / "model.json")
    assert Calibration.load(tmp_path / "model.json").report == cal.report


def test_the_selection_report_is_the_selection_as_it_was_made():
    """The stored account against the selection objects it was written from (models.selection)."""
    sel = _turning_fit().report.selection["gyro_z"]
    # the report's candidates are the selection's own class, read back from the file's fields
    assert isinstance(sel.chosen, Candidate) and Candidate.from_dict(sel.chosen.to_dict()) == sel.chosen
    assert {r.candidate.label for r in sel.candidates} >= {"constant (time)", sel.chosen.label, sel.best.label}
    best = min((r for r in sel.candidates if r.mean_drift is not None), key=lambda r: r.mean_drift)
    assert best.candidate == sel.best
    with pytest.raises(KeyError, match="label: no candidate 'poly:9 .time.' for gyro_z"):
        sel.result("poly:9 (time)")


def test_an_older_file_that_wrote_the_memory_as_text_reads_into_the_same_fields():
    old = {
        "chosen": "turning-point+lag (order 2)",
        "lag_time_constant_s": 31.5,
        "order": 3,
        "scores_bic": {"none": -10.0, "turning-point+lag": -14.5},
    }
    choice = MemoryChoice.from_dict(old)
    assert (choice.memory, choice.hysteresis_order, choice.order) == ("turning-point+lag", 2, 3)
    assert choice.label == old["chosen"] and choice.scores["turning-point+lag"] == -14.5
    assert MemoryChoice.from_dict({"chosen": "lag", "lag_time_constant_s": 12.0}).hysteresis_order == 0
    report = FitReport.from_dict(
        {
            "temperature": "polynomial",
            "order_selection": "bic",
            "axes": {"gyro_x": {"order": 2, "scores": {"1": 3.0, "2": 1.0}, "fit_rms_dps": 0.01}},
            "hysteresis": {"mode": "auto", "selection": "bic", "axes": {"gyro_x": old}},
            "learner": {"points": 12},
        }
    )
    assert report.hysteresis.by_bic and report.hysteresis.memories_scored == ("none", "turning-point+lag")
    assert report.order_selection.scores == {"gyro_x": {1: 3.0, 2: 1.0}} and report.order_selection.orders == (1, 2)
    assert report.axes["gyro_x"].fit_rms == 0.01
    assert report.sections == {"learner": {"points": 12}}  # what has no typed record is kept as stored
    # an axis's entry is written from its record, and reads back into it
    entry = {"order": 2, "t_min_degc": 5.0, "t_max_degc": 60.0, "scores": {"1": 3.0, "2": 1.0}, "fit_rms_dps": 0.01}
    assert AxisFit.from_dict(entry).to_dict() == entry
    assert AxisFit.from_dict(entry, "g").to_dict() == {
        **{k: v for k, v in entry.items() if k != "fit_rms_dps"},
        "fit_rms_g": 0.01,
    }


def test_a_model_without_a_fit_report_reads_as_an_empty_one():
    report = FitReport.from_dict({})
    assert report.method is None and report.selection == {} and report.hysteresis is None
    assert report.acceleration is None and report.accel is None and report.stages == ()


@pytest.mark.parametrize(
    "how", ["chosen by the selection", "fixed order and memory (the thermal fit's own)", "no memory asked for"]
)
def test_the_hysteresis_section_is_written_from_its_typed_record(how, chamber_runs):
    """The fit builds the typed record and stores its serialization: reading the section back and writing it
    again gives the stored section, key for key, on each of the three ways the section is made."""
    if how == "chosen by the selection":
        cal = _turning_fit()
    else:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            cal = fit_calibration(
                [sim.recording for sim in chamber_runs[:3]],
                temperature=Polynomial(2),
                hysteresis="none" if how == "no memory asked for" else "lag",
            )
    stored = cal.fit_report["hysteresis"]
    typed = cal.report.hysteresis
    assert typed.to_dict() == stored
    if how == "no memory asked for":
        assert typed.axes == {} and stored == {"mode": "none", "selection": "none"}
    else:
        assert set(typed.axes) == set(cal.axes)
        for axis, choice in typed.axes.items():
            assert stored["axes"][axis]["chosen"] == choice.label
            assert (cal.axes[axis].lag_time_constant_s > 0) == ("lag" in choice.memory)


@pytest.mark.parametrize("mode", ["matrix", "matrix2", "none", "network"])
def test_the_acceleration_section_is_written_from_its_typed_record(mode):
    """As for the hysteresis: the section read back and written again is the stored one, for G, G with the g x g
    terms, no G (with why), and the acceleration network (and the temperature network's section before it); and
    the typed rows are the model's."""
    runs = [
        simulate("consumer", profile="combined", rate_hz=5, duration_s=3 * 3600, seed=s, unit=2).recording
        for s in range(3)
    ]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if mode == "network":
            cal = fit_pipeline(runs, "mlp>mlp-accel", FitOptions(temperature=Network(hidden=(3,))))
            cal = Calibration.from_dict(cal.to_dict())  # the stage's report as the file keeps it
            stored = cal.fit_report["stages"][1]["acceleration"]
            typed = FitReport.from_dict(cal.fit_report["stages"][1]).acceleration
            network = FitReport.from_dict(cal.fit_report["stages"][0]).network  # the temperature network's stage
            assert network.to_dict() == cal.fit_report["stages"][0]["network"] and network.hidden == (3,)
            assert set(network.validation_rmse) == set(cal.axes) and network.restarts >= 1
        else:
            cal = fit_calibration(runs, temperature=Polynomial(2), hysteresis="none", acceleration=mode)
            stored, typed = cal.fit_report["acceleration"], cal.report.acceleration
    assert typed.to_dict() == stored and typed.mode == mode
    if mode == "none":
        assert typed.why == "not asked for" and typed.axes == {}
    elif mode == "network":
        assert typed.hidden == (3,) and len(typed.static_segments) == 3
    else:
        for axis, row in typed.axes.items():
            np.testing.assert_allclose(row.g_sensitivity_dps_per_g, cal.axes[axis].g_sensitivity_dps_per_g)
            assert (row.g_squared_dps_per_g2 is not None) == (mode == "matrix2")
            if mode == "matrix2":
                np.testing.assert_allclose(row.g_squared_dps_per_g2, cal.axes[axis].g_squared_dps_per_g2)
