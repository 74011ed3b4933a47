"""Benchmark: gyrocomp's overlapping Allan deviation against ``allantools.oadev``, and a larger-than-memory run.

In one process, on the same white-noise rate arrays (1e6 and 1e7 samples), with the same octave taus
(m = 1, 2, 4, ... up to N/4), it times ``allantools.oadev`` (deviations only) against
``gyrocomp.allan.allan_deviation`` twice: deviations only (``confidence=None``, the like-for-like
figure) and with the default noise identification and 68 % confidence intervals at every tau; it checks that the deviations agree, and measures the peak extra memory of each call with
tracemalloc (numpy reports its buffers there), as a multiple of the input array's size.

``--huge N`` also runs gyrocomp on N samples that never sit in memory: the rate samples are a
memory-mapped ``.npy`` file and the phase goes to a second memory-mapped file (``phase_out``); it
prints the throughput and the process's peak resident memory.

The largest size is timed again with a busy neighbour process on one core (``benchmarks/busy.py``).

Usage: python benchmarks/bench_allan.py [--sizes 1e6,1e7] [--repeat 3] [--huge 1e9 --workdir DIR]
Needs the bench extra: pip install -e '.[bench]'
"""

from __future__ import annotations

import argparse
import platform
import resource
import tempfile
import time
import tracemalloc
from pathlib import Path

import numpy as np

from busy import busy_neighbour
from gyrocomp.allan import allan_deviation, averaging_factors


def measure(func, repeat: int):
    """(best time [s], peak traced allocation [bytes], last result)."""
    best, result = np.inf, None
    for _ in range(repeat):
        start = time.perf_counter()
        result = func()
        best = min(best, time.perf_counter() - start)
    tracemalloc.start()
    tracemalloc.reset_peak()
    func()
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return best, peak, result


def compare(n: int, repeat: int) -> dict:
    import allantools

    rate_hz = 100.0
    y = np.random.default_rng(0).standard_normal(n) * 0.01
    taus = averaging_factors(n + 1, "octave", rate_hz) / rate_hz
    t_ours, mem_ours, ours = measure(lambda: allan_deviation(y, rate_hz, taus=taus, confidence=None), repeat)
    t_ci, mem_ci, _ = measure(lambda: allan_deviation(y, rate_hz, taus=taus), repeat)
    t_theirs, mem_theirs, theirs = measure(
        lambda: allantools.oadev(y, rate=rate_hz, data_type="freq", taus=taus), repeat
    )
    agree = float(np.max(np.abs(ours.deviation / theirs[1] - 1.0)))
    return {
        "n": n,
        "taus": len(taus),
        "gyrocomp_s": t_ours,
        "allantools_s": t_theirs,
        "speedup": t_theirs / t_ours,
        "gyrocomp_extra_memory_x": mem_ours / y.nbytes,
        "gyrocomp_ci_s": t_ci,
        "speedup_ci": t_theirs / t_ci,
        "gyrocomp_ci_extra_memory_x": mem_ci / y.nbytes,
        "allantools_extra_memory_x": mem_theirs / y.nbytes,
        "max_relative_difference": agree,
    }


def huge(n: int, workdir: Path) -> dict:
    """gyrocomp on n samples with both the input and the phase memory-mapped."""
    rate_hz = 100.0
    source = workdir / "rate.npy"
    rate = np.lib.format.open_memmap(source, mode="w+", dtype=np.float64, shape=(n,))
    rng = np.random.default_rng(1)
    chunk = 1 << 24
    for start in range(0, n, chunk):
        stop = min(start + chunk, n)
        rate[start:stop] = rng.standard_normal(stop - start) * 0.01
    rate.flush()
    del rate
    rate = np.load(source, mmap_mode="r")
    phase = np.lib.format.open_memmap(workdir / "phase.npy", mode="w+", dtype=np.float64, shape=(n + 1,))
    tracemalloc.start()
    start = time.perf_counter()
    result = allan_deviation(rate, rate_hz, phase_out=phase)
    elapsed = time.perf_counter() - start
    traced_peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    expected = 0.01 / np.sqrt(result.tau * rate_hz)  # white noise: sigma(tau) = sigma_1 / sqrt(m)
    return {
        "n": n,
        "seconds": elapsed,
        "samples_per_s": n / elapsed,
        "taus": len(result.tau),
        "working_memory_mib": traced_peak / 2**20,
        "peak_rss_gib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20,
        "input_gib": n * 8 / 2**30,
        "max_relative_error_vs_white_noise_theory_first_10_taus": float(
            np.max(np.abs(result.deviation[:10] / expected[:10] - 1))
        ),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="1e6,1e7")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--huge", type=float, default=0)
    parser.add_argument("--workdir", type=Path, default=None)
    args = parser.parse_args()
    print(
        f"machine: {platform.processor() or platform.machine()}, python {platform.python_version()}, "
        f"numpy {np.__version__}"
    )
    print(
        "| samples | taus | allantools.oadev [s] | gyrocomp, deviations only [s] | speed-up | "
        "gyrocomp with noise ID + CIs [s] | speed-up | extra memory: allantools / gyrocomp / gyrocomp + CIs "
        "| max rel. difference |"
    )
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for size in args.sizes.split(","):
        r = compare(int(float(size)), args.repeat)
        print(
            f"| {r['n']:.0e} | {r['taus']} | {r['allantools_s']:.3f} | {r['gyrocomp_s']:.3f} | "
            f"{r['speedup']:.1f}x | {r['gyrocomp_ci_s']:.3f} | {r['speedup_ci']:.1f}x | "
            f"{r['allantools_extra_memory_x']:.2f}x / {r['gyrocomp_extra_memory_x']:.2f}x / "
            f"{r['gyrocomp_ci_extra_memory_x']:.2f}x input | {r['max_relative_difference']:.1e} |"
        )
    largest = max(int(float(size)) for size in args.sizes.split(","))
    with busy_neighbour():
        r = compare(largest, args.repeat)
    print(
        f"\nwith a busy neighbour process on one core, {largest:.0e} samples: allantools {r['allantools_s']:.3f} s, "
        f"gyrocomp {r['gyrocomp_s']:.3f} s = {r['speedup']:.1f}x; with noise ID + CIs {r['gyrocomp_ci_s']:.3f} s "
        f"= {r['speedup_ci']:.1f}x"
    )
    if args.huge:
        with tempfile.TemporaryDirectory(dir=args.workdir) as tmp:
            r = huge(int(args.huge), Path(tmp))
        print(
            f"\nout of core: {r['n']:.0e} samples ({r['input_gib']:.1f} GiB), {r['taus']} octave taus with CIs "
            f"in {r['seconds']:.0f} s = {r['samples_per_s'] / 1e6:.1f} M samples/s; working memory (numpy "
            f"allocations) {r['working_memory_mib']:.1f} MiB; peak RSS {r['peak_rss_gib']:.2f} GiB (reclaimable "
            f"memory-mapped file pages included); deviation vs theory "
            f"{r['max_relative_error_vs_white_noise_theory_first_10_taus']:.1e}"
        )


if __name__ == "__main__":
    main()
