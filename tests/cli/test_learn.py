"""``gyrocomp learn`` through the real entry point: a model from everyday logs, in one go or resumed from a state
file, applied and exported with the learner."""

import pytest

from gyrocomp.calibration import Calibration
from gyrocomp.fitting.online import LearnerSettings, OnlineCalibrator
from gyrocomp.io.tables import write_recording
from gyrocomp.simulation import get_profile, simulate

from ..conftest import run


@pytest.mark.slow
def test_learn_through_the_command_line(tmp_path):
    """gyrocomp learn on two logs; in two steps (--save-state, then --resume) the same model; apply takes it;
    a log without still data exits 2 in one line, writing nothing."""
    paths = []
    for k, rec in enumerate((simulate("consumer", profile=get_profile("field", motion_seed=k), rate_hz=10.0, seed=80 + k,
                                     unit=3).recording for k in range(2))):
        paths.append(tmp_path / f"log{k}.csv")
        write_recording(rec, paths[-1])
    done = run("learn", *paths, "-o", tmp_path / "all.json")
    assert done.returncode == 0, done.stderr
    assert "logs replayed" in done.stdout and "learned: curve of degree 3" in done.stdout
    assert run("-q", "learn", paths[0], "-o", tmp_path / "first.json", "--save-state",
               tmp_path / "state.json").returncode == 0
    done = run("-q", "learn", paths[1], "--resume", tmp_path / "state.json", "-o", tmp_path / "second.json")
    assert done.returncode == 0, done.stderr
    one, two = (Calibration.load(tmp_path / n) for n in ("all.json", "second.json"))
    assert one.axes == two.axes
    assert [entry["file"] for entry in one.provenance["inputs"]] == ["log0.csv", "log1.csv"]
    assert run("-q", "apply", tmp_path / "all.json", paths[0], "-o", tmp_path / "out.csv").returncode == 0
    # the C export bakes a learner state's settings (here 2.5 degC bins) into gyrocomp_learn.c
    OnlineCalibrator(LearnerSettings(rate_hz=10.0, bin_width_degc=2.5)).save(tmp_path / "coarse.json")
    done = run("-q", "export", tmp_path / "all.json", "--format", "c", "--rate", 10, "--learner",
               tmp_path / "coarse.json", "-o", tmp_path / "c")
    assert done.returncode == 0, done.stderr
    assert "BIN_WIDTH = 2.5," in (tmp_path / "c" / "gyrocomp_learn.c").read_text()
    done = run("export", tmp_path / "all.json", "--format", "px4", "--learner", tmp_path / "coarse.json", "-o",
               tmp_path / "x.params")
    assert done.returncode == 2 and "--learner" in done.stderr and not (tmp_path / "x.params").exists()
    moving = simulate("consumer", profile="tumble", rate_hz=10.0, duration_s=600, seed=1, unit=3).recording
    write_recording(moving, tmp_path / "moving.csv")
    done = run("learn", tmp_path / "moving.csv", "-o", tmp_path / "none.json", "--save-state", tmp_path / "s.json")
    assert done.returncode == 2 and "no model yet" in done.stderr and len(done.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "none.json").exists() and not (tmp_path / "s.json").exists()
    done = run("learn", paths[0], "-o", tmp_path / "x.json", "--save-state", tmp_path / "x.json")
    assert done.returncode == 2 and "--save-state" in done.stderr
