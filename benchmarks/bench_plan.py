"""Benchmark: are gyrocomp plan's predictions honest? (issue #73)

Parts from the shape zoo (``benchmarks/shape_zoo.py``: seven thermal memories written from the physics, none of
gyrocomp's model forms, on one tanh-shaped body behind a 25 s lag with white noise and a slow random walk) and the
shape matrix's chamber part (``tools/shape_matrix.chamber_run``: a tanh behind a 40 s lag and a term in the rate of
change). For each part and seed:

1. two heat-cool runs 20 -> 50 -> 20 degC at 1 degC/min (10 min holds, 2 Hz), fitted by default;
2. a held-out run of the same part, in one of two use cases: ``in range`` (20 -> 50 -> 20 degC at 1.5 degC/min:
   another ramp rate) or ``wider`` (10 -> 60 -> 10 degC at 1 degC/min: past both ends);
3. ``gyrocomp.plan`` with the held-out run's temperatures as the use profile (the default call);
4. **now**: the drift the model leaves on the held-out run (the RMS about its mean of the 60 s moving average of
   the output, the part being still), against the forecast's 95 % interval;
5. **after**: the recommended run (the best gain per hour) recorded from the same part's physics as the plan
   programs it (set points, ramp, holds), the three runs fitted by default, and the drift that fit leaves on the
   held-out run, against the interval the plan predicted after that run.

And the shared real recordings (skipped when absent): the CATS tag's three static periods (each predicted from the
other two, at 60 s and at the dataset's 600 s window) and the real one-cycle chamber log (fitted up to its hottest
point, the final cooling leg predicted), the forecast against the drift the default fit leaves.

Per part and use case the table gives the share of axes inside the interval (now, after), the median ratio of the
forecast to the drift (now, after) and the runs recommended. Usage:
``python benchmarks/bench_plan.py [--seeds 10] [--markdown FILE]``.
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from collections import Counter
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from benchmarks.shape_zoo import FORMS, zoo_run  # noqa: E402  (memories written from the physics)
from tools.shape_matrix import chamber_run  # noqa: E402  (the shape matrix's chamber part)

from gyrocomp import __version__, apply, fit  # noqa: E402
from gyrocomp.evaluation.drift_forecast import UseProfile, forecast_drift  # noqa: E402
from gyrocomp.evaluation.run_advice import plan  # noqa: E402
from gyrocomp.measures.merit import smoothed_residual_rms  # noqa: E402

RATE_HZ = 2.0
HOLD_S = 600.0
TRAIN = ((20.0, 50.0, 20.0), 1.0)
USE_CASES = {"in range": ((20.0, 50.0, 20.0), 1.5), "wider": ((10.0, 60.0, 10.0), 1.0)}
PHYSICS_CHAMBER = "chamber part (tanh, 40 s lag, dT/dt)"


def part_run(part: str, points, ramp: float, hold_s: float, seed: int):
    """A still run of ``part`` through the chamber's set points ``points`` [degC] at ``ramp`` [degC/min]."""
    if part == PHYSICS_CHAMBER:
        return chamber_run(list(points), ramp_degc_per_min=ramp, hold_s=hold_s, rate_hz=RATE_HZ, seed=seed)
    return zoo_run(part, list(points), ramp, hold_s=hold_s, rate_hz=RATE_HZ, seed=seed).recording


