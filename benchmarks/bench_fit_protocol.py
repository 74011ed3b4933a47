"""Benchmark: the default ``gyrocomp fit`` as a user runs it, against the PX4-style pipeline users compare it with.

Protocol (issue #38): N runs of one hour at 100 Hz written as CSV (``time_s``, ``gyro_x..z`` [deg/s],
``temperature_degc``; a heat-cool cycle, a cubic temperature drift, one constant per run, white noise). Timed as
separate processes, best of ``--repeat``:

- ``gyrocomp -q fit RUN1.csv ... -o model.json``, the whole command (start-up, reading, validation, the model
  choice, the fit, the atomic write);
- the PX4-style pipeline (``benchmarks/px4_style_fit.py``): ``pandas.read_csv``, ``scipy.signal.medfilt(..., 31)``,
  2000 temperature bins, one ``lstsq`` of a cubic with run constants.

Both idle and with a busy neighbour process on one core (``benchmarks/busy.py``), for 3 and 10 runs (the growth
from 3 to 10 should be at most linear). The stages of the gyrocomp fit are timed in this process as well
(reading with ``gyrocomp.io.read``; within ``fit_channels`` the input checks, the reduction, the model choice and
the final fit), so that the ratio can be read stage by stage.

Usage: python benchmarks/bench_fit_protocol.py [--runs 3 10] [--repeat 2]
"""

from __future__ import annotations

import argparse
import os
import platform
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

from busy import busy_neighbour

RATE_HZ = 100.0
HOURS = 1.0
HERE = Path(__file__).resolve().parent


def write_runs(folder: Path, n_runs: int, seed: int = 0) -> list[Path]:
    """``n_runs`` CSV files of one hour at 100 Hz: a heat-cool cycle over -10..60 degC, a cubic drift shared by
    the runs, a turn-on constant per run, white noise of 0.01 deg/s per sample."""
    rng = np.random.default_rng(seed)
    n = int(HOURS * 3600 * RATE_HZ)
    t = np.arange(n) / RATE_HZ
    temp = 25.0 - 35.0 * np.cos(2 * np.pi * t / t[-1])
    u = (temp - 25.0) / 35.0
    shape = np.column_stack([0.02 * u + 0.01 * u**2 - 0.005 * u**3, -0.015 * u + 0.004 * u**3, 0.01 * u**2])
    paths = []
    for r in range(n_runs):
        gyro = shape + rng.normal(0.0, 0.05, 3) + rng.normal(0.0, 0.01, (n, 3))
        path = folder / f"run{r + 1:02d}.csv"
        data = np.column_stack([t, gyro, temp + rng.normal(0.0, 0.02, n)])
        np.savetxt(
            path, data, delimiter=",", fmt="%.6f", header="time_s,gyro_x,gyro_y,gyro_z,temperature_degc", comments=""
        )
        paths.append(path)
    return paths


def timed_process(args: list[str], repeat: int) -> float:
    """Best wall time of ``repeat`` runs of a command [s]; a failure stops the benchmark with its message."""
    best = np.inf
    for _ in range(repeat):
        start = time.perf_counter()
        done = subprocess.run(args, capture_output=True, text=True)
        elapsed = time.perf_counter() - start
        if done.returncode != 0:
            sys.exit(f"{' '.join(args[:3])}...: exit {done.returncode}: {done.stderr.strip()[-500:]}")
        best = min(best, elapsed)
    return best


#: the fit's stages: the functions of ``gyrocomp.models`` (fit, joint) each stage's time is spent in (the rest of
#: ``gyrocomp.fit`` is the final fit of the chosen models and its report)
#: each stage's functions, by the module of gyrocomp.models that calls them (the runs are prepared once, by fit)
STAGES = {
    "checks": (("joint", "_check_fit_inputs"),),
    "reduction": (("fit", "prepare"), ("joint", "prepare_axis")),
    "model choice": (("joint", "share_fold_lags"), ("joint", "select_axes")),
}


def _timed(func, stage: str, spent: dict[str, float]):
    def wrapper(*args, **kwargs):
        start = time.perf_counter()
        try:
            return func(*args, **kwargs)
        finally:
            spent[stage] += time.perf_counter() - start

    return wrapper


def stages(paths: list[Path]) -> dict[str, float]:
    """The gyrocomp fit's stages in this process [s]: reading the CSVs, then within the fit the input checks
    (plausibility of each run), the reduction (stillness, blocks and bins per axis), the model choice (held-out
    drift of every candidate) and the final fit (the rest: the chosen models on all runs, the report)."""
    import importlib

    from gyrocomp.io import read

    modules = {name: importlib.import_module(f"gyrocomp.models.{name}") for name in ("fit", "joint")}
    start = time.perf_counter()
    runs = [read(p) for p in paths]
    spent = {"read": time.perf_counter() - start, **dict.fromkeys(STAGES, 0.0)}
    originals = {(module, name): getattr(modules[module], name) for pairs in STAGES.values() for module, name in pairs}
    for stage, pairs in STAGES.items():
        for module, name in pairs:
            setattr(modules[module], name, _timed(originals[module, name], stage, spent))
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            start = time.perf_counter()
            modules["fit"].fit(runs)
            whole = time.perf_counter() - start
    finally:
        for (module, name), func in originals.items():
            setattr(modules[module], name, func)
    spent["final fit"] = whole - sum(spent[stage] for stage in STAGES)
    return spent


def measure(paths: list[Path], out: Path, repeat: int) -> dict[str, float]:
    gyrocomp = [sys.executable, "-m", "gyrocomp", "-q", "fit", *map(str, paths), "-o", str(out)]
    px4 = [sys.executable, str(HERE / "px4_style_fit.py"), *map(str, paths)]
    figures = {"px4": timed_process(px4, repeat), "gyrocomp": timed_process(gyrocomp, repeat)}
    with busy_neighbour():
        figures["px4 busy"] = timed_process(px4, repeat)
        figures["gyrocomp busy"] = timed_process(gyrocomp, repeat)
    figures.update(stages(paths))
    return figures


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--runs", type=int, nargs="+", default=[3, 10])
    parser.add_argument("--repeat", type=int, default=2)
    args = parser.parse_args()
    lines = [
        "| runs | PX4-style pipeline [s] | `gyrocomp fit` [s] | ratio | busy neighbour: PX4-style / gyrocomp [s] "
        "| ratio | stages in-process: read / checks / reduction / model choice / final fit [s] |",
        "|---|---|---|---|---|---|---|",
    ]
    print("\n".join(lines), flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        all_paths = write_runs(folder, max(args.runs))
        for n in args.runs:
            f = measure(all_paths[:n], folder / "model.json", args.repeat)
            lines.append(
                f"| {n} | {f['px4']:.2f} | {f['gyrocomp']:.2f} | **{f['gyrocomp'] / f['px4']:.2f}x** | "
                f"{f['px4 busy']:.2f} / {f['gyrocomp busy']:.2f} | "
                f"{f['gyrocomp busy'] / f['px4 busy']:.2f}x | "
                f"{' / '.join(f'{f[stage]:.2f}' for stage in ('read', *STAGES, 'final fit'))} |"
            )
            print(lines[-1], flush=True)
    machine = (
        f"{os.cpu_count()} cores, {platform.machine()}, CPython {platform.python_version()}, "
        f"{time.strftime('%Y-%m-%d')}"
    )
    print(machine)


if __name__ == "__main__":
    main()
