"""Every command on every shape of input: runs written from the physics (not from gyrocomp's model forms) in many
shapes, each unit's runs through the whole command line, each call classed as ``ok`` (it succeeded and what it
wrote passed its invariant), ``refused`` (one line naming the file, run or option, exit 2) or ``failure`` (an
internal error, a traceback, a message of several lines, or an invariant broken).

The physics (:func:`chamber_run`): a chamber steps through set points at a ramp rate, holding at each; the die
follows through a first-order lag of 40 s; each axis's bias is a saturating curve (tanh) of the die's temperature,
a term in its rate of change and a power-on constant, with white noise; the temperature is reported in steps of
1/16 degC. The shapes vary what a user's runs vary: the legs (heating only, cooling only, a hold, one or several
cycles of other ramp rates), the length (a few windows to hours), the accelerometer (none, one pose, several), the
temperature (quantized coarsely, constant, beyond the fit's range), the clock (from 0 or the Unix epoch in s, ms,
us or ns, with gaps), the file format, and the number of runs.

Usage: python tools/shape_matrix.py [--shapes NAME,...] [--markdown FILE]  (the table in docs/reliability.md)
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import subprocess
import sys
import tempfile
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pandas as pd

from gyrocomp.io.tables import write_recording
from gyrocomp.recording import ACCEL_AXES, GYRO_AXES, Recording


def chamber_run(
    legs_degc: list[float],
    ramp_degc_per_min: float = 1.0,
    hold_s: float = 600.0,
    rate_hz: float = 10.0,
    seed: int = 0,
    start_s: float = 0.0,
) -> Recording:
    """A chamber run written from the physics alone, none of gyrocomp's model forms: the chamber steps through the
    set points ``legs_degc`` [degC] at ``ramp_degc_per_min``, holding ``hold_s`` [s] at each (one set point: a
    hold only); the die follows it through a first-order lag of 40 s, and each axis's bias is a saturating curve
    of the die's temperature (a tanh), a term in its rate of change (a gradient across the package) and a power-on
    constant, with white noise of 0.005 deg/s/sqrt(Hz); the temperature is reported in steps of 1/16 degC.
    ``start_s``: the first time stamp [s] (an epoch, say)."""
    rng = np.random.default_rng(seed)
    knots_t, knots_v = [0.0], [legs_degc[0]]
    for target in legs_degc[1:]:
        knots_t.append(knots_t[-1] + hold_s)
        knots_v.append(knots_v[-1])
        knots_t.append(knots_t[-1] + abs(target - knots_v[-1]) / ramp_degc_per_min * 60.0)
        knots_v.append(target)
    knots_t.append(knots_t[-1] + hold_s)
    knots_v.append(knots_v[-1])
    t = np.arange(0.0, knots_t[-1], 1.0 / rate_hz)
    chamber = np.interp(t, knots_t, knots_v)
    alpha = 1.0 - math.exp(-1.0 / (rate_hz * 40.0))
    die = np.empty_like(chamber)
    die[0] = chamber[0]
    for k in range(1, t.size):  # the die lags the chamber (first order, 40 s)
        die[k] = die[k - 1] + alpha * (chamber[k] - die[k - 1])
    rate_degc_per_s = np.gradient(die, t)
    gains = np.array([[0.05, 0.4], [-0.03, 0.2], [0.08, -0.5]])  # [deg/s], [deg/s per degC/s] per axis
    bias = np.column_stack(
        [g * np.tanh((die - 25.0) / 20.0) + r * rate_degc_per_s + rng.normal(0, 0.01) for g, r in gains]
    )
    gyro = bias + rng.standard_normal(bias.shape) * 0.005 * math.sqrt(rate_hz)
    return Recording(
        time_s=t + start_s,
        gyro_dps=gyro,
        gyro_axes=GYRO_AXES,
        temperature_degc=np.round(die * 16.0) / 16.0,
        source=f"chamber_run_{seed}",
    )


def _with_accel(rec: Recording, poses: int, seed: int) -> Recording:
    """The run with an accelerometer at rest: one pose (z up) or ``poses`` orientations held in turn, and each
    gyro axis 0.02 deg/s per g of the specific force along it (a g-sensitivity)."""
    rng = np.random.default_rng(seed)
    ups = [(0, 0, 1), (0, 0, -1), (1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0)][: max(1, poses)]
    which = np.minimum(np.arange(rec.n_samples) * len(ups) // rec.n_samples, len(ups) - 1)
    accel = np.asarray(ups, dtype=float)[which] + rng.standard_normal((rec.n_samples, 3)) * 1e-3
    return replace(rec, gyro_dps=rec.gyro_dps + 0.02 * accel, accel_g=accel, accel_axes=ACCEL_AXES)


@dataclass(frozen=True)
class Shape:
    """One shape of a unit's runs: how to make them, the file format they are written in, the time's unit (for a
    clock in integer ticks), and a note of what it is."""

    runs: Callable[[], list[Recording]]
    fmt: str = "csv"
    time_unit: str = "s"
    note: str = ""


def _legs(*legs, **kw) -> Callable[[], list[Recording]]:
    return lambda: [chamber_run(list(leg), seed=k, **kw) for k, leg in enumerate(legs)]


def _edit(make: Callable[[], list[Recording]], edit: Callable[[Recording, int], Recording]):
    return lambda: [edit(rec, k) for k, rec in enumerate(make())]


_CYCLE = [20, 50, 20]
_TWO = [20, 50, 20, 50, 20]

SHAPES: dict[str, Shape] = {
    "heating only": Shape(_legs([20, 50], [20, 50], hold_s=120), note="two runs, each one rising leg"),
    "cooling only": Shape(_legs([50, 20], [50, 20], hold_s=120), note="two runs, each one falling leg"),
    "a hold only": Shape(_legs([25], [25], hold_s=900), note="two runs at one set point"),
    "one cycle": Shape(_legs(_CYCLE, hold_s=300, ramp_degc_per_min=2), note="one run, heat then cool"),
    "two cycles": Shape(_legs(_TWO, hold_s=300, ramp_degc_per_min=2), note="one run, two heat-cool cycles"),
    "cycle and a leg": Shape(
        lambda: [chamber_run(_CYCLE, 2, 300, seed=1), chamber_run([20, 50], 1, 300, seed=2)],
        note="a heat-cool cycle and one heating leg (the certificate's case)",
    ),
    "other ramp rates": Shape(
        lambda: [chamber_run(_CYCLE, 0.5, 300, 2, seed=1), chamber_run(_CYCLE, 3, 300, 2, seed=2)],
        note="two cycles at 0.5 and 3 degC/min",
    ),
    "three runs": Shape(_legs(_CYCLE, _CYCLE, _CYCLE, hold_s=300, ramp_degc_per_min=3, rate_hz=5)),
    "cycles of other lengths": Shape(
        lambda: [chamber_run([20, 60, 20, 40, 20], 2, 200, 5, seed=1), chamber_run([10, 30, 10], 1, 600, 5, seed=2)]
    ),
    "very short": Shape(_legs([24, 26], [26, 24], hold_s=20, rate_hz=2), note="two runs of a few windows"),
    "long": Shape(_legs(_TWO + [50, 20], hold_s=1800, ramp_degc_per_min=1, rate_hz=20), note="5.6 h at 20 Hz"),
    "one pose": Shape(_edit(_legs(_CYCLE, _CYCLE, hold_s=300, ramp_degc_per_min=2), lambda r, k: _with_accel(r, 1, k))),
    "six poses": Shape(
        _edit(_legs(_CYCLE, _CYCLE, hold_s=300, ramp_degc_per_min=2), lambda r, k: _with_accel(r, 6, k))
    ),
    "whole degrees": Shape(
        _edit(
            _legs(_CYCLE, _CYCLE, hold_s=300, ramp_degc_per_min=2),
            lambda r, k: replace(r, temperature_degc=np.round(r.temperature_degc)),
        ),  # fmt: skip
        note="temperature in whole degrees",
    ),
    "constant temperature": Shape(
        _edit(_legs([25], [25], hold_s=900), lambda r, k: replace(r, temperature_degc=np.full(r.n_samples, 25.0)))
    ),
    "beyond the range": Shape(
        lambda: [chamber_run([20, 40, 20], 2, 300, seed=1), chamber_run([30, 70, 30], 2, 300, seed=2)],
        note="the applied run spans beyond the fitted one",
    ),
    "epoch s": Shape(_legs(_CYCLE, _CYCLE, hold_s=300, ramp_degc_per_min=2, start_s=1.7345e9)),
    "epoch ms": Shape(_legs(_CYCLE, _CYCLE, hold_s=300, ramp_degc_per_min=2, start_s=1.7345e9), time_unit="ms"),
    "epoch us": Shape(_legs(_CYCLE, _CYCLE, hold_s=300, ramp_degc_per_min=2, start_s=1.7345e9), time_unit="us"),
    "epoch ns": Shape(_legs(_CYCLE, _CYCLE, hold_s=300, ramp_degc_per_min=2, start_s=1.7345e9), time_unit="ns"),
    "gaps": Shape(
        _edit(
            _legs(_CYCLE, _CYCLE, hold_s=300, ramp_degc_per_min=2),
            lambda r, k: r.take((np.arange(r.n_samples) % 3000) >= 200),
        ),  # fmt: skip
        note="20 s missing every 300 s",
    ),
    "tsv": Shape(_legs(_CYCLE, _CYCLE, hold_s=300, ramp_degc_per_min=2), fmt="tsv"),
    "parquet": Shape(_legs(_CYCLE, _CYCLE, hold_s=300, ramp_degc_per_min=2), fmt="parquet"),
    "csv.gz": Shape(_legs(_CYCLE, _CYCLE, hold_s=300, ramp_degc_per_min=2), fmt="csv.gz"),
    "one axis": Shape(
        _edit(
            _legs(_CYCLE, _CYCLE, hold_s=300, ramp_degc_per_min=2),
            lambda r, k: replace(r, gyro_dps=r.gyro_dps[:, 2:], gyro_axes=("gyro_z",)),
        )  # fmt: skip
    ),
    "1 Hz": Shape(_legs(_CYCLE, _CYCLE, hold_s=300, ramp_degc_per_min=2, rate_hz=1)),
    "200 Hz": Shape(_legs([20, 35, 20], [20, 35, 20], hold_s=120, ramp_degc_per_min=3, rate_hz=200)),
    "cold": Shape(_legs([-40, -10, -40], [-40, -10, -40], hold_s=300, ramp_degc_per_min=2), note="below zero"),
    "one run one leg": Shape(_legs([20, 50], hold_s=300), note="a single heating leg"),
    "heat then hold": Shape(_legs([20, 50, 50], [20, 50, 50], hold_s=600, ramp_degc_per_min=2)),
}


def write_runs(shape: Shape, folder: Path) -> list[Path]:
    """The shape's runs written into ``folder`` in its format (a clock in ticks: integer ticks since the epoch)."""
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    ticks = {"s": None, "ms": 10**3, "us": 10**6, "ns": 10**9}[shape.time_unit]
    for k, rec in enumerate(shape.runs()):
        path = folder / f"run_{k + 1}.{shape.fmt}"
        if ticks is None:
            write_recording(rec, path)
        else:
            plain = folder / f"run_{k + 1}.tmp.csv"
            write_recording(rec, plain)
            frame = pd.read_csv(plain)
            frame["time"] = np.round(rec.time_s * ticks).astype(np.int64)  # integer ticks since the epoch
            frame.to_csv(path, index=False)
            plain.unlink()
        paths.append(path)
    return paths


