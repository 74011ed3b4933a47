"""Benchmark: a fleet of simulated units fitted end to end, serial against a local Dask cluster (issue #17).

Each unit is drawn from the ``consumer`` preset's production spread (``gyrocomp simulate --unit N``): three chamber
runs of 15 minutes at 10 Hz over -20..70 degC, written as Parquet files ``UNIT/run_K.parquet``. Timed:

- ``serial``: ``fit_fleet(..., scheduler="serial")``, one unit after another in this process (the baseline: the
  sequential batch script a production line writes today, with gyrocomp's default fit);
- ``dask``: the same units on a local Dask cluster of one single-threaded worker process per core;
- ``rerun``: the Dask fleet again, every unit unchanged (hashing only);

and, per worker, the peak resident memory (``ru_maxrss``) after the fleet, and the client's.

Usage: python benchmarks/bench_fleet.py [--units N] [--workers W] [--skip-serial]
"""

from __future__ import annotations

import argparse
import os
import platform
import resource
import tempfile
import time
import warnings
from pathlib import Path

import dask
from dask.distributed import Client, LocalCluster

from gyrocomp.fleet import expand_inputs, fit_fleet, units_from_pattern
from gyrocomp.io.tables import write_recording
from gyrocomp.simulation import simulate


def peak_rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def write_fleet(folder: Path, units: int) -> None:
    for unit in range(units):
        (folder / f"U{unit:05d}").mkdir(parents=True)
        for k in range(3):
            rec = simulate(
                "consumer", profile="chamber", duration_s=900.0, rate_hz=10.0, seed=1000 * unit + k, unit=unit
            ).recording
            write_recording(rec, folder / f"U{unit:05d}" / f"run_{k}.parquet")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--units", type=int, default=1000)
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--skip-serial", action="store_true")
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    with tempfile.TemporaryDirectory() as tmp:
        data = Path(tmp) / "data"
        start = time.perf_counter()
        write_fleet(data, args.units)
        simulated_s = time.perf_counter() - start
        units = units_from_pattern(expand_inputs([data]), "{serial}/run_{n}.parquet")
        size_mb = sum(p.stat().st_size for p in data.rglob("*.parquet")) / 1e6
        print(
            f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores; {len(units)} units, "
            f"3 runs each ({size_mb:.0f} MB of Parquet, simulated in {simulated_s:.0f} s)"
        )
        serial_s = None
        if not args.skip_serial:
            start = time.perf_counter()
            fit_fleet(units, Path(tmp) / "serial", scheduler="serial")
            serial_s = time.perf_counter() - start
            print(f"serial (baseline)   {serial_s:8.1f} s  {len(units) / serial_s:6.2f} units/s")
        # the local cluster fit_fleet starts (its profiler off), kept here to read the workers' memory after
        with (
            dask.config.set({"distributed.worker.profile.enabled": False}),
            LocalCluster(
                n_workers=args.workers, threads_per_worker=1, processes=True, dashboard_address=None
            ) as cluster,
            Client(cluster) as client,
        ):
            start = time.perf_counter()
            summary = fit_fleet(units, Path(tmp) / "dask", scheduler=cluster.scheduler_address)
            dask_s = time.perf_counter() - start
            speedup = f"  {serial_s / dask_s:4.2f}x serial" if serial_s else ""
            print(
                f"dask, {args.workers} workers     {dask_s:8.1f} s  {len(units) / dask_s:6.2f} units/s{speedup}  "
                f"({len(summary.fitted)} fitted, {len(summary.failed)} failed)"
            )
            start = time.perf_counter()
            again = fit_fleet(units, Path(tmp) / "dask", scheduler=cluster.scheduler_address)
            rerun_s = time.perf_counter() - start
            print(
                f"rerun, all unchanged {rerun_s:7.1f} s  {len(units) / rerun_s:6.1f} units/s "
                f"({len(again.unchanged)} skipped)"
            )
            workers = client.run(peak_rss_mb)
            print(
                "peak memory per worker: "
                + ", ".join(f"{mb:.0f} MB" for mb in sorted(workers.values()))
                + f"; client {peak_rss_mb():.0f} MB"
            )
            store_mb = (Path(tmp) / "dask" / "calibrations.sqlite").stat().st_size / 1e6
            print(f"store {store_mb:.1f} MB ({store_mb * 1e3 / len(units):.1f} kB per calibration)")


if __name__ == "__main__":
    main()
