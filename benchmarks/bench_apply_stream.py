"""Benchmark: ``gyrocomp apply``, ``allan`` and ``evaluate`` on a long Parquet (or CSV) file, peak memory and
time (issue #21).

A file of ``--rows`` rows (time, gyro x/y/z, accel x/y/z, temperature; a simulated hour at 100 Hz repeated with
the time running on, written row group by row group) is processed, each in a fresh process, by:

- ``pyarrow``: ``pq.read_table`` + ``pq.write_table`` of the same file (the baseline: plain I/O, nothing done);
- ``gyrocomp apply``: the command through its entry point (chunks of 2^18 rows: read, validate, compensate, write);
- ``whole file``: ``read_table`` + ``apply`` + ``write_gyro_back`` (what ``apply`` did before it streamed);
- ``gyrocomp allan`` (the three gyro axes, in chunks, phases spilled to temporary files past 8 MiB each) and
  ``allan whole file`` (``read_table`` of the columns used + ``analyse_noise``, what it did before);
- ``gyrocomp evaluate`` (the model on the file, in chunks) and ``evaluate whole file`` (``read_table`` +
  ``evaluate``);
- ``gyrocomp noise`` (``--commands noise``): the noise model of the six gyro and accelerometer axes, in chunks, and
  its Kalibr export, against ``gyrocomp allan`` of the three gyro axes.

Printed: each one's wall time, peak resident memory (``ru_maxrss`` of its process: this includes the pages of the
memory-mapped temporary files, which are file cache the kernel can drop, not working memory) and peak anonymous
memory (``RssAnon``, sampled every 20 ms: the working memory), and the ratios to the baseline.

Usage: python benchmarks/bench_apply_stream.py [--rows N] [--format parquet|csv] [--skip-whole]
       [--commands apply,allan,evaluate]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import warnings
from pathlib import Path

import pyarrow as pa
import pyarrow.csv as pacsv
import pyarrow.parquet as pq

from gyrocomp.io.tables import recording_table
from gyrocomp.models.fit import fit_channels
from gyrocomp.simulation import simulate

BLOCK_ROWS = 360_000  # one simulated hour at 100 Hz

PROGRAMS = {
    "pyarrow": (
        "import pyarrow.parquet as pq, pyarrow.csv as pc, sys\n"
        "i, o = sys.argv[1], sys.argv[2]\n"
        "if i.endswith('.parquet'): pq.write_table(pq.read_table(i), o)\n"
        "else: pc.write_csv(pc.read_csv(i), o)\n"
    ),
    "gyrocomp apply": (
        "import sys\nfrom gyrocomp.cli import main\n"
        "sys.exit(main(['--quiet', 'apply', sys.argv[3], sys.argv[1], '-o', sys.argv[2]]))\n"
    ),
    "whole file": (
        "import sys, warnings\nwarnings.simplefilter('ignore')\n"
        "from gyrocomp import Calibration, apply\nfrom gyrocomp.io.tables import read_table, write_gyro_back\n"
        "data = read_table(sys.argv[1])\n"
        "write_gyro_back(data, apply(Calibration.load(sys.argv[3]), data.recording).gyro_dps, sys.argv[2])\n"
    ),
    "gyrocomp allan": (
        "import sys\nfrom gyrocomp.cli import main\nsys.exit(main(['--quiet', 'allan', sys.argv[1]]))\n"
    ),
    "allan whole file": (
        "import sys, warnings\nwarnings.simplefilter('ignore')\n"
        "from gyrocomp.io.tables import read_table\nfrom gyrocomp.measures.noise import analyse_noise\n"
        "analyse_noise(read_table(sys.argv[1], channels=('gyro_x', 'gyro_y', 'gyro_z')).recording)\n"
    ),
    "gyrocomp noise": (
        "import sys\nfrom gyrocomp.cli import main\n"
        "sys.exit(main(['--quiet', 'noise', sys.argv[1], '--export', 'kalibr', '-o', sys.argv[2] + '.yaml']))\n"
    ),
    "gyrocomp evaluate": (
        "import sys\nfrom gyrocomp.cli import main\nsys.exit(main(['--quiet', 'evaluate', sys.argv[3], sys.argv[1]]))\n"
    ),
    "evaluate whole file": (
        "import sys, warnings\nwarnings.simplefilter('ignore')\n"
        "from gyrocomp import Calibration\nfrom gyrocomp.evaluation import evaluate\n"
        "from gyrocomp.io.tables import read_table\n"
        "evaluate(Calibration.load(sys.argv[3]), read_table(sys.argv[1]).recording)\n"
    ),
}
#: the programs each command runs (the first is its streamed path, the second what it did before)
COMMANDS = {
    "apply": ("gyrocomp apply", "whole file"),
    "allan": ("gyrocomp allan", "allan whole file"),
    "evaluate": ("gyrocomp evaluate", "evaluate whole file"),
    "noise": ("gyrocomp noise",),
}
WRAPPER = (
    "import resource, sys, threading, time\npeak = [0]\n"
    "def anon():\n    for line in open('/proc/self/status'):\n"
    "        if line.startswith('RssAnon:'):\n            return int(line.split()[1])\n    return 0\n"
    "def watch():\n    while True:\n        peak[0] = max(peak[0], anon())\n        time.sleep(0.02)\n"
    "threading.Thread(target=watch, daemon=True).start()\nstart = time.perf_counter()\n"
    "try:\n    exec(compile(sys.argv.pop(1), 'program', 'exec'))\nexcept SystemExit as e:\n"
    "    assert not e.code, e.code\n"
    "print(time.perf_counter() - start, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, max(peak[0], anon()),"
    " file=sys.stderr)\n"
)


def make_file(path: Path, rows: int, fmt: str) -> None:
    """``rows`` rows: a simulated hour at 100 Hz repeated, the time running on."""
    block = recording_table(
        simulate(
            "consumer", profile="chamber", rate_hz=100.0, duration_s=(BLOCK_ROWS - 1) / 100, seed=1, unit=3
        ).recording
    )
    writer = pq.ParquetWriter(path, block.schema) if fmt == "parquet" else pacsv.CSVWriter(path, block.schema)
    done, k = 0, 0
    while done < rows:
        n = min(BLOCK_ROWS, rows - done)
        part = block.slice(0, n)
        part = part.set_column(0, "time", pa.array(part.column("time").to_numpy() + k * BLOCK_ROWS / 100.0))
        writer.write_table(part)
        done += n
        k += 1
    writer.close()


def measure(name: str, source: Path, target: Path, model: Path) -> tuple[float, float, float]:
    """(wall time [s], peak RSS [MB], peak anonymous memory [MB]) of one program in a fresh process."""
    done = subprocess.run(
        [sys.executable, "-c", WRAPPER, PROGRAMS[name], str(source), str(target), str(model)],
        capture_output=True,
        text=True,
        check=True,
    )
    seconds, kb, anon_kb = done.stderr.strip().splitlines()[-1].split()
    return float(seconds), float(kb) / 1024.0, float(anon_kb) / 1024.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rows", type=float, default=3e7)
    parser.add_argument("--format", choices=("parquet", "csv"), default="parquet")
    parser.add_argument("--skip-whole", action="store_true", help="skip the whole-file runs (they need GBs)")
    parser.add_argument(
        "--commands", default="apply,allan,evaluate", help="comma-separated: apply, allan, evaluate, noise"
    )
    args = parser.parse_args()
    rows = int(args.rows)
    warnings.simplefilter("ignore")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        source = tmp / f"in.{args.format}"
        make_file(source, rows, args.format)
        model = tmp / "model.json"
        fit_channels(
            [
                simulate("consumer", profile="chamber", rate_hz=5, duration_s=3600, seed=s, unit=3).recording
                for s in (2, 3)
            ]
        ).save(model)
        size_mb = source.stat().st_size / 2**20
        print(f"{rows:,} rows, {args.format} {size_mb:,.0f} MB")
        results = {"pyarrow": measure("pyarrow", source, tmp / f"out.{args.format}", model)}
        _print("pyarrow", results["pyarrow"])
        for command in args.commands.split(","):
            for name in COMMANDS[command.strip()]:
                if name.endswith("whole file") and args.skip_whole:
                    continue
                results[name] = measure(name, source, tmp / f"out.{args.format}", model)
                (tmp / f"out.{args.format}").unlink(missing_ok=True)
                _print(name, results[name])
        base = results["pyarrow"]
        for command in args.commands.split(","):
            ours = results[COMMANDS[command.strip()][0]]
            print(
                f"  gyrocomp {command.strip()}: {ours[0] / base[0]:.2f}x pyarrow's time, {ours[1]:.0f} MB peak RSS "
                f"({ours[1] / base[1]:.2f}x pyarrow's), {ours[2]:.0f} MB peak anonymous"
            )
        if "gyrocomp noise" in results and "gyrocomp allan" in results:
            noise, allan = results["gyrocomp noise"], results["gyrocomp allan"]
            print(
                f"  gyrocomp noise (six axes, the model and a Kalibr export): {noise[0] / allan[0]:.2f}x the time of "
                "gyrocomp allan (three axes)"
            )


def _print(name: str, result: tuple[float, float, float]) -> None:
    print(f"  {name:20s} {result[0]:8.1f} s  {result[1]:8.0f} MB peak RSS  {result[2]:8.0f} MB peak anonymous")


if __name__ == "__main__":
    main()