@dataclass(frozen=True)
class Call:
    """One command's call on a shape: its name, its result (``ok``, ``refused``, ``failure``) and why."""

    command: str
    result: str
    detail: str = ""


def classify(name: str, done: subprocess.CompletedProcess, check_exit: bool = False) -> Call:
    """``ok`` on exit 0; ``refused`` on exit 2 (``check``: 1 too) with one line on stderr starting ``gyrocomp:``;
    else ``failure`` (an internal error, a traceback, a refusal of several lines)."""
    err = done.stderr.strip()
    errors = [line for line in err.splitlines() if line.startswith("gyrocomp: error") or "internal error" in line]
    if "Traceback" in err or "internal error" in err:
        return Call(name, "failure", err.splitlines()[-1][:300] if err else "")
    if done.returncode == 0:
        return Call(name, "ok")
    if done.returncode == 2 and len(errors) == 1:
        return Call(name, "refused", errors[0][:300])
    if check_exit and done.returncode == 1:
        return Call(name, "refused", done.stdout.strip().splitlines()[0][:300] if done.stdout.strip() else "")
    return Call(name, "failure", f"exit {done.returncode}: {err[-300:]}")


def _invariant(call: Call, holds: bool, why: str) -> Call:
    return call if call.result != "ok" or holds else Call(call.command, "failure", why)


