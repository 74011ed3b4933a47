"""``gyrocomp learn`` through the real entry point: a model from everyday logs, in one go or resumed from a state
file, applied and exported with the learner."""

import json
import subprocess
import sys

import pytest

from gyrocomp.calibration import Calibration
from gyrocomp.errors import InputError
from gyrocomp.fitting.online import LearnerSettings, OnlineCalibrator
from gyrocomp.io.tables import write_recording
from gyrocomp.simulation import get_profile, simulate

from ..conftest import SCRIPT, run


@pytest.mark.slow
def test_learn_through_the_command_line(tmp_path):
    """gyrocomp learn on two logs; in two steps (--save-state, then --resume) the same model; apply takes it;
    a log without still data exits 2 in one line, writing nothing."""
    paths = []
    for k, rec in enumerate(
        (
            simulate(
                "consumer", profile=get_profile("field", motion_seed=k), rate_hz=10.0, seed=80 + k, unit=3
            ).recording
            for k in range(2)
        )
    ):
        paths.append(tmp_path / f"log{k}.csv")
        write_recording(rec, paths[-1])
    done = run("learn", *paths, "-o", tmp_path / "all.json")
    assert done.returncode == 0, done.stderr
    assert "logs replayed" in done.stdout and "learned: curve of degree 3" in done.stdout
    assert (
        run("-q", "learn", paths[0], "-o", tmp_path / "first.json", "--save-state", tmp_path / "state.json").returncode
        == 0
    )
    done = run("-q", "learn", paths[1], "--resume", tmp_path / "state.json", "-o", tmp_path / "second.json")
    assert done.returncode == 0, done.stderr
    one, two = (Calibration.load(tmp_path / n) for n in ("all.json", "second.json"))
    assert one.axes == two.axes
    assert [entry["file"] for entry in one.provenance["inputs"]] == ["log0.csv", "log1.csv"]
    assert run("-q", "apply", tmp_path / "all.json", paths[0], "-o", tmp_path / "out.csv").returncode == 0
    # the C export bakes a learner state's settings (here 2.5 degC bins) into gyrocomp_learn.c
    OnlineCalibrator(LearnerSettings(rate_hz=10.0, bin_width_degc=2.5)).save(tmp_path / "coarse.json")
    done = run(
        "-q",
        "export",
        tmp_path / "all.json",
        "--format",
        "c",
        "--rate",
        10,
        "--learner",
        tmp_path / "coarse.json",
        "-o",
        tmp_path / "c",
    )
    assert done.returncode == 0, done.stderr
    assert "BIN_WIDTH = 2.5," in (tmp_path / "c" / "gyrocomp_learn.c").read_text()
    done = run(
        "export",
        tmp_path / "all.json",
        "--format",
        "px4",
        "--learner",
        tmp_path / "coarse.json",
        "-o",
        tmp_path / "x.params",
    )
    assert done.returncode == 2 and "--learner" in done.stderr and not (tmp_path / "x.params").exists()
    moving = simulate("consumer", profile="tumble", rate_hz=10.0, duration_s=600, seed=1, unit=3).recording
    write_recording(moving, tmp_path / "moving.csv")
    done = run("learn", tmp_path / "moving.csv", "-o", tmp_path / "none.json", "--save-state", tmp_path / "s.json")
    assert done.returncode == 2 and "no model yet" in done.stderr and len(done.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "none.json").exists() and not (tmp_path / "s.json").exists()
    done = run("learn", paths[0], "-o", tmp_path / "x.json", "--save-state", tmp_path / "x.json")
    assert done.returncode == 2 and "--save-state" in done.stderr


def test_a_state_is_saved_only_over_one_it_goes_on_from(tmp_path):
    """A learner state file is replaced only by a learner that goes on from it: a fresh learner, or one that
    resumed another state, is refused in one line naming the file, and the file stays as it was."""
    first = OnlineCalibrator(LearnerSettings(rate_hz=10.0))
    first.save(tmp_path / "s1.json")
    resumed = OnlineCalibrator.load(tmp_path / "s1.json")
    resumed.save(tmp_path / "s2.json")
    kept = (tmp_path / "s2.json").read_text()
    for other in (OnlineCalibrator(LearnerSettings(rate_hz=10.0)), OnlineCalibrator.load(tmp_path / "s1.json")):
        with pytest.raises(
            InputError,
            match=r"s2.json: holds another learner's state, one this learner does not go "
            r"on from .* nothing written",
        ):
            other.save(tmp_path / "s2.json")
        assert (tmp_path / "s2.json").read_text() == kept
    OnlineCalibrator.load(tmp_path / "s2.json").save(tmp_path / "s1.json")  # s1 is an ancestor: replaced
    assert json.loads((tmp_path / "s1.json").read_text())["lineage"][:2] == [first.state_id, resumed.state_id]
    (tmp_path / "other.json").write_text("{}")  # a file that is no learner state is an ordinary output
    first.save(tmp_path / "other.json")


@pytest.mark.slow
@pytest.mark.parametrize("repeat", range(3))
def test_two_learners_resuming_one_state_at_once_never_lose_each_others_work(tmp_path, repeat):
    """The issue's case: two ``learn --resume s.json --save-state next.json`` at once, each on its own log. One
    saves; the other is refused in one line naming the file (it exits 2, writes nothing), never silently
    overwriting; the state saved is the one that went on from s.json with its own log."""
    paths = []
    for k in range(3):
        rec = simulate(
            "consumer", profile=get_profile("field", motion_seed=k), rate_hz=10.0, seed=90 + k, unit=3
        ).recording
        paths.append(tmp_path / f"log{k}.csv")
        write_recording(rec, paths[-1])
    assert run("-q", "learn", paths[0], "-o", tmp_path / "m0.json", "--save-state", tmp_path / "s.json").returncode == 0
    command = [SCRIPT if SCRIPT.exists() else sys.executable, *([] if SCRIPT.exists() else ["-m", "gyrocomp"])]
    learners = [
        subprocess.Popen(
            [
                *map(str, command),
                "-q",
                "learn",
                str(paths[k]),
                "--resume",
                str(tmp_path / "s.json"),
                "-o",
                str(tmp_path / f"m{k}.json"),
                "--save-state",
                str(tmp_path / "next.json"),
            ],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        for k in (1, 2)
    ]
    results = [(learner.wait(timeout=300), learner.stderr.read()) for learner in learners]
    assert sorted(code for code, _ in results) == [0, 2], results
    saved = next(k for (code, _), k in zip(results, (1, 2)) if code == 0)
    refused = 3 - saved
    message = next(err for code, err in results if code == 2)
    assert message.count("\n") == 1 and "next.json: holds another learner's state" in message
    assert not (tmp_path / f"m{refused}.json").exists()
    state = json.loads((tmp_path / "next.json").read_text())
    assert state["lineage"][-2] == json.loads((tmp_path / "s.json").read_text())["lineage"][-1]
    model = Calibration.load(tmp_path / f"m{saved}.json")
    assert [entry["file"] for entry in model.provenance["inputs"]] == [f"log{saved}.csv"]
