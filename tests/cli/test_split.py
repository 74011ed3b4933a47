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