def run_shape(name: str, shape: Shape, folder: Path, run) -> list[Call]:
    """Every command on the shape's runs (``run``: a function running ``gyrocomp ARGS`` and returning its
    :class:`subprocess.CompletedProcess`); each call classed and, where it succeeded, its invariant checked."""
    runs = write_runs(shape, folder / "data")
    out = folder / "out"
    out.mkdir(exist_ok=True)
    unit = ["--time-unit", shape.time_unit] if shape.time_unit != "s" else []
    calls = [classify("check", run("check", *runs, *unit), check_exit=True)]
    model = out / "m.json"
    fitted = classify("fit", run("fit", *runs, *unit, "-o", model))
    calls.append(fitted)
    for family, args in (
        ("rate+lag", ("--hysteresis", "rate+lag")),
        ("turning-table", ("--hysteresis", "turning-table")),
        ("play-bank", ("--hysteresis", "play-bank")),
        ("table", ("--temperature", "table")),
    ):
        calls.append(classify(f"fit {family}", run("fit", *runs, *unit, *args, "-o", out / f"m-{family}.json")))
    state = out / "learner.json"
    learned = classify("learn", run("learn", *runs, *unit, "-o", out / "learned.json", "--save-state", state))
    calls.append(learned)
    if learned.result == "ok":
        calls.append(
            classify("learn --resume", run("learn", runs[-1], *unit, "--resume", state, "-o", out / "again.json"))
        )
    calls.append(classify("noise", run("noise", runs[0], *unit)))
    calls.append(classify("allan", run("allan", runs[0], *unit, "--json")))
    converted = out / "run.parquet"
    conv = classify("convert", run("convert", runs[0], converted, *unit))
    calls.append(conv)
    for by in ("gap", "temperature-turn", "still", "power-on"):
        calls.append(classify(f"split --by {by}", run("split", runs[0], *unit, "-o", out / f"split-{by}", "--by", by)))
    if len(runs) >= 2:
        calls.append(classify("validate", run("validate", *runs, *unit)))
    calls += _fleet(runs, unit, out, run)
    if fitted.result != "ok":
        return calls
    calls.append(classify("show", run("show", model)))
    table = out / f"comp.{shape.fmt if shape.fmt != 'tsv' else 'tsv'}"
    applied = classify("apply", run("apply", model, runs[-1], *unit, "-o", table))
    if applied.result == "ok":
        applied = _invariant(applied, *_same_as_library(model, runs[-1], table, shape.time_unit))
    calls.append(applied)
    if conv.result == "ok":  # apply to the converted Parquet equals apply to the table it came from
        again = out / "comp_of_parquet.parquet"
        ok = classify("apply (converted)", run("apply", model, converted, "-o", again))
        calls.append(ok)
    calls.append(classify("evaluate", run("evaluate", model, runs[-1], *unit, "--json")))
    calls.append(classify("report", run("report", model, runs[-1], *unit, "-o", out / "r.html")))
    calls.append(
        classify("export px4", run("export", model, "--format", "px4", "--device-id", "1", "-o", out / "p.params"))
    )
    calls.append(classify("export ardupilot", run("export", model, "--format", "ardupilot", "-o", out / "a.parm")))
    calls.append(classify("export c", run("export", model, "--format", "c", "--rate", "10", "-o", out / "c")))
    return calls


