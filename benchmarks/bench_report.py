"""Benchmark: the HTML report of a 24-hour, 100 Hz, 3-axis run (target: under a minute on 2 cores).

The run is the ``mti10`` preset through a cold-hot-cold cycle stretched to 24 h; the model is fitted on a
1 Hz run of the same profile (fitting is not what is measured). Timed in the same process:

- ``gyrocomp report`` (build_report): compensation, evaluation, every figure, the Allan curves of raw and
  compensated data, the page;
- baseline: ``gyrocomp apply`` on the same run (the least a report must do is compensate the data), and
  one overlapping Allan deviation (octave taus) of the three raw axes.

Usage: python benchmarks/bench_report.py [--hours H] [--rate HZ]
"""

from __future__ import annotations

import argparse
import platform
import resource
import time
import warnings

import numpy as np

from gyrocomp import apply, fit_calibration
from gyrocomp.allan import allan_deviation
from gyrocomp.report.html import build_report
from gyrocomp.simulation import get_profile, simulate


def timed(func):
    start = time.perf_counter()
    result = func()
    return time.perf_counter() - start, result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--hours", type=float, default=24.0)
    parser.add_argument("--rate", type=float, default=100.0)
    args = parser.parse_args()
    duration = args.hours * 3600.0
    profile = get_profile("cycle", set_points_degc=(-25.0, 90.0), cycles=1)
    warnings.simplefilter("ignore")
    calibration_runs = [
        simulate("mti10", profile=profile, duration_s=duration, rate_hz=1.0, seed=s).recording for s in (1, 2)
    ]
    calibration = fit_calibration(calibration_runs, hysteresis="none")
    run = simulate("mti10", profile=profile, duration_s=duration, rate_hz=args.rate, seed=3).recording

    t_report, report = timed(lambda: build_report(calibration, [run]))
    t_apply, _ = timed(lambda: apply(calibration, run))
    t_allan, _ = timed(lambda: [allan_deviation(run.gyro_dps[:, j], run.rate_hz) for j in range(3)])
    peak_mib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024

    print(
        f"machine: {platform.processor() or platform.machine()}, python {platform.python_version()}, "
        f"numpy {np.__version__}"
    )
    print(
        f"run: {args.hours:g} h at {args.rate:g} Hz, 3 axes = {run.n_samples:,} samples per axis; "
        f"model {calibration.model}"
    )
    print("| step | time [s] | ratio |")
    print("|---|---:|---:|")
    print(
        f"| gyrocomp report (HTML, {len(report.sections)} sections, {len(report.html) / 1e6:.1f} MB) | "
        f"{t_report:.1f} | {t_report / t_apply:.1f}x apply |"
    )
    print(f"| gyrocomp apply (baseline) | {t_apply:.1f} | 1 |")
    print(f"| Allan deviation of the 3 raw axes, octave taus | {t_allan:.1f} | {t_allan / t_apply:.1f}x apply |")
    print(f"peak resident memory of the process: {peak_mib:.0f} MiB")


if __name__ == "__main__":
    main()
