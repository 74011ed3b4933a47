"""The example station (examples/openhtf_station.py) run as OpenHTF runs it: a good unit passes with its figures
recorded as measurements against the limits and its certificate attached; a unit whose run has no temperature
stops at the data check and fails. Skipped where OpenHTF is not installed."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

from gyrocomp.fleet import CalibrationStore
from gyrocomp.io.tables import write_recording
from gyrocomp.simulation import simulate

htf = pytest.importorskip("openhtf", reason="OpenHTF is not installed (pip install openhtf)")
EXAMPLE = Path(__file__).parents[1] / "examples" / "openhtf_station.py"


def _example():
    spec = importlib.util.spec_from_file_location("openhtf_station", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    sys.modules["openhtf_station"] = module
    spec.loader.exec_module(module)
    return module


def _execute(station, serial: str, runs, store, output):
    records = []
    test = station.station_test([str(r) for r in runs], str(store), str(output))
    test.add_output_callbacks(records.append)
    test.execute(test_start=lambda: serial)
    return records[0]


@pytest.mark.slow
def test_the_openhtf_station_checks_fits_and_certifies_one_unit(tmp_path):
    station = _example()
    runs = []
    for k in range(3):
        path = tmp_path / f"run{k}.parquet"
        write_recording(
            simulate("mti10", profile="chamber", rate_hz=1, duration_s=3600, seed=k, unit=4).recording, path
        )
        runs.append(path)
    store, output = tmp_path / "line.sqlite", tmp_path / "out"
    record = _execute(station, "SN-HTF-1", runs, store, output)
    assert record.outcome.name == "PASS", [p.name for p in record.phases]
    measured = {name: m.measured_value.value for p in record.phases for name, m in p.measurements.items()}
    with CalibrationStore(store) as db:
        row = db.latest("SN-HTF-1")
    assert row.station == "openhtf" and row.verdict == "pass"
    assert measured["runs_refused"] == 0
    for axis in ("gyro_x", "gyro_y", "gyro_z"):
        assert measured[f"{axis}_held_out_drift_dps"] == row.figures.axes[axis].held_out_drift_dps
    (attachment,) = [a for p in record.phases for a in p.attachments.values()]
    assert b"Calibration certificate: SN-HTF-1" in attachment.data
    # a run without its temperature: refused by the data check, the unit fails there and nothing is stored
    bare = tmp_path / "bare.csv"
    rec = simulate("mti10", profile="chamber", rate_hz=1, duration_s=600, seed=9).recording
    write_recording(rec, bare)
    text = bare.read_text().splitlines()
    header = text[0].split(",")
    keep = [i for i, name in enumerate(header) if name != "temperature"]
    bare.write_text("\n".join(",".join(row.split(",")[i] for i in keep) for row in text) + "\n")
    failed = _execute(station, "SN-HTF-2", [bare], store, output)
    assert failed.outcome.name == "FAIL" and [p.name for p in failed.phases][-1] == "data_check"
    with CalibrationStore(store) as db:
        assert "SN-HTF-2" not in db.serials()
