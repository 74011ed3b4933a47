"""Benchmark: is the exported noise model one a filter can trust? (``gyrocomp noise``, issue #47, item 5)

For each simulated part, its white noise and flicker growing ``--tempco`` per degC: the noise model is made as a
user would, from a chamber run held at -20, 25 and 70 degC for ``--dwell-hours`` each after 300 s of settling
(``noise_over_temperature``: each dwell's curve bounded). Then ``--runs`` Monte Carlo runs of ``--minutes`` at ``--rate`` Hz, the temperature ramping from -20
to 70 degC and back (the noise following it), feed the small attitude filter of
:mod:`gyrocomp.evaluation.filter_consistency` (absolute attitude updates every 2 s, 0.01 deg) told each model in
turn: the bound with white noise and random walk (what Kalibr, VINS and the autopilots carry), the bound with
Gauss-Markov terms, the dwells' own bounds scheduled by the temperature (interpolated between them; two-term and with
Gauss-Markov terms),
the IEEE 952 fit of the 25 degC dwell (N and K), and that fit times 10; and, to tell the bound's construction from
its margin over a finite log, the scheduled bound with Gauss-Markov terms made from each dwell's true curve (the mean
Allan variance of ``--draws`` independent logs of the part held at that temperature, no interval). Printed: the median
time-averaged NEES and the share of runs inside its 95 % chi-square band (below it: over-cautious; above:
over-confident).

Usage: python benchmarks/bench_noise_nees.py [--runs R] [--minutes M] [--rate HZ] [--tempco C] [--dwell-hours H]
       [--draws D] [--seed S] [--presets P,...]
"""

from __future__ import annotations

import argparse
import dataclasses
import warnings

import numpy as np

from gyrocomp.allan import allan_deviation
from gyrocomp.allan.bound import NoiseBound, bound_noise, markov_grid
from gyrocomp.evaluation.filter_consistency import attitude_nees
from gyrocomp.measures.noise import analyse_noise
from gyrocomp.measures.noise_model import noise_over_temperature, scheduled_bound, temperature_dwells
from gyrocomp.simulation import get_profile, preset_model, simulate
from gyrocomp.simulation.error_model import simulate_noise

PRESETS = ("mti10", "adis16488", "consumer", "adxrs450")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=200)
    parser.add_argument("--minutes", type=float, default=30.0)
    parser.add_argument("--rate", type=float, default=20.0)
    parser.add_argument("--tempco", type=float, default=0.005)
    parser.add_argument("--dwell-hours", type=float, default=10.0)
    parser.add_argument("--draws", type=int, default=8)
    parser.add_argument("--seed", type=int, default=1, help="seed of the chamber run the models are made from")
    parser.add_argument("--presets", default=",".join(PRESETS), help="the parts, comma-separated")
    args = parser.parse_args()
    n = int(args.minutes * 60 * args.rate)
    ramp = np.interp(np.linspace(0.0, 1.0, n), [0.0, 0.5, 1.0], [-20.0, 70.0, -20.0])
    print("| part | model told to the filter | median NEES | runs inside the 95 % band | band |")
    print("|---|---|---|---|---|")
    for preset in args.presets.split(","):
        model = dataclasses.replace(preset_model(preset), noise_tempco_per_degc=args.tempco)
        profile = get_profile("chamber", set_points_degc=(-20.0, 25.0, 70.0), dwell_s=args.dwell_hours * 3600.0 + 300.0)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            chamber = simulate(model, profile=profile, rate_hz=args.rate, seed=args.seed).recording
            made = noise_over_temperature(chamber, [model.axes[0]])
        axis = made.axes[model.axes[0]]
        middle = chamber.take(temperature_dwells(chamber)[1])  # the 25 degC dwell: what a user fits at room temperature
        ieee = analyse_noise(middle, [model.axes[0]], motion_check=False).axes[model.axes[0]].terms
        fitted = NoiseBound(ieee.white_noise_density, ieee.random_walk, (), (1.0,), 1.0, 1.0)
        scaled = dataclasses.replace(
            fitted, white_noise_density=10 * fitted.white_noise_density, random_walk=10 * fitted.random_walk
        )
        #: what the filter is told: attitude_nees's keywords
        told = {
            "bound, white + random walk": {"noise": axis.bound},
            "bound with Gauss-Markov terms": {"noise": axis.markov},
            "bound scheduled by temperature (each dwell's)": {
                "noise": axis.bound,
                "schedule": scheduled_bound(axis),
                "temperature_degc": ramp,
            },
            "bound with Gauss-Markov terms scheduled by temperature": {
                "noise": axis.markov,
                "schedule": scheduled_bound(axis, markov=True),
                "temperature_degc": ramp,
            },
            "the same, bounding the true curves": {
                "noise": axis.markov,
                "schedule": scheduled_bound(_true_curves_bounded(axis, model, args, chamber), markov=True),
                "temperature_degc": ramp,
            },
            "IEEE 952 fit (N, K)": {"noise": fitted},
            "IEEE 952 fit x10": {"noise": scaled},
        }
        errors = np.empty((args.runs, n))
        for r in range(args.runs):
            truth = simulate_noise(n, args.rate, model, np.random.default_rng(1000 + r), ramp)
            errors[r] = truth.white_dps[:, 0] + truth.flicker_dps[:, 0] + truth.random_walk_dps[:, 0]
        for name, keywords in told.items():
            result = attitude_nees(errors, args.rate, **keywords)
            print(
                f"| {preset} | {name} | {np.median(result.nees):.2f} | {result.inside:.0%} | "
                f"{result.band[0]:.2f}..{result.band[1]:.2f} |"
            )


def _true_curves_bounded(axis, model, args, chamber):
    """``axis`` with each dwell's Gauss-Markov bound made from the part's true curve at the dwell's temperature:
    the mean Allan variance of ``args.draws`` independent logs as long as the dwell, taken as exact (no interval)."""
    logs = []
    for log, dwell in zip(axis.logs, temperature_dwells(chamber)):
        n = dwell.stop - dwell.start
        held = np.full(n, log.temperature_degc)
        curves = []
        for d in range(args.draws):
            truth = simulate_noise(n, args.rate, model, np.random.default_rng(500 + d), held)
            curves.append(
                allan_deviation(
                    truth.white_dps[:, 0] + truth.flicker_dps[:, 0] + truth.random_walk_dps[:, 0], args.rate
                )
            )
        exact = dataclasses.replace(
            curves[0],
            deviation=np.sqrt(np.mean([c.deviation**2 for c in curves], axis=0)),
            edf=np.full(curves[0].edf.shape, 1e12),
        )
        grid = markov_grid(axis.markov.taus_s[0], axis.markov.taus_s[-1])
        bound = bound_noise(exact, max_tau_s=axis.max_tau_s, time_constants_s=grid)
        logs.append(dataclasses.replace(log, markov=bound))
    return dataclasses.replace(axis, logs=tuple(logs))


if __name__ == "__main__":
    main()
