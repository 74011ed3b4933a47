"""The HTML report and the single figures: structure, decodable images, no network, the real entry point."""

from __future__ import annotations

import base64
import dataclasses
import io
import os
import pty
import re
import subprocess
import sys
import warnings
from html.parser import HTMLParser

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gyrocomp import fit_calibration
from gyrocomp.models.pipelines import fit_channels
from gyrocomp.report.figures import envelope
from gyrocomp.report.html import SECTIONS, build_report
from gyrocomp.rounding import with_error
from gyrocomp.simulate import get_profile, simulate
from gyrocomp.models.options import FitOptions
from ..conftest import SCRIPT, run

matplotlib_image = pytest.importorskip("matplotlib.image", reason="the report tests draw with matplotlib")


class _Page(HTMLParser):
    def __init__(self):
        super().__init__()
        self.sections, self.images, self.links, self.heads = [], [], [], 0

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "section":
            self.sections.append(attrs["id"])
        if tag == "img":
            self.images.append(attrs["src"])
        for key in ("href", "src"):
            if key in attrs and tag != "img":
                self.links.append(attrs[key])


def _check_page(text: str, expected_sections: list[str]) -> _Page:
    page = _Page()
    page.feed(text)
    assert page.sections == expected_sections
    assert page.images, "no figure in the report"
    for src in page.images:
        assert src.startswith("data:image/png;base64,")
        image = matplotlib_image.imread(io.BytesIO(base64.b64decode(src.split(",", 1)[1])), format="png")
        assert image.ndim == 3 and image.shape[0] > 100 and image.shape[1] > 100
        assert np.ptp(image[..., :3]) > 0.5  # drawn, not blank
    assert all(link.startswith("#") for link in page.links)  # only links within the page
    assert not re.search(r"(https?:)?//[a-z0-9]", re.sub(r"data:image/png;base64,[A-Za-z0-9+/=]+", "", text))
    return page


def _quiet(func, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return func(*args, **kwargs)


def test_single_axis_report_with_hysteresis_has_every_section():
    prof = get_profile("cycle", set_points_degc=(-30.0, 80.0), cycles=1)
    runs = [simulate("adxrs450", profile=prof, rate_hz=0.5, seed=s).recording for s in range(3)]
    cal = _quiet(fit_calibration, runs[:2], hysteresis="turning-point")
    report = build_report(cal, [runs[2]])
    assert report.sections == ("summary", "evaluation", "axis-gyro_z", "firmware", "allan")
    page = _check_page(report.html, list(report.sections))
    assert len(page.images) == 3  # bias against temperature, time series, Allan
    # the hysteresis is what the firmware cannot carry: its cost through a heat-cool cycle is shown
    assert "correction against the model" in report.html and "heat-cool cycle as run" in report.html
    assert "PX4 file (as run)" in report.html
    assert "stages of the compensation" in report.html  # the thesis's Table 4.4 shape with hysteresis
    assert "<th>window [s]</th>" in report.html  # each figure with the window it depends on
    assert "temperature + hysteresis" in report.html and "polynomial order" in report.html


@pytest.mark.slow
def test_three_axis_report_with_acceleration_and_accelerometer():
    runs = [simulate("consumer", profile="combined", duration_s=5400, rate_hz=1, seed=s).recording for s in range(3)]
    cal = _quiet(fit_channels, runs[:2], ("gyro", "accel"), options=FitOptions(hysteresis="none"))
    progress = []
    report = build_report(cal, [runs[2]], progress=progress.append)
    axes = [f"axis-{a}" for a in ("gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z")]
    # the combined profile visits the six faces: the accelerometer triad gets its section too
    assert cal.accel_triad is not None
    assert report.sections == ("summary", "evaluation", *axes, "firmware", "allan", "g-sensitivity", "scale-factor")
    _check_page(report.html, list(report.sections))
    assert "g-sensitivity matrix G [deg/s/g] +- standard error" in report.html
    assert "temperature + acceleration" in report.html and "accelerometer" in report.html
    # chosen by held-out drift: the drift to expect on unseen data, per axis, with its standard error
    expected = cal.report.expected_drift()
    assert "drift to expect on unseen data: mean +- standard error over 4 held-out legs" in report.html
    assert f"{with_error(expected['gyro_x'].drift, expected['gyro_x'].standard_error)} deg/s" in report.html
    assert "thin evidence" not in report.html  # two runs that heat and cool: four legs
    assert progress == sorted(progress) and progress[-1] == 1.0
    assert set(SECTIONS) <= set(report.sections)


@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(-1e6, 1e6, allow_nan=False), min_size=1, max_size=3000), st.integers(1, 400))
def test_envelope_keeps_every_extreme_and_bounds_the_points(values, columns):
    v = np.asarray(values)
    t, e = envelope(np.arange(v.size, dtype=float), v, columns)
    assert e.size <= max(v.size, 2 * columns)
    assert e.min() == v.min() and e.max() == v.max()
    assert np.all(np.diff(t) >= 0)


@pytest.fixture(scope="module")
def cli_files(tmp_path_factory):
    d = tmp_path_factory.mktemp("report")
    for seed in (1, 2):
        r = run("simulate", "--preset", "mti10", "--profile", "combined", "--duration", 3600, "--rate", 1,
                "--seed", seed, "-o", d / f"run{seed}.csv")
        assert r.returncode == 0, r.stderr
    r = run("fit", d / "run1.csv", "-o", d / "model.json", "--hysteresis", "none")
    assert r.returncode == 0, r.stderr
    return d