def drift(calibration, recording) -> dict[str, float]:
    """The drift the model leaves on a still run, per axis [deg/s]."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        out = apply(calibration, recording)
    return {a: smoothed_residual_rms(out.gyro(a), int(60 * RATE_HZ)) for a in calibration.axes}


def one_case(part: str, case: str, seed: int) -> dict:
    """The forecast now and after the recommended run, against the drift, for one part, use case and seed."""
    train = [part_run(part, TRAIN[0], TRAIN[1], HOLD_S, 100 * seed + k) for k in range(2)]
    held = part_run(part, *USE_CASES[case], HOLD_S, 100 * seed + 7)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = fit(train)
        advised = plan(model, train, UseProfile.of(held))
        best = advised.advice[0]
        recorded = part_run(part, best.run.set_points_degc, best.run.ramp_degc_per_min, best.run.hold_s, 100 * seed + 3)
        refit = fit(train + [recorded])
    now, after = drift(model, held), drift(refit, held)
    rows = []
    for axis, f in advised.now.axes.items():
        g = best.after.axes[axis]
        rows.append(
            (
                f.low_dps <= now[axis] <= f.high_dps,
                g.low_dps <= after[axis] <= g.high_dps,
                f.drift_dps / now[axis],
                g.drift_dps / after[axis],
            )
        )
    return {"rows": rows, "run": best.run.name}


def real_rows() -> list[str]:
    """The forecast against the drift on the shared real recordings, one row per recording and window."""
    from tests.real import real_data

    rows = []
    if real_data.CATS.exists():
        runs = real_data.cats_runs()
        for window in (60.0, float(real_data.CATS_WINDOW_S)):
            inside, ratios = [], []
            for held in range(len(runs)):
                train = [r for k, r in enumerate(runs) if k != held]
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    model = fit(train)
                    forecast = forecast_drift(model, train, UseProfile.of(runs[held]), window_s=window)
                    out = apply(model, runs[held])
                for axis, f in forecast.axes.items():
                    actual = smoothed_residual_rms(out.gyro(axis), int(window * runs[held].rate_hz))
                    inside.append(f.low_dps <= actual <= f.high_dps)
                    ratios.append(f.drift_dps / actual)
            rows.append(
                f"| CATS, each static period from the other two | {window:g} s | {sum(inside)} of {len(inside)} | "
                f"{np.median(ratios):.2f} |"
            )
    if real_data.TOFUPILOT.exists():
        log = real_data.tofupilot_run()
        hot = int(np.argmax(log.temperature_degc))
        train, held = log.take(np.arange(hot + 1)), log.take(np.arange(hot + 1, log.n_samples))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            model = fit([train])
            forecast = forecast_drift(model, [train], UseProfile.of(held))
            left = apply(model, log).gyro_dps[hot + 1 :]
        inside, ratios = [], []
        for axis, f in forecast.axes.items():
            actual = smoothed_residual_rms(left[:, log.gyro_axes.index(axis)], int(60 * log.rate_hz))
            inside.append(f.low_dps <= actual <= f.high_dps)
            ratios.append(f.drift_dps / actual)
        rows.append(
            f"| one-cycle log, the final cooling leg | 60 s | {sum(inside)} of {len(inside)} | {np.median(ratios):.2f} |"
        )
    return rows


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--parts", default="", help="comma-separated part names (default: all)")
    parser.add_argument("--markdown", type=Path, default=None)
    parser.add_argument("--only", choices=("zoo", "real"), default=None, help="one section of the two")
    args = parser.parse_args(argv)
    parts = [p for p in (*FORMS, PHYSICS_CHAMBER) if not args.parts or p in args.parts.split(",")]
    lines = [
        f"gyrocomp {__version__}, {args.seeds} seeds, default fit and plan; 95 % intervals",
        "",
        "| part | use | inside now | inside after | forecast/drift now | forecast/drift after | runs recommended |",
        "|---|---|---|---|---|---|---|",
    ]
    totals = {"now": [], "after": []}
    started = time.perf_counter()
    for part in parts if args.only != "real" else ():
        for case in USE_CASES:
            rows, runs = [], Counter()
            for seed in range(args.seeds):
                result = one_case(part, case, seed)
                rows += result["rows"]
                runs[result["run"]] += 1
            now_in, after_in, now_ratio, after_ratio = map(np.array, zip(*rows))
            totals["now"] += list(now_in)
            totals["after"] += list(after_in)
            lines.append(
                f"| {part} | {case} | {now_in.mean():.0%} | {after_in.mean():.0%} | {np.median(now_ratio):.2f} | "
                f"{np.median(after_ratio):.2f} | {', '.join(f'{k} {v}' for k, v in runs.most_common())} |"
            )
            print(lines[-1], flush=True)
    if totals["now"]:
        lines += [
            "",
            f"All: inside now {np.mean(totals['now']):.0%} of {len(totals['now'])} axes, inside after "
            f"{np.mean(totals['after']):.0%}",
        ]
        print(lines[-1])
    if args.only != "zoo":
        lines += ["", "| real recording | window | inside | forecast/drift (median) |", "|---|---|---|---|"]
        lines += real_rows()
        print("\n".join(lines[-3:]))
    lines.append(f"\n{time.perf_counter() - started:.0f} s")
    if args.markdown is not None:
        args.markdown.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
