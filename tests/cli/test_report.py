"""``gyrocomp report`` through the real entry point: the HTML page of a model on runs, and without matplotlib."""

import subprocess
import sys

import pytest

from .conftest import assert_refused_in_one_line
from ..conftest import check_report_page, report_sections, run


@pytest.mark.slow
def test_report_of_a_model_on_runs_with_validation(report_files):
    d = report_files
    r = run(
        "report",
        d / "model.json",
        d / "run2.csv",
        "-o",
        d / "report.html",
        "--validate-on",
        d / "run1.csv",
        "--validate-on",
        d / "run2.csv",
    )
    assert r.returncode == 0, r.stderr
    assert "sections summary, validation, evaluation, axis-gyro_x" in r.stdout and "g-sensitivity" in r.stdout
    text = (d / "report.html").read_text()
    check_report_page(text, report_sections(text))
    # the table gyrocomp validate prints: every method, the folds it held out (legs of two runs)
    assert "held-out drift [deg/s]" in text and "PX4 cubic" in text and "gyrocomp default" in text
    assert "folds: run 1" in text and "(legs)" in text


@pytest.mark.parametrize(
    "args, message",
    [
        (["report", "{d}/model.json", "{d}/run2.csv", "-o", "{d}/r.txt"], "-o: {d}/r.txt: name the report .html"),
        (["report", "{d}/model.json", "{d}/run2.csv", "-o", "{d}/run2.csv"], "this is an input file"),
    ],
)
def test_report_refuses_bad_options_in_one_line(report_files, args, message):
    assert_refused_in_one_line(args, message, report_files)


def test_package_imports_and_cli_answers_without_matplotlib(report_files, tmp_path):
    code = (
        "import sys; sys.modules['matplotlib'] = None; import gyrocomp, gyrocomp.cli; "
        "from gyrocomp.cli import main; sys.exit(main(sys.argv[1:]))"
    )
    d = report_files
    done = subprocess.run(
        [
            sys.executable,
            "-c",
            code,
            "report",
            str(d / "model.json"),
            str(d / "run2.csv"),
            "-o",
            str(tmp_path / "r.html"),
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 1
    assert done.stderr.strip() == (
        "gyrocomp: error: plots need the optional package matplotlib; install it with: "
        "pip install 'gyrocomp[plot]' (from a clone of the repository: "
        "pip install -e '.[plot]')"
    )
    assert not (tmp_path / "r.html").exists()
