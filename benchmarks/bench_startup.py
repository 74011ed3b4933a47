"""Benchmark: start-up of the command line (#21 asks ``gyrocomp --help`` under 0.4 s).

Each command runs as a new process, as a user's shell or script starts it (best of 5), against the bare
interpreter (``python -c pass``) and the interpreter importing numpy and pandas, in the same run:

- ``gyrocomp --help`` and ``gyrocomp --version`` (only click is loaded: the commands are imported when one runs);
- ``gyrocomp convert`` of a 100-row CSV to Parquet and ``gyrocomp apply`` of a model with thermal lag to a
  600-row CSV (whole commands on small files: numpy and pyarrow, not pandas or scipy.signal);
- ``gyrocomp simulate`` of 600 s at 1 Hz (its noise processes filtered without importing scipy.signal).

Usage: python benchmarks/bench_startup.py
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

SCRIPT = Path(sys.executable).parent / "gyrocomp"


def best(cmd: list[str], repeat: int = 5) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        subprocess.run(cmd, check=True, capture_output=True)
        times.append(time.perf_counter() - start)
    return min(times)


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        small = Path(tmp) / "small.csv"
        t = np.arange(100) / 10.0
        pd.DataFrame({"time": t, "gyro_x": 0.01 * t, "gyro_y": 0.0, "gyro_z": 0.02, "temperature": 25.0}).to_csv(
            small, index=False
        )
        run = Path(tmp) / "run.csv"
        model = Path(tmp) / "model.json"
        subprocess.run(
            [str(SCRIPT), "-q", "simulate", "--preset", "consumer", "--rate", "1", "--duration", "600", "-o", str(run)],
            check=True,
            capture_output=True,
        )
        subprocess.run(
            [str(SCRIPT), "-q", "fit", str(run), "-o", str(model), "--hysteresis", "lag"],
            check=True,
            capture_output=True,
        )
        rows = [
            ("`python -c pass` (baseline)", best([sys.executable, "-c", "pass"])),
            ("`python -c 'import numpy, pandas'`", best([sys.executable, "-c", "import numpy, pandas"])),
            (
                "`python -c 'import numpy, pyarrow.parquet'`",
                best([sys.executable, "-c", "import numpy, pyarrow.parquet"]),
            ),
            ("`gyrocomp --help`", best([str(SCRIPT), "--help"])),
            ("`gyrocomp --version`", best([str(SCRIPT), "--version"])),
            (
                "`gyrocomp convert` of a 100-row CSV to Parquet",
                best([str(SCRIPT), "-q", "convert", str(small), str(Path(tmp) / "small.parquet")]),
            ),
            (
                "`gyrocomp apply` of a model with thermal lag to a 600-row CSV",
                best([str(SCRIPT), "-q", "apply", str(model), str(run), "-o", str(Path(tmp) / "out.csv")]),
            ),
            (
                "`gyrocomp simulate` of 600 s at 1 Hz to CSV",
                best(
                    [str(SCRIPT), "-q", "simulate", "--rate", "1", "--duration", "600", "-o", str(Path(tmp) / "s.csv")]
                ),
            ),
        ]
    base = rows[0][1]
    print("| command | time [s] | ratio |")
    print("|---|---:|---:|")
    for name, seconds in rows:
        print(f"| {name} | {seconds:.3f} | {seconds / base:.1f}x |")


if __name__ == "__main__":
    main()
