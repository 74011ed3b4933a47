"""A calibration certificate per unit: one self-contained HTML page (and its PDF, printed by headless Chromium).

It states what was done, on what data and how good the result is: the serial, the station, the time, the
inputs with their SHA-256, the gyrocomp version that calibrated it, the model of each axis and the temperature
range it is valid over, the held-out residual with its 95 % band (:mod:`gyrocomp.evaluation.held_out`), the
figures of merit against the line's limits, and the verdict. Every text from the store or the files is escaped.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np

from ..calibration import Calibration
from ..errors import FOREIGN_MESSAGE_CHARS, InputError, printable
from ..evaluation.held_out import BAND_LEVEL, HeldOut
from ..fleet.limits import Limits
from ..fleet.store import CalibrationRecord
from ..io.atomic import atomic_path
from . import figures
from .page import Report, escape_text, figure_html, html_page, table_html

SECTIONS = ("unit", "inputs", "model", "residual", "merit")
#: printed: A4, small type, no navigation, the figure a third of a page: two pages for a three-axis unit
PRINT_CSS = """
@page { size: A4; margin: 12mm; }
@media print { body { font-size: 8.5pt; margin: 0; max-width: none; } nav { display: none; }
  h1 { font-size: 1.4em; } h2 { margin-top: 1em; } img { max-height: 95mm; width: auto; }
  table { font-size: 0.95em; } section { break-inside: auto; } }
