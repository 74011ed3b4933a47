"""The data check on a fault-injection corpus and on every shared real recording.

Protocol (issue: the production line): for every simulator preset, ``--runs`` (50) clean chamber runs and, for
each fault of :data:`gyrocomp.simulation.faults.FAULTS`, ``--runs`` faulty ones (each its own seed), written as
Parquet tables and checked as ``gyrocomp check`` checks them (read, then judged with the default ask; the
``no-reversal`` fault with turning-point hysteresis asked). A faulty run counts as found when the check it should
name is among its reasons; a clean run counts as flagged when it has any finding, and is counted again when it has
a finding other than those its part has by design (the consumer part's whole-degree temperature register is
``temperature-quantized``, a true finding, on every run). Then every shared real
recording gyrocomp reads is checked, and what is flagged is listed with the reason.

    python benchmarks/bench_data_check.py [--runs 50] [--markdown docs/data-check-results.md]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from gyrocomp.files.check import check_files, read_checked
from gyrocomp.measures.data_check import QUANTIZED_STEP_DEGC, Ask, CheckedRun, check_runs
from gyrocomp.io.tables import write_recording
from gyrocomp.recording import GYRO_AXES, Recording
from gyrocomp.simulation import PRESETS, preset_model, simulate
from gyrocomp.simulation.faults import FAULTS, inject

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from tests.real import real_data  # noqa: E402  (the shared recordings, read as the tests read them)

RATE_HZ = 1.0


def _columns(preset: str, seed: int, folder: Path) -> dict[str, np.ndarray]:
    path = folder / "clean.parquet"
    write_recording(simulate(preset, profile="chamber", rate_hz=RATE_HZ, seed=seed).recording, path)
    table = pd.read_parquet(path)
    return {c: table[c].to_numpy() for c in table.columns}


def _by_design(preset: str) -> set[str]:
    """The findings a preset's clean runs have by the part's design: a temperature register of coarse steps (the
    consumer part's whole degrees) is ``temperature-quantized`` on every run, the check's true finding."""
    steps = preset_model(preset).temperature_quantization_degc
    return {"temperature-quantized"} if steps >= QUANTIZED_STEP_DEGC else set()


def corpus(runs: int, folder: Path) -> tuple[dict, dict]:
    """(found[preset][fault] = fraction found with the right reason, clean[preset] = {reason: fraction})."""
    found: dict[str, dict[str, float]] = {}
    clean: dict[str, dict[str, float]] = {}
    for preset in PRESETS:
        found[preset] = {f: 0.0 for f in FAULTS}
        reasons: dict[str, int] = {}
        flagged = other = 0  # clean runs with a finding; with one the part does not have by design
        by_design = _by_design(preset)
        for k in range(runs):
            rng = np.random.default_rng(10_000 + k)
            columns = _columns(preset, 1000 + k, folder)
            path = folder / "run.parquet"
            pd.DataFrame(columns).to_parquet(path)
            (check,) = check_files([path])[1]
            flagged += bool(check.findings)
            other += any(reason not in by_design for reason in check.reasons)
            for reason in check.reasons:
                reasons[reason] = reasons.get(reason, 0) + 1
            for fault, expected in FAULTS.items():
                pd.DataFrame(inject(columns, fault, rng)).to_parquet(path)
                ask = Ask(hysteresis=True) if fault == "no-reversal" else Ask()
                run = read_checked(path)
                (check,) = check_runs([run], ask)
                found[preset][fault] += expected in check.reasons
        found[preset] = {f: n / runs for f, n in found[preset].items()}
        clean[preset] = {
            "any": flagged / runs,
            "other": other / runs,
            **{r: n / runs for r, n in sorted(reasons.items())},
        }
        print(f"{preset}: clean flagged {100 * flagged / runs:.0f} % {clean[preset]}", file=sys.stderr)
    return found, clean


def real_recordings() -> list[tuple[str, Ask, list[CheckedRun]]]:
    """Every shared real recording gyrocomp reads, as sets of runs (a unit's runs together) with what a fit of
    them asks: the default, or no temperature curve for the recordings that have no temperature."""
    sets = []
    if real_data.TOFUPILOT.is_dir():
        sets.append(("tofupilot-imu-thermal", Ask(), [CheckedRun("imu_raw_data.tsv", real_data.tofupilot_run())]))
    if real_data.CATS.is_dir():
        sets.append(("skdivemove-cats-tempcal", Ask(), [CheckedRun(r.source, r) for r in real_data.cats_runs()]))
    if real_data.XSENS.is_dir() and real_data.FERRARIS.is_dir() and real_data.MPU.is_dir():
        for name, rec in real_data.multi_position_recordings().items():
            sets.append((rec.source, Ask(temperature="none"), [CheckedRun(name, rec)]))
    if real_data.ADIS.is_dir():
        for name, gyro in real_data.adis_sessions().items():
            rec = Recording(time_s=np.arange(len(gyro)) / 100.0, gyro_dps=gyro, gyro_axes=GYRO_AXES, source=name)
            sets.append(("smac-imudata-adis16405", Ask(temperature="none"), [CheckedRun(name, rec)]))
    if real_data.GALAXY.is_dir():
        gyro = real_data.galaxy_gyro_dps()
        rec = Recording(time_s=np.arange(len(gyro)) / 10.0, gyro_dps=gyro, gyro_axes=GYRO_AXES, source="galaxy s5")
        sets.append(("skdivemove-galaxy-s5-static", Ask(temperature="none"), [CheckedRun("samsung_galaxy_s5.nc", rec)]))
    datasets = Path(real_data.TOFUPILOT).parent
    for name, pattern in (("px4-pyulog-samples", "*.ulg"), ("ardupilot-pymavlink-sample", "*.BIN")):
        for path in sorted((datasets / name).glob(pattern)):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                sets.append((name, Ask(), [read_checked(path)]))
    return sets


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=50)
    parser.add_argument("--markdown", type=Path, default=None)
    args = parser.parse_args()
    started = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        found, clean = corpus(args.runs, Path(tmp))
    lines = [
        f"Fault-injection corpus: {args.runs} runs per preset and fault, {args.runs} clean runs per preset "
        f"(chamber profile, {RATE_HZ:g} Hz), {time.perf_counter() - started:.0f} s.",
        "",
        "| fault (check) | " + " | ".join(PRESETS) + " |",
        "|---|" + "---|" * len(PRESETS),
    ]
    for fault, check in FAULTS.items():
        lines.append(f"| {fault} ({check}) | " + " | ".join(f"{100 * found[p][fault]:.0f} %" for p in PRESETS) + " |")
    lines.append("| **clean runs flagged** | " + " | ".join(f"{100 * clean[p]['any']:.0f} %" for p in PRESETS) + " |")
    lines.append(
        "| **clean runs flagged for what the part does not have** | "
        + " | ".join(f"{100 * clean[p]['other']:.0f} %" for p in PRESETS)
        + " |"
    )
    lines += [
        "",
        "Reasons on clean runs: "
        + "; ".join(
            f"{p}: "
            + (", ".join(f"{r} {100 * v:.0f} %" for r, v in clean[p].items() if r not in ("any", "other")) or "none")
            for p in PRESETS
        ),
        "",
        "Real recordings:",
        "",
        "| dataset | run | verdict |",
        "|---|---|---|",
    ]
    for name, ask, runs in real_recordings():
        for check in check_runs(runs, ask):
            line = check.line()[len(check.source) + 2 :].replace("|", "\\|")
            lines.append(f"| {name} | {Path(check.source).name} | {line} |")
    text = "\n".join(lines) + "\n"
    print(text)
    if args.markdown is not None:
        args.markdown.write_text(text)


if __name__ == "__main__":
    main()
