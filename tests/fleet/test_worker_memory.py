"""A unit whose fit outgrows its Dask worker's memory limit: Dask kills the worker (and the ones it retries on),
the unit is recorded as failed with why, and the other units of the fleet are fitted and stored."""

from __future__ import annotations

import warnings

import pandas as pd
import pytest

from gyrocomp.fleet.run import fit_fleet
from gyrocomp.fleet.store import CalibrationStore
from gyrocomp.fleet.devices import UnitRuns
from gyrocomp.io.tables import write_recording
from gyrocomp.simulation import simulate

pytestmark = pytest.mark.slow


def test_a_unit_past_the_worker_memory_limit_fails_and_the_fleet_goes_on(tmp_path):
    units = []
    for serial, rate_hz, hours in (("SMALL-1", 1.0, 1.0), ("BIG", 100.0, 8.0), ("SMALL-2", 1.0, 1.0)):
        paths = []
        for k in range(2):
            path = tmp_path / f"{serial}_{k}.parquet"
            write_recording(
                simulate(
                    "consumer", profile="chamber", rate_hz=rate_hz, duration_s=hours * 3600, seed=k, unit=len(units)
                ).recording,
                path,
            )
            paths.append(str(path))
        units.append(UnitRuns(serial, tuple(paths)))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        # one worker of 650 MB (Dask pauses it at 80 %, kills it at 95 %: 617 MB): a process fitting a small unit
        # peaks at about 210 MB (measured, plus the worker's own ~70 MB), one fitting BIG's two runs of 2.88 M
        # samples at about 1.1 GB (measured in one process; runs of 1.44 M samples, 800 MB until the fit's moving
        # variance was taken a column at a time, now fit in about 650 MB)
        summary = fit_fleet(units, tmp_path / "fleet", workers=1, memory_limit="650MB")
    assert sorted(summary.fitted) == ["SMALL-1", "SMALL-2"], (summary.failed, summary.busy)
    assert list(summary.failed) == ["BIG"]
    assert summary.failed["BIG"].startswith(
        "its worker was killed on every try (past its memory limit, or a crash): KilledWorker"
    )
    table = pd.read_parquet(tmp_path / "fleet" / "fleet.parquet").set_index("serial")
    assert table.loc["BIG", "status"] == "failed" and (table.loc[["SMALL-1", "SMALL-2"], "status"] == "ok").all()
    with CalibrationStore(tmp_path / "fleet") as store:
        assert store.latest("SMALL-1").status == "ok" and store.latest("SMALL-1").model_json
        big = store.latest("BIG")
        assert big.status == "failed" and big.model_json is None and "KilledWorker" in big.error
