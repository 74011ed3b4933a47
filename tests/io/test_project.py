"""The project file read by the library (gyrocomp.io.project): ``gyrocomp.read(path, config=...)`` reads a file
as every command run beside the project file does; what is given to ``read`` wins; bad files and keys are refused
in one line naming them."""

import numpy as np
import pytest

from gyrocomp import read
from gyrocomp.errors import InputError
from gyrocomp.io import TableLayout
from gyrocomp.io.project import project_read_options

ROWS = 50


@pytest.fixture()
def log(tmp_path):
    """A semicolon-separated log with a decimal comma, time in ms, gyro in rad/s, other names."""
    t = np.arange(ROWS) * 10.0
    gyro = np.column_stack([np.full(ROWS, 0.01), np.linspace(0, 0.02, ROWS), np.full(ROWS, -0.01)])
    lines = ["Zeit;GX;GY;GZ;Temp"] + [
        ";".join(f"{v:.6f}".replace(".", ",") for v in (t[i], *gyro[i], 25.0 + i)) for i in range(ROWS)
    ]
    path = tmp_path / "log.txt"
    path.write_text("\n".join(lines) + "\n")
    (tmp_path / "gyrocomp.toml").write_text(
        '[read]\ngyro-unit = "rad/s"\ntime-unit = "ms"\ndelimiter = ";"\ndecimal = ","\nformat = "csv"\n'
        '[read.columns]\ntime = "Zeit"\ngyro_x = "GX"\ngyro_y = "GY"\ngyro_z = "GZ"\ntemperature = "Temp"\n'
        '[fit]\nhysteresis = "none"\n'
    )
    return path, gyro


def test_read_takes_the_project_files_reading_options(log, tmp_path):
    path, gyro = log
    rec = read(path, config=tmp_path / "gyrocomp.toml")
    np.testing.assert_allclose(rec.gyro_dps, np.degrees(gyro), atol=1e-4)  # six decimals of rad/s
    np.testing.assert_allclose(rec.time_s[:3], [0.0, 0.01, 0.02])  # ms -> s
    assert rec.temperature_degc[-1] == pytest.approx(25.0 + ROWS - 1)
    options, fmt = project_read_options(tmp_path / "gyrocomp.toml")
    assert fmt == "csv" and options.layout.columns["gyro_x"] == "GX" and options.layout.decimal == ","


def test_what_is_given_to_read_wins_over_the_project_file(log, tmp_path):
    path, gyro = log
    as_deg = read(path, config=tmp_path / "gyrocomp.toml", gyro_unit="deg/s", time_range_s=(0.0, 0.1))
    np.testing.assert_allclose(as_deg.gyro_dps, gyro[:10], atol=1e-6)  # the file's numbers, taken as deg/s
    columns = {"time": "Zeit", "gyro_z": "GZ", "temperature": "Temp"}
    only_z = read(path, columns=columns, gyro_unit="rad/s", time_unit="ms")  # the layout's fields, no file
    assert only_z.gyro_axes == ("gyro_z",)
    np.testing.assert_allclose(only_z.gyro_dps[:, 0], np.degrees(gyro[:, 2]), atol=1e-4)
    with pytest.raises(InputError, match=r"layout: give a TableLayout or its fields \(gyro_unit\), not both"):
        read(path, TableLayout(columns=columns), gyro_unit="rad/s")


def test_a_bad_project_file_is_refused_naming_what(log, tmp_path):
    path, _ = log
    with pytest.raises(InputError, match=r"config: .*nowhere.toml: no such project file \(gyrocomp init writes one"):
        read(path, config=tmp_path / "nowhere.toml")
    (tmp_path / "bad.toml").write_text('[read]\ngyro-units = "rad/s"\n')
    with pytest.raises(InputError, match=r"bad.toml: \[read\] gyro-units: not a reading option; use .*gyro-unit"):
        read(path, config=tmp_path / "bad.toml")
    (tmp_path / "broken.toml").write_text("[read\n")
    with pytest.raises(InputError, match=r"broken.toml: not a readable TOML file"):
        read(path, config=tmp_path / "broken.toml")
    (tmp_path / "switch.toml").write_text('[read]\ndrop-nan = "yes"\n')
    with pytest.raises(InputError, match=r"switch.toml: \[read\] drop-nan: true or false, got 'yes'"):
        read(path, config=tmp_path / "switch.toml")