def _fleet(runs: list[Path], unit: list[str], out: Path, run) -> list[Call]:
    """The shape's runs as one unit of a fleet: fleet fit into a folder, then the unit's certificate (which
    reads its runs again for the held-out residual), checked to name the unit and its verdict."""
    manifest = out / "manifest.csv"
    manifest.write_text("path,serial\n" + "".join(f"{p},SN1\n" for p in runs), encoding="utf-8")
    fleet = out / "FLEET"
    fitted = classify(
        "fleet fit", run("fleet", "fit", "--manifest", manifest, *unit, "-o", fleet, "--scheduler", "serial")
    )
    if fitted.result != "ok":
        return [fitted]
    calls = [fitted, classify("fleet show", run("fleet", "show", "SN1", "--store", fleet))]
    calls.append(classify("fleet report", run("fleet", "report", fleet, "-o", out / "fleet.html")))
    page = out / "cert.html"
    cert = classify("fleet certificate", run("fleet", "certificate", "SN1", "--store", fleet, *unit, "-o", page))
    if cert.result == "ok":
        text = page.read_text(encoding="utf-8")
        cert = _invariant(cert, "SN1" in text and "verdict" in text, "the certificate names no unit or verdict")
    return [*calls, cert]


def _same_as_library(model: Path, run_path: Path, table: Path, time_unit: str) -> tuple[bool, str]:
    """Whether the command's compensated table equals :func:`gyrocomp.apply` on the same run to 1e-9 deg/s."""
    import warnings

    from gyrocomp import Calibration, apply, read

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        expected = apply(Calibration.load(model), read(run_path, time_unit=time_unit))
        got = read(table, time_unit=time_unit)
    if got.n_samples != expected.n_samples:
        return False, f"apply wrote {got.n_samples} rows for {expected.n_samples}"
    worst = float(np.max(np.abs(got.gyro_dps - expected.gyro_dps)))
    return worst <= 1e-9, f"apply differs from the library's by {worst:.3g} deg/s"


