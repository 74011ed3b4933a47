"""Benchmark: ``gyrocomp apply`` on a 1,000,000-row CSV against plain table I/O of the same file.

Baselines, timed in the same run on the same file:
- pandas: ``pd.read_csv`` + ``DataFrame.to_csv`` (the issue's named baseline);
- pyarrow: ``pyarrow.csv.read_csv`` + ``pyarrow.csv.write_csv`` (the fastest plain I/O, a stricter bar).

gyrocomp is timed through its real CLI entry point (``gyrocomp.cli.entry_point``) in this process, so the figure
includes reading, validation, compensation and the atomic write, but not interpreter start-up. pyarrow's I/O and
``gyrocomp apply`` are timed again with a busy neighbour process on one core (``benchmarks/busy.py``).
Usage: python benchmarks/bench_apply.py [--rows N] [--repeat K]
"""

from __future__ import annotations

import argparse
import platform
import tempfile
import time
from pathlib import Path

import pandas as pd
import pyarrow.csv as pacsv

from gyrocomp import fit_calibration
from gyrocomp.cli import main
from gyrocomp.io import write_recording
from gyrocomp.simulation import simulate

from busy import busy_neighbour


def best_of(repeat, func):
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        func()
        times.append(time.perf_counter() - start)
    return min(times)


def run(rows: int, repeat: int) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        rate_hz = 100.0
        sim = simulate(duration_s=(rows - 1) / rate_hz, rate_hz=rate_hz, seed=1)
        data = tmp / "run.csv"
        write_recording(sim.recording, data)
        model = tmp / "model.json"
        fit_calibration([simulate(duration_s=1800, rate_hz=20, seed=s).recording for s in (2, 3)]).save(model)

        def pandas_io():
            pd.read_csv(data).to_csv(tmp / "pandas_out.csv", index=False)

        def arrow_io():
            pacsv.write_csv(pacsv.read_csv(data), tmp / "arrow_out.csv")

        def gyrocomp_apply():
            status = main(["--quiet", "apply", str(model), str(data), "-o", str(tmp / "comp.csv")])
            assert status == 0

        t_pandas = best_of(repeat, pandas_io)
        t_arrow = best_of(repeat, arrow_io)
        t_apply = best_of(repeat, gyrocomp_apply)
        with busy_neighbour():
            t_arrow_busy = best_of(repeat, arrow_io)
            t_apply_busy = best_of(repeat, gyrocomp_apply)
        size_mb = data.stat().st_size / 1e6
    return {
        "rows": sim.recording.n_samples,
        "size_mb": size_mb,
        "pandas_s": t_pandas,
        "pyarrow_s": t_arrow,
        "apply_s": t_apply,
        "pyarrow_busy_s": t_arrow_busy,
        "apply_busy_s": t_apply_busy,
    }


def cli() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", type=int, default=1_000_000)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    r = run(args.rows, args.repeat)
    print(
        f"machine: {platform.machine()}, {platform.python_implementation()} {platform.python_version()}, "
        f"pandas {pd.__version__}"
    )
    print(f"file: {r['rows']} rows, 8 columns, {r['size_mb']:.1f} MB CSV; best of {args.repeat}")
    print(f"pandas read_csv + to_csv : {r['pandas_s']:7.2f} s")
    print(f"pyarrow read + write     : {r['pyarrow_s']:7.2f} s")
    print(f"gyrocomp apply           : {r['apply_s']:7.2f} s")
    print(f"apply / pandas I/O  = {r['apply_s'] / r['pandas_s']:.2f}x (target <= 1.3x)")
    print(f"apply / pyarrow I/O = {r['apply_s'] / r['pyarrow_s']:.2f}x")
    print(
        f"with a busy neighbour on one core: pyarrow I/O {r['pyarrow_busy_s']:.2f} s, gyrocomp apply "
        f"{r['apply_busy_s']:.2f} s ({r['apply_busy_s'] / r['apply_s']:.2f}x idle, "
        f"{r['apply_busy_s'] / r['pyarrow_busy_s']:.2f}x pyarrow)"
    )


if __name__ == "__main__":
    cli()
