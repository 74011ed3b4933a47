"""Benchmark: the round trip to the vehicle. Simulated chamber runs -> fit (default, and --target for the firmware)
-> exported parameter file -> the firmware's correction as its source computes it (gyrocomp.export.firmware) on a
held-out run that leaves the calibrated range by 20 degC on both sides -> compared with gyrocomp apply of the same
model and with the simulator's truth.

For each part (the ``consumer`` preset: large tempco, 30 s lag; ``mti10``: small drift) and firmware (PX4,
ArduPilot): the drift left (RMS of the 60 s moving average of output minus true rate, about its mean, mean over
axes) [deg/s] by the raw output, by gyrocomp apply of the default model, by the firmware with the default model's
file, by the firmware with the --target model's file, and the largest difference between the firmware's correction
and apply of the --target model (about the mean for ArduPilot, whose constant is the boot-time offset).

The calibration runs span the part's range less 20 degC at each end, the held-out run the whole range: beyond the
calibrated range the firmware holds its correction at the edge, gyrocomp's default continues the curve along its
tangent, which is most of what separates the two on a part with a large tempco. Calibrate over the temperatures the
vehicle will see.

Usage: python benchmarks/bench_firmware.py [--markdown FILE]   (``--markdown docs/firmware.md`` writes the page)
"""

from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path

import numpy as np

from gyrocomp import __version__, apply
from gyrocomp.export.autopilot import ardupilot_parameters, px4_parameters
from gyrocomp.export.firmware import ardupilot_gyro_correction_dps, px4_as_run, px4_gyro_correction_dps
from gyrocomp.measures.merit import smoothed_residual_rms
from gyrocomp.models.joint import fit_calibration
from gyrocomp.simulation import get_preset, get_profile, simulate

RATE_HZ = 2.0
WINDOW = int(60 * RATE_HZ)
STEPS = """## On the vehicle

PX4 (`gyrocomp export model.json --format px4 -o thermal.params --device-id ID`):

1. Load the file in QGroundControl (Vehicle Setup > Parameters > Tools > Load from file). `TC_G0_ID` must be the
   gyro's device id (the ULog's `sensor_gyro`, `listener sensor_gyro`, or `CAL_GYRO0_ID`): a model fitted on a
   ULog carries it, otherwise the export asks for `--device-id`.
2. Reboot: `TC_G_ENABLE` / `TC_A_ENABLE` take effect at start-up.
3. PX4 subtracts `CAL_GYRO*_XOFF/YOFF/ZOFF` after the thermal offsets: calibrate the gyro again (or zero them);
   calibrate the accelerometer again after loading `TC_A*`.
4. Outside TMIN..TMAX PX4 holds the correction at its edge, and it updates it at 1 Hz only after the
   temperature moved by more than 1 degC: the figures below are as it runs.

ArduPilot (`gyrocomp export model.json --format ardupilot -o thermal.parm`):

1. Set `INS_TCAL1_ENABLE = 1` first (the `INS_TCAL1_*` group is hidden until then): load the file, refresh the
   parameters, load it again.
2. Reboot.
3. `INS_GYR1_CALTEMP` must hold a valid temperature (calibrate the gyro once); the boot-time gyro offset is taken
   without this correction: keep the vehicle still at boot.
4. Outside TMIN..TMAX ArduPilot holds the correction at its edge.

`gyrocomp fit RUNS -o m.json --target px4|ardupilot` fits the best model the firmware carries, so that
`gyrocomp apply` computes what the vehicle will; the default model (lag, hysteresis, higher orders) is better where
the firmware can carry it, and the export prints what the file loses against it.

Checking it: `gyrocomp report MODEL RUNS -o r.html` has an "On the autopilot" section (the PX4 and ArduPilot files
exported from the model, applied to each run as each firmware applies them, beside the model), and after a flight
`gyrocomp evaluate MODEL flight.ulg --installed` judges the calibration the vehicle holds, applied as its firmware
applies it (PX4: only the `TC_Gn` slot whose id is the logged gyro's, stepped at 1 Hz / 1 degC; ArduPilot: relative
to `INS_GYRn_CALTEMP`; a parameter left out has the firmware's default: PX4 TMIN/TMAX 0/100 degC, TREF 25 degC,
ArduPilot 0/70 degC).
"""