def _subprocess_run(*args) -> subprocess.CompletedProcess:
    script = Path(sys.executable).parent / "gyrocomp"
    cmd = [str(script)] if script.exists() else [sys.executable, "-m", "gyrocomp"]
    env = {**os.environ, "COLUMNS": "200", "GYROCOMP_NO_CONFIG": "1"}
    return subprocess.run([*cmd, *map(str, args)], capture_output=True, text=True, env=env, timeout=600)


def markdown(results: dict[str, list[Call]]) -> str:
    """The matrix as a Markdown table: a row per shape, a column per command (ok, refused, failure, or - not run)."""
    commands = list(dict.fromkeys(c.command for calls in results.values() for c in calls))
    lines = ["| shape | " + " | ".join(commands) + " |", "|---|" + "---|" * len(commands)]
    for name, calls in results.items():
        by = {c.command: c.result for c in calls}
        lines.append(f"| {name} | " + " | ".join(by.get(c, "-") for c in commands) + " |")
    return "\n".join(lines)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--shapes", default=None, help="comma-separated shape names (default: all)")
    parser.add_argument("--markdown", default=None, help="write the table to this file")
    args = parser.parse_args()
    names = list(SHAPES) if args.shapes is None else [n.strip() for n in args.shapes.split(",")]
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name in names:
            results[name] = run_shape(name, SHAPES[name], Path(tmp) / re.sub(r"\W+", "_", name), _subprocess_run)
            bad = [c for c in results[name] if c.result == "failure"]
            print(f"{name}: " + ", ".join(f"{c.command} {c.result}" for c in results[name]), flush=True)
            for c in bad:
                print(f"  FAILURE {c.command}: {c.detail}", flush=True)
    table = markdown(results)
    if args.markdown:
        Path(args.markdown).write_text(table + "\n", encoding="utf-8")
    print(table)
    counts = {r: sum(c.result == r for calls in results.values() for c in calls) for r in ("ok", "refused", "failure")}
    print(json.dumps({"shapes": len(results), **counts}))
    return 1 if counts["failure"] else 0


if __name__ == "__main__":
    sys.exit(main())
