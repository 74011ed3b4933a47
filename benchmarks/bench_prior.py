"""Benchmark: how much chamber time the population prior saves (issue #17, ``gyrocomp fleet fit --prior``).

A fleet of ``--fleet`` units of the ``consumer`` preset's production spread (three 15-minute chamber runs over
-20..70 degC at 10 Hz each) is fitted and its prior built. Then, for ``--new`` units not in the fleet, each is
calibrated three ways and judged on a held-out full-range chamber run (mean over the axes of the RMS of the 60 s
moving average of the compensated rate):

- ``full``: the default fit on the unit's three full runs (45 minutes of chamber time: the reference);
- ``prior``: ``fit_with_prior`` on one short run;
- ``alone``: the default fit on that short run alone;
- ``oracle``: ``fit_with_prior`` on the same short run, with the simulator's true population instead of the
  fleet's (its coefficients' mean and covariance from 4,000 drawn parts, their true thermal lag and noise): what no
  fleet can know, so the best this estimator can do on that run;

for short runs covering a third, half, two thirds and all of the range, in a quarter or half of the full chamber
time, run two ways: ``one way`` (the ``chamber`` profile: held cold, one ramp up, held hot) and ``there and back``
(the ``cycle`` profile's two round trips: held cold, up, held hot, down, held cold, and again). Printed: the median (and worst) ratio of
the held-out drift to the full calibration's, and the held-out runs' noise floor (the simulator's deterministic
error taken out) on the same scale.

Usage: python benchmarks/bench_prior.py [--fleet N] [--new M]
"""

from __future__ import annotations

import argparse
import itertools
import tempfile
import warnings
from pathlib import Path

import numpy as np

from gyrocomp.calibration.compensate import apply
from gyrocomp.fleet import CalibrationStore, UnitRuns, fit_fleet, fit_with_prior, population_prior, prior_from_models
from gyrocomp.io.tables import write_recording
from gyrocomp.measures.merit import smoothed_residual_rms
from gyrocomp.models.fit import fit_channels
from gyrocomp.simulation import preset_model, resolve_profile, simulate

RUN_S, RATE_HZ, RUNS = 900.0, 10.0, 3
COVERAGES = {
    "a third (10..40 degC)": (10.0, 40.0),
    "half (2.5..47.5 degC)": (2.5, 47.5),
    "two thirds (-5..55 degC)": (-5.0, 55.0),
    "all (-20..70 degC)": (-20.0, 70.0),
}
TIME_FRACTIONS = (0.25, 0.5)
#: how the short run visits its range: the profile's name
DESIGNS = {"one way": "chamber", "there and back": "cycle"}


def drift(calibration, recording) -> float:
    compensated = apply(calibration, recording)
    window = int(60 * recording.rate_hz)
    return float(np.mean([smoothed_residual_rms(compensated.gyro_dps[:, j], window) for j in range(3)]))


def simulation(unit: int, seed: int, profile="chamber", duration_s: float = RUN_S):
    if isinstance(profile, str):
        return simulate("consumer", profile=profile, duration_s=duration_s, rate_hz=RATE_HZ, seed=seed, unit=unit)
    return simulate(preset_model("consumer", unit), profile=profile, duration_s=duration_s, rate_hz=RATE_HZ, seed=seed)


def run(unit: int, seed: int, profile="chamber", duration_s: float = RUN_S):
    return simulation(unit, seed, profile, duration_s).recording


def noise_floor(sim) -> float:
    """The held-out drift with the simulator's whole deterministic error taken out: the floor of any model."""
    left = sim.recording.gyro_dps - sum(sim.truth.components_dps.values())
    window = int(60 * sim.recording.rate_hz)
    return float(np.mean([smoothed_residual_rms(left[:, j], window) for j in range(3)]))


def fleet_prior(units: int, folder: Path):
    fleet = []
    for unit in range(units):
        paths = []
        for k in range(RUNS):
            path = folder / f"U{unit}_{k}.parquet"
            write_recording(run(unit, 1000 * unit + k), path)
            paths.append(str(path))
        fleet.append(UnitRuns(f"U{unit}", tuple(paths)))
    fit_fleet(fleet, folder / "FLEET", scheduler="local")
    with CalibrationStore(folder / "FLEET") as db:
        return population_prior(db.latest_rows())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fleet", type=int, default=200)
    parser.add_argument("--new", type=int, default=20)
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    with tempfile.TemporaryDirectory() as tmp:
        prior = fleet_prior(args.fleet, Path(tmp))
    print(
        f"prior from {prior.units} of {args.fleet} units; {args.new} new units; full calibration: "
        f"{RUNS} x {RUN_S / 60:.0f} min over -20..70 degC"
    )
    oracle = prior_from_models([preset_model("consumer", unit) for unit in range(50_000, 54_000)], like=prior)
    print(
        f"{'short run':15s} {'covers':26s} {'time':>6s}  {'prior: median (worst)':>22s}  "
        f"{'alone: median (worst)':>22s}  {'oracle: median (worst)':>23s}"
    )
    new = range(10_000, 10_000 + args.new)
    references = {}
    held_out = {}
    floors = []
    for unit in new:
        held = simulation(unit, 1000 * unit + 7)  # each unit its own noise: one seed for all would be one draw
        held_out[unit] = held.recording
        references[unit] = drift(fit_channels([run(unit, 1000 * unit + k) for k in range(RUNS)]), held_out[unit])
        floors.append(noise_floor(held) / references[unit])
    print(
        f"the held-out runs' noise alone (every deterministic error taken out): {np.median(floors):.2f}x "
        f"({max(floors):.2f}x) the full calibration's drift"
    )
    for (design, profile_name), (label, (low, high)) in itertools.product(DESIGNS.items(), COVERAGES.items()):
        profile = resolve_profile(profile_name, "consumer", set_points_degc=(low, high))
        for fraction in TIME_FRACTIONS:
            with_prior, alone, best = [], [], []
            for unit in new:
                short = run(unit, 1000 * unit + 9, profile, fraction * RUNS * RUN_S)
                with_prior.append(drift(fit_with_prior(short, prior), held_out[unit]) / references[unit])
                alone.append(drift(fit_channels(short), held_out[unit]) / references[unit])
                best.append(drift(fit_with_prior(short, oracle), held_out[unit]) / references[unit])
            print(
                f"{design:15s} {label:26s} {fraction:5.0%}   {np.median(with_prior):8.2f}x ({max(with_prior):5.2f}x)     "
                f"{np.median(alone):8.2f}x ({max(alone):5.2f}x)     {np.median(best):8.2f}x ({max(best):5.2f}x)"
            )


if __name__ == "__main__":
    main()