def drift(series: np.ndarray) -> float:
    return float(np.mean([smoothed_residual_rms(series[:, j], WINDOW) for j in range(series.shape[1])]))


def firmware_output(cal, target: str, held) -> np.ndarray:
    rec = held.recording
    if target == "px4":
        params = px4_parameters(cal, device_id=1).values
        correction = px4_as_run(params, rec.time_s, rec.temperature_degc)
    else:
        params = ardupilot_parameters(cal).values
        lo, hi = params["INS_TCAL1_TMIN"], params["INS_TCAL1_TMAX"]
        correction = ardupilot_gyro_correction_dps(params, rec.temperature_degc, 0.5 * (lo + hi))
    return rec.gyro_dps - correction


def case(preset: str, target: str) -> list[str]:
    lo, hi = get_preset(preset).set_points_degc
    fit = [
        simulate(
            preset, profile=get_profile("cycle", set_points_degc=(lo + 20, hi - 20), cycles=1), rate_hz=RATE_HZ, seed=s
        ).recording
        for s in range(3)
    ]
    held = simulate(preset, profile=get_profile("cycle", set_points_degc=(lo, hi), cycles=1), rate_hz=RATE_HZ, seed=99)
    truth = held.truth.true_rate_dps
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        default = fit_calibration(fit)
        carried = fit_calibration(fit, target=target)
        ours = apply(default, held.recording).gyro_dps
        ours_target = apply(carried, held.recording).gyro_dps
        fw_default = firmware_output(default, target, held)
        fw_target = firmware_output(carried, target, held)
    # the firmware as a function of temperature (PX4 without its republish steps), against apply
    static = (
        held.recording.gyro_dps
        - px4_gyro_correction_dps(px4_parameters(carried, device_id=1).values, held.recording.temperature_degc)
        if target == "px4"
        else fw_target
    )
    gap = static - ours_target
    gap = gap - gap.mean(axis=0) if target == "ardupilot" else gap
    return [
        preset,
        target,
        f"{drift(held.recording.gyro_dps - truth):.4g}",
        f"{drift(ours - truth):.4g}",
        f"{drift(fw_default - truth):.4g}",
        f"{drift(fw_target - truth):.4g}",
        default.model,
        carried.model,
        f"{np.max(np.abs(gap)):.2g}",
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--markdown", type=Path)
    args = parser.parse_args()
    start = time.perf_counter()
    header = [
        "part",
        "firmware",
        "raw",
        "gyrocomp apply (default)",
        "firmware, default's file",
        "firmware, --target file",
        "default model",
        "--target model",
        "max |firmware - apply| (target)",
    ]
    rows = [case(p, t) for p in ("consumer", "mti10") for t in ("px4", "ardupilot")]
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)] + ["| " + " | ".join(r) + " |" for r in rows]
    print("\n".join(lines))
    print(f"({time.perf_counter() - start:.0f} s)")
    if args.markdown:
        page = [
            "# Loading it into PX4 / ArduPilot",
            "",
            f"Generated by `python benchmarks/bench_firmware.py --markdown docs/firmware.md` (gyrocomp {__version__},"
            f" {time.strftime('%Y-%m-%d')}); do not edit by hand.",
            "",
            STEPS,
            "## The round trip, measured",
            "",
            *__doc__.split("\n\nUsage:")[0].split("\n")[2:],
            "",
            "Drift left on the held-out run [deg/s]:",
            "",
            *lines,
        ]
        args.markdown.write_text("\n".join(page) + "\n")


if __name__ == "__main__":
    main()