@pytest.mark.slow
def test_cli_report_and_plots(cli_files):
    d = cli_files
    r = run("report", d / "model.json", d / "run2.csv", "-o", d / "report.html",
            "--validate-on", d / "run1.csv", "--validate-on", d / "run2.csv")
    assert r.returncode == 0, r.stderr
    assert "sections summary, validation, evaluation, axis-gyro_x" in r.stdout and "g-sensitivity" in r.stdout
    text = (d / "report.html").read_text()
    _check_page(text, list(_sections(text)))
    # the table gyrocomp validate prints: every method, the folds it held out (legs of two runs)
    assert "held-out drift [deg/s]" in text and "PX4 cubic" in text and "gyrocomp default" in text
    assert "folds: run 1" in text and "(legs)" in text
    for kind, args, out, magic in (
            ("allan", [d / "run2.csv", "--model", d / "model.json", "--split-gaps"], "allan.png", b"\x89PNG"),
            ("temperature", [d / "model.json", d / "run1.csv", d / "run2.csv", "--axis", "gyro_y"], "t.svg", b"<?xml"),
            ("timeseries", [d / "model.json", d / "run2.csv", "--axis", "gyro_z"], "ts.pdf", b"%PDF")):
        r = run("plot", kind, *args, "-o", d / out)
        assert r.returncode == 0, r.stderr
        assert (d / out).read_bytes().startswith(magic)


def _sections(text):
    page = _Page()
    page.feed(text)
    return page.sections


@pytest.mark.parametrize("args, message", [
    (["report", "{d}/model.json", "{d}/run2.csv", "-o", "{d}/r.txt"], "-o: {d}/r.txt: name the report .html"),
    (["plot", "timeseries", "{d}/model.json", "{d}/run2.csv", "-o", "{d}/x.gif"], "x.gif: figure suffix '.gif'"),
    (["plot", "timeseries", "{d}/model.json", "{d}/run2.csv", "--axis", "gyro_q", "-o", "{d}/x.png"],
     "--axis: 'gyro_q': the model and the data share gyro_x, gyro_y, gyro_z"),
    (["report", "{d}/model.json", "{d}/run2.csv", "-o", "{d}/run2.csv"], "this is an input file"),
])
def test_cli_report_and_plot_refuse_bad_options_in_one_line(cli_files, args, message):
    d = cli_files
    r = run(*[a.format(d=d) for a in args])
    assert r.returncode == 2
    errors = [line for line in r.stderr.splitlines() if line.startswith("gyrocomp: error")]
    assert len(errors) == 1 and message.format(d=d) in errors[0], r.stderr
    assert "Traceback" not in r.stderr


def test_progress_bar_on_a_terminal_only(cli_files):
    d = cli_files
    cmd = [str(SCRIPT)] if SCRIPT.exists() else [sys.executable, "-m", "gyrocomp"]

    def stderr_of(*extra):
        master, slave = pty.openpty()
        done = subprocess.run([*cmd, *extra, "convert", str(d / "run2.csv"), str(d / "tty.parquet")],
                               stdout=subprocess.PIPE, stderr=slave, timeout=300)
        os.close(slave)
        chunks = []
        while True:
            try:
                chunk = os.read(master, 65536)
            except OSError:
                break
            if not chunk:
                break
            chunks.append(chunk)
        os.close(master)
        assert done.returncode == 0
        return b"".join(chunks)

    bar = b"\xe2\x94\x81"  # the bar's glyph
    shown = stderr_of()
    assert b"reading run2.csv" in shown and bar in shown
    assert bar not in stderr_of("--quiet")
    piped = run("convert", d / "run2.csv", d / "piped.parquet")
    assert bar.decode() not in piped.stderr  # not a terminal: no bar


def test_package_imports_and_cli_answers_without_matplotlib(cli_files, tmp_path):
    code = ("import sys; sys.modules['matplotlib'] = None; import gyrocomp, gyrocomp.cli; "
            "from gyrocomp.cli import main; sys.exit(main(sys.argv[1:]))")
    d = cli_files
    done = subprocess.run([sys.executable, "-c", code, "report", str(d / "model.json"), str(d / "run2.csv"),
                           "-o", str(tmp_path / "r.html")], capture_output=True, text=True, timeout=300)
    assert done.returncode == 1
    assert done.stderr.strip() == ("gyrocomp: error: plots need the optional package matplotlib; install it with: "
                                   "pip install 'gyrocomp[plot]'")
    assert not (tmp_path / "r.html").exists()


def test_text_from_files_is_escaped_once():
    prof = get_profile("cycle", set_points_degc=(-30.0, 80.0), cycles=1)
    runs = [simulate("adxrs450", profile=prof, rate_hz=0.5, seed=s).recording for s in range(3)]
    cal = _quiet(fit_calibration, runs[:2], hysteresis="none")
    hostile = dataclasses.replace(runs[2], source="run&1<script>alert(1)<b>.csv")
    page = build_report(dataclasses.replace(cal, model="m<b>&amp;"), [hostile]).html
    assert "run&amp;1&lt;script&gt;alert(1)&lt;b&gt;.csv" in page and "<script>" not in page
    assert "&amp;amp;" not in page.replace("m&lt;b&gt;&amp;amp;", "")  # nothing escaped twice but the name's own
    assert "m&lt;b&gt;&amp;amp;" in page
