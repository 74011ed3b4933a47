"""Benchmark: simulating a 24-hour, 100 Hz, 3-axis run of the ``mti10`` preset with every effect on.

The run is a cold-hot-cold cycle stretched to 24 h (thermal lag, hysteresis, g-sensitivity, scale
factor, white + flicker noise, output and temperature quantization, accelerometer). Baselines,
timed in the same process:

- numpy white noise: ``rng.standard_normal((n, 3))``, the least any simulator of this run must do;
- full-rate flicker bank: the same Gauss-Markov bank with every process drawn at the sample rate
  (what the coarse grids of ``flicker_bank`` replace).

Usage: python benchmarks/bench_simulate.py [--hours H] [--rate HZ] [--repeat K]
"""

from __future__ import annotations

import argparse
import platform
import resource

import numpy as np
from bench_apply import best_of  # run as a script from the repository root: benchmarks/ is on the path

from gyrocomp.simulation import error_model, get_profile, simulate


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--hours", type=float, default=24.0)
    parser.add_argument("--rate", type=float, default=100.0)
    parser.add_argument("--repeat", type=int, default=2)
    args = parser.parse_args()
    duration = args.hours * 3600.0
    n = int(duration * args.rate) + 1
    profile = get_profile("cycle", set_points_degc=(-25.0, 90.0), cycles=1)

    t_sim = best_of(
        args.repeat, lambda: simulate("mti10", profile=profile, duration_s=duration, rate_hz=args.rate, seed=1)
    )
    rng = np.random.default_rng(0)
    t_white = best_of(args.repeat, lambda: rng.standard_normal((n, 3)))
    t_bank = best_of(args.repeat, lambda: [error_model.flicker_bank(n, args.rate, 18.0, rng) for _ in range(3)])
    saved = error_model.GM_STEPS_PER_TIME_CONSTANT
    error_model.GM_STEPS_PER_TIME_CONSTANT = float("inf")  # every process at the sample rate
    try:
        t_bank_full = best_of(1, lambda: [error_model.flicker_bank(n, args.rate, 18.0, rng) for _ in range(3)])
    finally:
        error_model.GM_STEPS_PER_TIME_CONSTANT = saved
    peak_mib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024

    print(
        f"machine: {platform.processor() or platform.machine()}, python {platform.python_version()}, "
        f"numpy {np.__version__}"
    )
    print(f"run: {args.hours:g} h at {args.rate:g} Hz, 3 axes = {n:,} samples per axis")
    print("| step | time [s] | ratio |")
    print("|---|---:|---:|")
    print(f"| gyrocomp simulate, every effect | {t_sim:.2f} | {t_sim / t_white:.1f}x numpy white noise |")
    print(f"| numpy white noise only (baseline) | {t_white:.2f} | 1 |")
    print(f"| flicker bank, coarse grids (3 axes) | {t_bank:.2f} | {t_bank_full / t_bank:.1f}x faster than full rate |")
    print(f"| flicker bank, every process at full rate (baseline) | {t_bank_full:.2f} | 1 |")
    print(f"peak resident memory of the process: {peak_mib:.0f} MiB")


if __name__ == "__main__":
    main()
