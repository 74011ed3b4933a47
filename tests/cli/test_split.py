"""``gyrocomp split`` through the real entry point: one log cut into its runs."""

import numpy as np

from gyrocomp import read
from gyrocomp.io.tables import write_recording
from gyrocomp.simulation import simulate

from ..conftest import joined_recordings, run


def test_split_through_the_command_line(tmp_path):
    parts = [simulate("consumer", profile="warmup", duration_s=300, rate_hz=10, seed=s).recording for s in range(2)]
    log = tmp_path / "two.csv"
    write_recording(joined_recordings(parts, 120.0), log)
    result = run("split", log, "-o", tmp_path / "runs", "--by", "power-on")
    assert result.returncode == 0, result.stderr
    assert "wrote 2 run(s)" in result.stdout
    written = sorted((tmp_path / "runs").glob("*.csv"))
    assert [p.name for p in written] == ["two_run1.csv", "two_run2.csv"]
    np.testing.assert_allclose(read(written[1]).gyro_dps, parts[1].gyro_dps, rtol=1e-12)
    again = run("split", log, "-o", tmp_path / "runs", "--by", "power-on")
    assert again.returncode == 2 and "two_run1.csv exists; split into an empty folder" in again.stderr


def test_a_tables_runs_keep_its_columns_units_and_separator(tmp_path):
    """The runs of a table read as the table does, with the same project file: its own columns, units, separator
    and decimal point, the suffix its own (before: canonical columns in a comma-separated .csv, which the project
    file that named the log's columns no longer read)."""
    parts = [simulate("consumer", profile="warmup", duration_s=300, rate_hz=10, seed=s).recording for s in range(2)]
    joined = joined_recordings(parts, 120.0)
    lines = ["Zeit;GyrX;GyrY;GyrZ;Temp"] + [
        ";".join(f"{v:.6f}".replace(".", ",") for v in (t, *np.radians(g), temp))
        for t, g, temp in zip(joined.time_s, joined.gyro_dps, joined.temperature_degc)
    ]
    (tmp_path / "log.txt").write_text("\n".join(lines) + "\n")
    (tmp_path / "gyrocomp.toml").write_text(
        '[read]\ncolumns = "time=Zeit,gyro_x=GyrX,gyro_y=GyrY,gyro_z=GyrZ,temperature=Temp"\ngyro-unit = "rad/s"\n'
    )
    done = run("split", "log.txt", "-o", "runs", "--by", "power-on", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    first = (tmp_path / "runs" / "log_run1.csv").read_text().splitlines()
    assert first[0] == "Zeit;GyrX;GyrY;GyrZ;Temp" and first[1].count(";") == 4 and "," in first[1]
    fitted = run("fit", "runs/log_run1.csv", "runs/log_run2.csv", "-o", "m.json", cwd=tmp_path)  # no flag
    assert fitted.returncode == 0, fitted.stderr
    back = read(tmp_path / "runs" / "log_run2.csv", _layout())
    np.testing.assert_allclose(back.gyro_dps, parts[1].gyro_dps, atol=1e-4)  # six decimals of rad/s


def _layout():
    from gyrocomp.io import TableLayout

    return TableLayout(
        columns={"time": "Zeit", "gyro_x": "GyrX", "gyro_y": "GyrY", "gyro_z": "GyrZ", "temperature": "Temp"},
        gyro_unit="rad/s",
    )
