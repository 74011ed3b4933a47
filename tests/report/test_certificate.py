"""The certificate per unit (built from the store's row and the unit's runs, text escaped, refused when a run
changed), and the pages in a real browser: the report and the certificate opened in headless Chromium (no console
error, every figure drawn at a non-zero size) and printed to PDF (the pages expected); skipped with the reason
where no Chromium is installed."""

from __future__ import annotations

import warnings

import pytest

from gyrocomp.errors import InputError
from gyrocomp.evaluation.held_out import BAND_LEVEL
from gyrocomp.fleet import CalibrationStore
from gyrocomp.fleet.certify import held_out_of
from gyrocomp.io.tables import write_recording
from gyrocomp.models.fit import fit_channels
from gyrocomp.report.certificate import build_certificate
from gyrocomp.report.html import build_report
from gyrocomp.simulation import simulate

from ..conftest import browser, check_report_page, run

needs_chromium = pytest.mark.skipif(
    browser.chromium() is None, reason="no Chromium to open the pages in (apt-get install chromium)"
)
SERIAL = 'SN<1>&"x"'


@pytest.fixture(scope="module")
def fleet(tmp_path_factory):
    """One unit (a hostile serial) of three 1-hour chamber runs at 1 Hz, fitted through the command line with
    limits and its certificate printed to PDF where Chromium is installed."""
    folder = tmp_path_factory.mktemp("certified")
    rows = ["path,serial"]
    for k in range(3):
        path = folder / f"run{k}.parquet"
        write_recording(
            simulate("mti10", profile="chamber", rate_hz=1, duration_s=3600, seed=k, unit=2).recording, path
        )
        rows.append(f'{path},"{SERIAL.replace(chr(34), 2 * chr(34))}"')
    (folder / "m.csv").write_text("\n".join(rows) + "\n")
    (folder / "limits.toml").write_text(
        "[held_out_drift_dps]\nmax = 0.05\n\n[noise_density_dps_per_sqrt_hz]\nmax = 1e-6\n"
    )
    out = folder / "FLEET"
    result = run(
        "fleet",
        "fit",
        "--manifest",
        folder / "m.csv",
        "-o",
        out,
        "--scheduler",
        "serial",
        "--limits",
        folder / "limits.toml",
        "--station",
        "bay <3>",
        "--certificates",
        "pdf" if browser.chromium() else "html",
    )
    assert result.returncode == 0, result.stderr
    return folder, out


@pytest.mark.slow
def test_the_certificate_states_the_unit_its_inputs_model_band_and_verdict(fleet):
    folder, out = fleet
    with CalibrationStore(out) as db:
        record = db.latest(SERIAL)
    held = held_out_of(record)
    assert held.folds == "runs" and held.fold_count == 3 and set(held.axes) == {"gyro_x", "gyro_y", "gyro_z"}
    for axis in held.axes.values():  # the band is the 95 % quantile of |r|: 5 % of the held-out samples beyond it
        assert (abs(axis.residual_dps) > axis.band_dps).mean() == pytest.approx(1 - BAND_LEVEL, abs=0.01)
    page = build_certificate(record, held_out=held).html
    checked = check_report_page(page, ["unit", "inputs", "model", "residual", "merit"])
    assert len(checked.images) == 1
    assert "SN&lt;1&gt;&amp;&quot;x&quot;" in page and SERIAL not in page and "bay &lt;3&gt;" in page
    assert "FAIL: outside a limit" in page  # no part has 1e-6 deg/s/sqrt(Hz) of noise
    for run_input in record.inputs:
        assert run_input.sha256 in page
    written = next((out / "certificates").glob("*.html")).read_text()
    assert "Calibration certificate: SN&lt;1&gt;" in written
    # a run changed since the calibration: refused in one line
    changed = folder / "run0.parquet"
    original = changed.read_bytes()
    changed.write_bytes(original + b"\0")
    try:
        with pytest.raises(InputError, match=r"run0.parquet: changed since unit .* was calibrated"):
            held_out_of(record)
    finally:
        changed.write_bytes(original)


@pytest.mark.slow
@needs_chromium
def test_the_certificate_in_a_browser_and_its_pdf(fleet, tmp_path):
    _, out = fleet
    page = next((out / "certificates").glob("*.html"))
    seen = browser.open_page(page)
    assert seen.errors == ()
    images = [f for f in seen.figures if f["tag"] == "IMG"]
    assert len(images) == 1 and all(f["natural"] > 0 and f["width"] > 0 and f["height"] > 0 for f in images)
    assert seen.pdf_pages == 2  # A4, a three-axis unit: the print style keeps it to two pages
    printed = page.with_suffix(".pdf").read_bytes()
    assert printed.startswith(b"%PDF") and browser.pdf_page_count(printed) == 2
    cli = run("fleet", "certificate", SERIAL, "--store", out, "-o", tmp_path / "c.html", "--pdf", tmp_path / "c.pdf")
    assert cli.returncode == 0, cli.stderr
    assert browser.pdf_page_count((tmp_path / "c.pdf").read_bytes()) == 2


@pytest.mark.slow
@needs_chromium
def test_the_report_in_a_browser(tmp_path):
    runs = [simulate("mti10", profile="chamber", rate_hz=1, duration_s=3600, seed=k).recording for k in range(3)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        report = build_report(fit_channels(runs[:2]), [runs[2]])
    path = tmp_path / "report.html"
    path.write_text(report.html)
    seen = browser.open_page(path)
    assert seen.errors == ()
    images = [f for f in seen.figures if f["tag"] == "IMG"]
    assert len(images) == len(check_report_page(report.html, list(report.sections)).images) > 3
    assert all(f["natural"] > 0 and f["width"] > 0 and f["height"] > 0 for f in images)
    least, most = seen.pages_expected()  # from the page's height on screen: nothing cut, no blank pages
    assert least >= 3 and least <= seen.pdf_pages <= most
