"""An OpenHTF station that calibrates one unit with gyrocomp: the data check, the fit into the line's store, the
certificate, each a phase, the figures recorded as OpenHTF measurements with the line's limits.

    pip install 'gyrocomp[fleet,plot]' openhtf
    python examples/openhtf_station.py SERIAL STORE OUTPUT RUN [RUN ...]

STORE is the line's store (a folder, an SQLite file or a postgresql:// URL); OUTPUT a folder for the unit's
model and certificate. The test passes when every run passes the data check and every figure is within its limit.
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import openhtf as htf

from gyrocomp.files.check import ask_for, check_files
from gyrocomp.fleet import CalibrationStore, FleetSettings, Limit, Limits, UnitRuns, fit_fleet
from gyrocomp.fleet.certify import held_out_of
from gyrocomp.report.certificate import build_certificate

AXES = ("gyro_x", "gyro_y", "gyro_z")
#: the line's limits [deg/s, deg/s/sqrt(Hz)]: the held-out drift and the white noise of each axis
MAX_HELD_OUT_DRIFT_DPS = 0.05
MAX_NOISE_DENSITY_DPS_PER_SQRT_HZ = 0.05
LIMITS = Limits(
    (
        Limit("held_out_drift_dps", max=MAX_HELD_OUT_DRIFT_DPS),
        Limit("noise_density_dps_per_sqrt_hz", max=MAX_NOISE_DENSITY_DPS_PER_SQRT_HZ),
    )
)


def station_test(runs: list[str], store: str, output: str, station: str = "openhtf") -> htf.Test:
    """The OpenHTF test of one unit: its serial is the test's DUT id (``execute(test_start=lambda: SERIAL)``)."""

    @htf.measures(htf.Measurement("runs_refused").equals(0), htf.Measurement("runs_with_warnings"))
    def data_check(test):
        """gyrocomp check: a refused run stops the unit here, with the reason in the log."""
        _, checks = check_files(runs, ask=ask_for())
        for c in checks:
            test.logger.info(c.line())
        test.measurements.runs_refused = sum(c.verdict == "refused" for c in checks)
        test.measurements.runs_with_warnings = sum(c.verdict == "warning" for c in checks)
        return htf.PhaseResult.STOP if test.measurements.runs_refused else htf.PhaseResult.CONTINUE

    # the names carry the units (OpenHTF's unit table has no deg/s)
    @htf.measures(
        *[htf.Measurement(f"{a}_held_out_drift_dps").in_range(maximum=MAX_HELD_OUT_DRIFT_DPS) for a in AXES],
        *[
            htf.Measurement(f"{a}_noise_density_dps_per_sqrt_hz").in_range(maximum=MAX_NOISE_DENSITY_DPS_PER_SQRT_HZ)
            for a in AXES
        ],
    )
    def fit(test):
        """gyrocomp fleet fit of this one unit into the line's store (the data check runs there too)."""
        serial = test.test_record.dut_id
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            summary = fit_fleet(
                [UnitRuns(serial, tuple(runs))],
                output,
                FleetSettings(),
                limits=LIMITS,
                scheduler="serial",
                store=store,
                station=station,
            )
        if serial in summary.failed:
            test.logger.error(summary.failed[serial])
            return htf.PhaseResult.STOP
        with CalibrationStore(store) as db:
            figures = db.latest(serial).figures
        for axis in AXES:
            test.measurements[f"{axis}_held_out_drift_dps"] = figures.axes[axis].held_out_drift_dps
            test.measurements[f"{axis}_noise_density_dps_per_sqrt_hz"] = figures.axes[
                axis
            ].noise_density_dps_per_sqrt_hz
        return htf.PhaseResult.CONTINUE

    def certificate(test):
        """The unit's certificate, written beside its model and attached to the test record."""
        serial = test.test_record.dut_id
        with CalibrationStore(store) as db:
            record = db.latest(serial)
        path = Path(output) / f"certificate-{record.id}.html"
        path.write_text(build_certificate(record, held_out=held_out_of(record), limits=LIMITS).html)
        test.attach_from_file(str(path), mimetype="text/html")

    return htf.Test(data_check, fit, certificate, test_name="gyrocomp calibration")


def main() -> int:
    serial, store, output, *runs = sys.argv[1:]
    test = station_test(runs, store, output)
    return 0 if test.execute(test_start=lambda: serial) else 1


if __name__ == "__main__":
    sys.exit(main())
