"""Benchmark: the default fit of three one-hour runs at 100 Hz, every candidate scored (target: under a minute on
2 cores).

The runs are the ``consumer`` preset (whole-degree temperature register, 30 s thermal lag, g-sensitivity) through
a heat-cool cycle, a ramp-and-hold and a warm-up, one power-on each. Timed in the same process:

- ``fit_calibration`` with the defaults: every candidate (polynomial order 0..5, thermal lag, turning-point
  hysteresis 1..3, time or temperature-balanced weights, with the g-sensitivity columns when the unit turns)
  scored by held-out drift on leave-one-run-out folds, the choice refitted on all runs;
- baseline: a plain cubic with one constant per run by ordinary least squares on every sample
  (``gyrocomp.evaluation.validation.fit_plain_cubic``), what a user writes by hand in numpy;
- ``validate``: the whole comparison table (raw, PX4's and ArduPilot's cubics, the plain cubic, the default),
  each method refitted on every fold.

The plain cubic and the default fit are timed again with a busy neighbour process on one core
(``benchmarks/busy.py``): the library keeps BLAS on one thread, so it should barely notice.

Usage: python benchmarks/bench_fit.py [--minutes M] [--rate HZ]
"""

from __future__ import annotations

import argparse
import os
import platform
import time
import warnings

import numpy as np

from busy import busy_neighbour
from gyrocomp import fit_calibration
from gyrocomp.simulation import get_profile, simulate
from gyrocomp.evaluation.validation import fit_plain_cubic, validate


def timed(func):
    start = time.perf_counter()
    result = func()
    return time.perf_counter() - start, result


def runs(minutes: float, rate_hz: float, count: int = 3):
    """``count`` power-ons of the consumer preset: a heat-cool cycle, a ramp-and-hold, a warm-up, in turn."""
    duration = minutes * 60.0
    profiles = [
        get_profile("cycle", set_points_degc=(10.0, 50.0), cycles=1),
        get_profile("chamber", set_points_degc=(10.0, 50.0)),
        get_profile("warmup"),
    ]
    return [
        simulate("consumer", profile=profiles[s % 3], duration_s=duration, rate_hz=rate_hz, seed=s).recording
        for s in range(count)
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=60.0)
    parser.add_argument("--rate", type=float, default=100.0)
    parser.add_argument("--runs", type=int, default=3, help="number of runs (e.g. 10: how the fit grows with runs)")
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    recordings = runs(args.minutes, args.rate, args.runs)
    n = sum(r.n_samples for r in recordings)

    t_cubic, _ = timed(lambda: fit_plain_cubic(recordings))
    t_fit, cal = timed(lambda: fit_calibration(recordings))
    t_validate, result = timed(lambda: validate(recordings))
    with busy_neighbour():
        t_cubic_busy, _ = timed(lambda: fit_plain_cubic(recordings))
        t_fit_busy, _ = timed(lambda: fit_calibration(recordings))
    scored = sum(len(s["candidates"]) for s in cal.fit_report["selection"].values())

    print(
        f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
        f"python {platform.python_version()}, numpy {np.__version__}"
    )
    print(
        f"runs: {args.runs} x {args.minutes:g} min at {args.rate:g} Hz, 3 axes = {n:,} samples per axis; "
        f"chosen {cal.model}; {scored} candidates scored over 3 axes, folds: {result.fold_kind}"
    )
    print("| step | time [s] | ratio |")
    print("|---|---:|---:|")
    print(f"| plain cubic + run constants, least squares on every sample (baseline) | {t_cubic:.1f} | 1 |")
    print(
        f"| `fit_calibration`, defaults (every candidate scored on held-out folds) | {t_fit:.1f} | "
        f"{t_fit / t_cubic:.1f}x |"
    )
    print(f"| `validate` (5 methods, each refitted on every fold) | {t_validate:.1f} | {t_validate / t_cubic:.1f}x |")
    print(
        f"| with a busy neighbour on one core: plain cubic | {t_cubic_busy:.1f} | {t_cubic_busy / t_cubic:.2f}x idle |"
    )
    print(
        f"| with a busy neighbour on one core: `fit_calibration` | {t_fit_busy:.1f} | {t_fit_busy / t_fit:.2f}x idle |"
    )


if __name__ == "__main__":
    main()
