"""Benchmark: what a calibration buys a filter's bias process noise (``gyrocomp noise --model``, issue #47 item 3).

For each simulated part: the default fit on two one-cycle chamber runs (-10..60 degC), then on a third, held out,
the bias random walk K a filter needs with the raw gyro and with the compensated one (white noise and random walk
at or above the Allan curve up to a quarter of the run, :mod:`gyrocomp.evaluation.bias_process_noise`), beside
the K of the noise alone (the simulator's truth): the largest over the part's axes.

Usage: python benchmarks/bench_bias_process_noise.py [--rate HZ]
"""

from __future__ import annotations

import argparse
import warnings

from gyrocomp import fit_calibration
from gyrocomp.allan import allan_deviation
from gyrocomp.allan.bound import bound_noise
from gyrocomp.evaluation.bias_process_noise import MAX_TAU_FRACTION, bias_process_noise
from gyrocomp.simulation import get_profile, simulate

PRESETS = ("mti10", "adis16488", "consumer", "adxrs450")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rate", type=float, default=5.0)
    args = parser.parse_args()
    profile = get_profile("cycle", set_points_degc=(-10.0, 60.0), cycles=1)
    print("| part | raw K [deg/h/sqrt(h)] | compensated K | noise alone K | raw / compensated |")
    print("|---|---:|---:|---:|---:|")
    for preset in PRESETS:
        sims = [simulate(preset, profile=profile, rate_hz=args.rate, seed=s) for s in range(3)]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            calibration = fit_calibration([s.recording for s in sims[:2]])
        rec = sims[2].recording
        benefit = bias_process_noise(calibration, rec)
        alone = []
        for j in range(len(rec.gyro_axes)):
            noise = sims[2].truth.noise.total_dps[:, j]
            alone.append(
                bound_noise(
                    allan_deviation(noise - noise.mean(), rec.rate_hz),
                    markov=False,
                    max_tau_s=MAX_TAU_FRACTION * rec.time_s[-1],
                ).random_walk
            )
        raw = max(b.raw.random_walk for b in benefit.values()) * 216000.0  # deg/s/sqrt(s) -> deg/h/sqrt(h)
        compensated = max(b.compensated.random_walk for b in benefit.values()) * 216000.0
        print(f"| {preset} | {raw:.0f} | {compensated:.0f} | {max(alone) * 216000.0:.0f} | {raw / compensated:.1f} |")


if __name__ == "__main__":
    main()
