"""Benchmark: noise models that bound the measured Allan deviation (``gyrocomp noise``, issue #47, item 1).

For each simulated part (the presets' noise: white, flicker as a Gauss-Markov bank, rate random walk), one static
log of ``--hours`` at ``--rate`` Hz is measured (overlapping Allan deviation, octave taus up to a tenth of the
record) and three models are made of it: the IEEE Std 952 least-squares fit, the bound with white noise and
random walk only (what Kalibr, VINS and the autopilots carry), and the bound with Gauss-Markov terms. Each is
compared with the true deviation, the mean Allan variance of ``--truths`` independent realizations of the same
part: the share of taus where the model is at or above it, and the median and largest ratio.

Usage: python benchmarks/bench_noise_bound.py [--hours H] [--rate HZ] [--truths K]
"""

from __future__ import annotations

import argparse

import numpy as np

from gyrocomp.allan import allan_deviation, noise_terms
from gyrocomp.allan.bound import bound_noise
from gyrocomp.simulation import preset_model
from gyrocomp.simulation.error_model import simulate_noise

PRESETS = ("mti10", "adis16488", "consumer", "adxrs450")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--hours", type=float, default=1.0)
    parser.add_argument("--rate", type=float, default=50.0)
    parser.add_argument("--truths", type=int, default=16)
    args = parser.parse_args()
    n = int(args.hours * 3600 * args.rate)
    record_s = n / args.rate
    print("| part | model | taus at or above the truth | median ratio | largest ratio | smallest ratio |")
    print("|---|---|---|---|---|---|")
    for preset in PRESETS:
        model = preset_model(preset)

        def draw(seed, model=model):
            return simulate_noise(n, args.rate, model, np.random.default_rng(seed)).total_dps[:, 0]

        measured = allan_deviation(draw(1), args.rate, taus="octave")
        keep = measured.tau <= record_s / 10
        tau = measured.tau[keep]
        truth = np.sqrt(
            np.mean(
                [
                    allan_deviation(draw(seed), args.rate, taus="octave").deviation[keep] ** 2
                    for seed in range(2, 2 + args.truths)
                ],
                axis=0,
            )
        )
        models = {
            "IEEE 952 fit": noise_terms(measured).model_deviation(tau),
            "bound, white + random walk": bound_noise(measured, markov=False, max_tau_s=record_s / 10).deviation(tau),
            "bound with Gauss-Markov terms": bound_noise(measured, max_tau_s=record_s / 10).deviation(tau),
        }
        for name, deviation in models.items():
            ratio = deviation / truth
            print(
                f"| {preset} | {name} | {np.mean(ratio >= 1.0):.0%} | {np.median(ratio):.2f} | {ratio.max():.2f} "
                f"| {ratio.min():.2f} |"
            )


if __name__ == "__main__":
    main()