"""
#: what the PDF printer may be called
CHROMIUM_NAMES = ("chromium", "chromium-browser", "google-chrome")


def build_certificate(
    record: CalibrationRecord, *, held_out: HeldOut | None = None, limits: Limits | None = None
) -> Report:
    """The certificate of the calibration ``record`` (a successful row of the store); ``held_out``: its residual
    and band (from the unit's runs); ``limits``: the line's limits (default: the verdict stored with the row)."""
    calibration = record.calibration()
    verdict, failures = record.verdict, record.failures
    if limits is not None and record.figures is not None:
        checked = limits.check(record.figures)
        verdict, failures = checked.label, checked.failures
    sections = {
        "unit": ("Unit and verdict", _unit(record, verdict)),
        "inputs": ("Inputs", table_html(["run", "SHA-256"], [[i.path, i.sha256] for i in record.inputs])),
        "model": ("Model", _model(calibration, record)),
        "residual": (f"Held-out residual and its {100 * BAND_LEVEL:.0f} % band", _residual(held_out)),
        "merit": ("Figures of merit against the limits", _merit(record, limits, failures)),
    }
    title = f"Calibration certificate: {record.serial}"
    page = html_page(title, title, f"calibrated {record.calibrated_utc:%Y-%m-%d %H:%M:%S} UTC", sections, css=PRINT_CSS)
    return Report(page, SECTIONS)


def _unit(record: CalibrationRecord, verdict: str | None) -> str:
    words = {"pass": "PASS: within every limit", "fail": "FAIL: outside a limit"}.get(
        verdict or "", "not judged (no limits given)"
    )
    rows = [
        ["serial", record.serial],
        ["station", record.station or "-"],
        ["calibrated (UTC)", f"{record.calibrated_utc:%Y-%m-%d %H:%M:%S}"],
        ["calibrated by", f"gyrocomp {record.gyrocomp_version}"],
        ["store row", str(record.id)],
        ["input hash (runs and settings)", record.input_hash],
        ["verdict", words],
    ]
    return (
        f'<p class="lead"><strong>{escape_text(words)}</strong></p>'
        + table_html(["", ""], rows)
        + ("".join(f"<p class=note>{escape_text(w)}</p>" for w in record.warnings[:5]))
    )


def _model(calibration: Calibration, record: CalibrationRecord) -> str:
    rows = []
    for s in calibration.summaries():
        valid = "-" if s.range_degc is None else f"{s.range_degc[0]:.4g} .. {s.range_degc[1]:.4g}"
        rows.append([s.axis, s.unit, s.model, valid])
    seen = ""
    if record.figures is not None:
        seen = (
            f"<p class=note>The runs covered {record.figures.temperature_min_degc:.4g} .. "
            f"{record.figures.temperature_max_degc:.4g} degC in {record.figures.runs} run(s); outside the valid "
            "range the model is held at its edge.</p>"
        )
    return table_html(["axis", "unit", "model", "valid temperature range [degC]"], rows) + seen


def _residual(held_out: HeldOut | None) -> str:
    if held_out is None:
        return "<p class=note>Not computed (the unit's runs were not at hand).</p>"
    rows = [[axis, a.rms_dps, a.band_dps] for axis, a in held_out.axes.items()]
    text = (
        f"<p>Each {held_out.folds[:-1] if held_out.folds.endswith('s') else held_out.folds} of the "
        f"{held_out.fold_count} held out in turn, fitted on the rest and compensated; the residual is the "
        f"compensated output moving-averaged over {held_out.window_s:.4g} s, about its mean. On a new run of "
        f"this unit the residual is expected within +-band {100 * BAND_LEVEL:.0f} % of the time.</p>"
    )
    return (
        text
        + table_html(["axis", "held-out residual RMS [deg/s]", f"{100 * BAND_LEVEL:.0f} % band [deg/s]"], rows)
        + figure_html(_residual_figure(held_out), "held-out residual against temperature")
    )


def _residual_figure(held_out: HeldOut):
    plt = figures._pyplot()
    axes_names = list(held_out.axes)
    fig, axes = plt.subplots(len(axes_names), 1, figsize=(7.5, 2.2 * len(axes_names)), squeeze=False)
    for ax, name in zip(axes[:, 0], axes_names):
        a = held_out.axes[name]
        step = max(1, a.residual_dps.size // 4000)
        ax.plot(a.temperature_degc[::step], a.residual_dps[::step], ".", ms=2, color="#1f77b4", label="held out")
        for sign in (1, -1):
            ax.axhline(
                sign * a.band_dps, color="#d62728", lw=1, label=f"{100 * BAND_LEVEL:.0f} % band" if sign > 0 else None
            )
        ax.set_ylabel(f"{name} [deg/s]")
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("temperature [degC]")
    axes[0, 0].legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    return fig


def _merit(record: CalibrationRecord, limits: Limits | None, failures) -> str:
    if record.figures is None:
        return "<p class=note>No figures (a failed calibration).</p>"
    row = record.figures.as_row()
    failing = {f.figure: f.reason for f in failures}
    bounds = _bounds(limits, row) if limits is not None else {}
    names = [
        n
        for n in row
        if np.isfinite(row[n])
        and (n in bounds or n in failing or n.endswith("drift_dps") or "noise_density" in n or "bias_instability" in n)
    ]
    rows = [
        [n, row[n], bounds.get(n, "-"), "fail" if n in failing else ("pass" if n in bounds else "-")] for n in names
    ]
    return table_html(["figure", "value", "limit", "result"], rows)


def _bounds(limits: Limits, row: dict) -> dict[str, str]:
    out = {}
    for limit in limits.limits:
        words = ", ".join(
            f"{k} {v:.4g}"
            for k, v in (("min", limit.min), ("max", limit.max), ("abs_max", limit.abs_max))
            if v is not None
        )
        for name in row:
            if (
                name == limit.figure
                or name == f"{limit.axis}_{limit.figure}"
                or (limit.axis is None and name.endswith("_" + limit.figure))
            ):
                out[name] = words
    return out


#: how long Chromium may take to print a certificate [s] (a few seconds on a 2-core machine; one that hangs is stopped)
PDF_TIMEOUT_S = 60.0


def print_pdf(page: str | os.PathLike, pdf: str | os.PathLike, timeout_s: float = PDF_TIMEOUT_S) -> Path:
    """Print the HTML file ``page`` to ``pdf`` with headless Chromium (atomically), within ``timeout_s`` [s]; one
    line when no Chromium is installed (Debian's package ``chromium``), when it hangs, fails or writes something
    that is not a PDF (nothing is then written at ``pdf``)."""
    browser = next((shutil.which(n) for n in CHROMIUM_NAMES if shutil.which(n)), None)
    if browser is None:
        raise InputError(
            f"{pdf}: printing the PDF needs Chromium, and none is installed (apt-get install "
            "chromium); the HTML certificate was written"
        )
    with atomic_path(pdf) as tmp, tempfile.TemporaryDirectory() as profile:
        command = [
            browser,
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--no-first-run",
            "--disable-background-networking",
            f"--user-data-dir={profile}",
            "--no-pdf-header-footer",
            f"--print-to-pdf={tmp}",
            Path(page).resolve().as_uri(),
        ]
        try:
            done = subprocess.run(command, capture_output=True, timeout=timeout_s)
        except subprocess.TimeoutExpired:
            raise InputError(
                f"{pdf}: Chromium ({browser}) did not print {page} within {timeout_s:g} s and was stopped; "
                "the HTML certificate was written"
            ) from None
        if done.returncode != 0 or not _is_pdf(tmp):
            said = done.stderr.decode("utf-8", "replace").strip().splitlines()[-1:]
            why = f"exit {done.returncode}" if done.returncode != 0 else "what it wrote is not a PDF"
            raise InputError(
                f"{pdf}: Chromium ({browser}) could not print {page} ({why}"
                + (f": {printable(said[0])[:FOREIGN_MESSAGE_CHARS]}" if said else "")
                + "); the HTML certificate was written"
            )
    return Path(pdf)


def _is_pdf(path: Path) -> bool:
    """Whether ``path`` holds a PDF: its header, and an end-of-file marker in its last KiB."""
    with open(path, "rb") as f:
        head = f.read(5)
        f.seek(max(0, path.stat().st_size - 1024))
        tail = f.read()
    return head == b"%PDF-" and b"%%EOF" in tail


__all__ = ["SECTIONS", "build_certificate", "print_pdf"]
