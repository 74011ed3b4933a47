"""Coverage of the certificate's 95 % band over a simulated fleet.

Protocol (issue: the production line): for every simulator preset, ``--units`` units of its production spread;
each is fitted by gyrocomp's default fit on three chamber runs (as ``fleet fit`` does), its held-out residual
and band computed (:func:`gyrocomp.evaluation.held_out.held_out_residuals`), then a fourth run of the same unit
(another power-on, never seen) is compensated with the model and its residual r taken as the band's is (the
moving average over the same window, about its mean). Coverage: the fraction of the new run's samples with
|r| within the band, over every unit and axis; the target is 93..97 %.

    python benchmarks/bench_certificate_band.py [--units 40] [--rate 1]
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np

from gyrocomp import apply, fit
from gyrocomp.evaluation.held_out import held_out_residuals
from gyrocomp.measures.merit import smoothed_about_mean
from gyrocomp.simulation import PRESETS, simulate


def unit_coverage(preset: str, unit: int, rate_hz: float) -> list[float]:
    """Per axis, the fraction of a new run's residual within the band of ``unit``."""
    runs = [
        simulate(preset, profile="chamber", rate_hz=rate_hz, seed=100 * unit + k, unit=unit).recording for k in range(4)
    ]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        held = held_out_residuals(runs[:3])
        comp = apply(fit(runs[:3]), runs[3]).gyro_dps
    w = max(1, int(round(held.window_s * rate_hz)))
    return [
        float(np.mean(np.abs(smoothed_about_mean(comp[:, j], w)) <= held.axes[axis].band_dps))
        for j, axis in enumerate(runs[3].gyro_axes)
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--units", type=int, default=40)
    parser.add_argument("--rate", type=float, default=1.0)
    args = parser.parse_args()
    started = time.perf_counter()
    every = []
    for preset in PRESETS:
        cover = [c for u in range(args.units) for c in unit_coverage(preset, u, args.rate)]
        every += cover
        print(
            f"{preset}: {args.units} units: band covers {100 * np.mean(cover):.1f} % of the new runs' residual "
            f"(units' axes below 80 %: {sum(c < 0.8 for c in cover)} of {len(cover)})",
            flush=True,
        )
    print(
        f"fleet ({len(PRESETS)} presets x {args.units} units): {100 * np.mean(every):.1f} % "
        f"({time.perf_counter() - started:.0f} s)"
    )


if __name__ == "__main__":
    main()
