"""The 'Your first file' page (docs/first-file.md), run as a newcomer runs it: its six commands through the real
entry point on the shared one-cycle log, each printing what the page shows."""

import re
import shutil

import pytest

from ..conftest import REPO, run, shared_dataset

pytestmark = [pytest.mark.real]

PAGE = (REPO / "docs" / "first-file.md").read_text()


def test_the_first_file_page_is_what_the_commands_say(tmp_path):
    shutil.copy(shared_dataset("tofupilot-imu-thermal") / "imu_raw_data.tsv", tmp_path)
    commands = re.findall(r"(?:^|&& )gyrocomp (.+)$", PAGE, re.M)
    assert [c.split()[0] for c in commands] == ["init", "fit", "show", "apply", "evaluate", "report"]
    said = {}
    for command in commands:
        done = run(*command.split(), cwd=tmp_path)
        assert done.returncode == 0, (command, done.stderr)
        said[command.split()[0]] = done.stdout + done.stderr
    for line in ("time unit us: the median step 5.054e+05 is 1.979 Hz in us", "accelerometer in m/s2: its norm"):
        assert line in said["init"] and line in PAGE
    for row in re.findall(r"^(gyro_[xyz] │ .+)$", PAGE, re.M):  # the fit's table, as the page quotes it
        assert row in said["fit"], row
    assert "is above the constant's" in said["fit"]
    assert "wrote compensated.tsv: 8400 rows, gyro_x, gyro_y, gyro_z compensated" in said["apply"]
    assert "in-sample" not in said["evaluate"]
    assert re.search(r"gyro_y │ +\S+ │ +1\.958 │ +0\.1418 │ +13\.8x", said["evaluate"])
    assert "sections summary, evaluation, axis-gyro_x" in said["report"]
