"""``gyrocomp plot`` through the real entry point: each kind of figure, and bad options."""

import pytest

from .conftest import assert_refused_in_one_line
from ..conftest import run


@pytest.mark.slow
def test_plot_draws_each_kind_in_the_format_its_suffix_names(report_files):
    d = report_files
    for kind, args, out, magic in (
        ("allan", [d / "run2.csv", "--model", d / "model.json", "--split-gaps"], "allan.png", b"\x89PNG"),
        ("temperature", [d / "model.json", d / "run1.csv", d / "run2.csv", "--axis", "gyro_y"], "t.svg", b"<?xml"),
        ("timeseries", [d / "model.json", d / "run2.csv", "--axis", "gyro_z"], "ts.pdf", b"%PDF"),
    ):
        r = run("plot", kind, *args, "-o", d / out)
        assert r.returncode == 0, r.stderr
        assert (d / out).read_bytes().startswith(magic)


@pytest.mark.parametrize(
    "args, message",
    [
        (["plot", "timeseries", "{d}/model.json", "{d}/run2.csv", "-o", "{d}/x.gif"], "x.gif: figure suffix '.gif'"),
        (
            ["plot", "timeseries", "{d}/model.json", "{d}/run2.csv", "--axis", "gyro_q", "-o", "{d}/x.png"],
            "--axis: 'gyro_q': the model and the data share gyro_x, gyro_y, gyro_z",
        ),
    ],
)
def test_plot_refuses_bad_options_in_one_line(report_files, args, message):
    assert_refused_in_one_line(args, message, report_files)
