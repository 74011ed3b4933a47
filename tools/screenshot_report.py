"""Render a gyrocomp report in headless Chromium and save a full-page screenshot (see docs/report.md).

Makes simulated runs (the ``mti10`` preset through the ``combined`` profile: temperature cycles, tumble
positions, thermal lag), fits the default model on two and reports the third, then asks Debian's
Chromium (``apt-get install chromium``) for a screenshot, with networking off.

Usage: python tools/screenshot_report.py [--out DIR] [--chromium PATH]
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import tempfile
import warnings
from pathlib import Path

from gyrocomp import fit_calibration
from gyrocomp.report.html import build_report
from gyrocomp.simulation import simulate

CHROMIUM_FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--hide-scrollbars",
)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="report-screenshot", help="Folder for report.html and the PNGs.")
    parser.add_argument("--chromium", default=shutil.which("chromium") or "/usr/bin/chromium")
    parser.add_argument("--height", type=int, default=9000, help="Page height of the screenshot [px].")
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    warnings.simplefilter("ignore")
    runs = [simulate("mti10", profile="combined", duration_s=4 * 3600, rate_hz=2, seed=s).recording for s in range(3)]
    calibration = fit_calibration(runs[:2])
    report = build_report(calibration, [runs[2]])
    page = out / "report.html"
    page.write_text(report.html, encoding="utf-8")
    shots = {"report-top.png": 1400, "report-full.png": args.height}
    with tempfile.TemporaryDirectory() as profile:
        for name, height in shots.items():
            subprocess.run(
                [
                    args.chromium,
                    *CHROMIUM_FLAGS,
                    f"--user-data-dir={profile}",
                    f"--window-size=1280,{height}",
                    f"--screenshot={out / name}",
                    page.resolve().as_uri(),
                ],
                check=True,
                capture_output=True,
                timeout=180,
            )
    print(f"model {calibration.model}; sections {', '.join(report.sections)}")
    print("wrote " + ", ".join(str(out / n) for n in ("report.html", *shots)))


if __name__ == "__main__":
    main()
