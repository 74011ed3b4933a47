"""Benchmark: how many still minutes the online learner needs (issue #16, ``gyrocomp.OnlineCalibrator``).

For each part (a preset and unit of its production spread), ten one-hour simulated field logs (power-on at room
temperature, warm-up by self-heating, still about a third of the time, turning, shaking and accelerating in
between) are replayed through the learner one log after the other. After each log the learner's model is judged on
a held-out chamber run (20..45 degC; the mean over the axes of the RMS of the 60 s moving average of the compensated
rate, the same figure as the field-fit test) against:

- ``chamber``: the default ``gyrocomp fit`` on three one-hour chamber runs of the same part over the same range;
- ``field``: the default ``gyrocomp fit`` on the still segments of all ten logs (batch, ``--still-only``).

Printed per part: the still minutes the learner had accepted after each log and its held-out drift, and the still
minutes after which it stays within 1.5x of the chamber model (the issue's bar) and within 1.1x of the batch field
model. Also the learner's throughput [samples/s] (Python, whole logs at once).

Usage: python benchmarks/bench_learner.py [--parts consumer:3:25,consumer:7:25,adxrs450:0:10]
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np

from gyrocomp.calibration.compensate import apply
from gyrocomp.measures.merit import smoothed_residual_rms
from gyrocomp.models.field import field_recordings
from gyrocomp.fitting.online import OnlineCalibrator, replay
from gyrocomp.models.fit import fit_channels
from gyrocomp.simulation import get_profile, resolve_profile, simulate

LOGS = 10


def drift(calibration, recording) -> float:
    compensated = recording if calibration is None else apply(calibration, recording)
    return float(
        np.mean(
            [
                smoothed_residual_rms(compensated.gyro_dps[:, j], int(60 * recording.rate_hz))
                for j in range(compensated.gyro_dps.shape[1])
            ]
        )
    )


def first_staying_within(values: list[float], minutes: list[float], bound: float) -> float | None:
    """The still minutes from which every later model is within ``bound`` (None: never)."""
    for k in range(len(values)):
        if all(v <= bound for v in values[k:]):
            return minutes[k]
    return None


def part(preset: str, unit: int, rate_hz: float) -> None:
    logs = [
        simulate(
            preset, profile=get_profile("field", motion_seed=k), rate_hz=rate_hz, seed=100 + k, unit=unit
        ).recording
        for k in range(LOGS)
    ]
    profile = resolve_profile("chamber", preset, set_points_degc=(20.0, 45.0))
    held = simulate(preset, profile=profile, rate_hz=rate_hz, duration_s=3600, seed=300, unit=unit).recording
    chamber = fit_channels(
        [
            simulate(preset, profile=profile, rate_hz=rate_hz, duration_s=3600, seed=200 + k, unit=unit).recording
            for k in range(3)
        ]
    )
    field = fit_channels(field_recordings(logs)[0])
    reference = {"raw": drift(None, held), "chamber": drift(chamber, held), "field": drift(field, held)}
    learner = OnlineCalibrator(rate_hz)
    minutes, values, seconds = [], [], 0.0
    for rec in logs:
        start = time.perf_counter()
        replay(learner, [rec])
        seconds += time.perf_counter() - start
        status = learner.status
        minutes.append(status.still_s / 60)
        values.append(drift(learner.to_calibration(axes=held.gyro_axes), held) if status.degree > 0 else np.inf)
    print(
        f"\n{preset} unit {unit} at {rate_hz:g} Hz: raw {reference['raw']:.4f}, chamber {reference['chamber']:.4f}, "
        f"batch field fit {reference['field']:.4f} deg/s"
    )
    print("  after log  still [min]  learner [deg/s]  / chamber")
    for k, (m, v) in enumerate(zip(minutes, values), start=1):
        print(f"  {k:9d}  {m:11.1f}  {v:15.4f}  {v / reference['chamber']:9.2f}")
    for label, bound in (("1.5x chamber", 1.5 * reference["chamber"]), ("1.1x batch field", 1.1 * reference["field"])):
        reached = first_staying_within(values, minutes, bound)
        print(f"  within {label} from {'never' if reached is None else f'{reached:.0f} still minutes'}")
    samples = sum(rec.n_samples for rec in logs)
    print(f"  learner: lag {learner.lag_time_constant_s:g} s, {samples / seconds:,.0f} samples/s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--parts", default="consumer:3:25,consumer:7:25,adxrs450:0:10", help="preset:unit:rate_hz, comma-separated"
    )
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    for item in args.parts.split(","):
        preset, unit, rate = item.split(":")
        part(preset, int(unit), float(rate))


if __name__ == "__main__":
    main()
