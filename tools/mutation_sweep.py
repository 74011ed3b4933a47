"""Reliability sweep (#20): corrupted logs and malformed CSV and model files through the real command line.

Makes 500 corrupted logs (truncations and byte flips of the shared PX4 ULog and ArduPilot DataFlash samples,
250 each), 150 malformed CSV tables and 150 mutated model files, runs each through ``gyrocomp convert`` (logs,
tables; every other table with ``--drop-nan``) or ``gyrocomp apply`` (models) in this process, and classifies the outcome:

- ``clean``: exit 0, every number written finite, no warning;
- ``warned``: exit 0 with a warning, every number written finite;
- ``refused``: exit 2 with one line on stderr (besides warnings);
- ``internal error``: exit 1 (a bug);
- ``multi-line error``: a refusal of more than one line;
- ``non-finite written``: a NaN or infinity in the output without a warning.

The last three must be zero. Usage: python tools/mutation_sweep.py [--datasets DIR] [--seed N] [--docs FILE]
(``--docs docs/reliability.md`` rewrites the summary there).
"""

from __future__ import annotations

import argparse
import collections
import contextlib
import io
import json
import tempfile
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from gyrocomp import Polynomial, fit_calibration, write
from gyrocomp.cli import main
from gyrocomp.simulate import simulate

BAD = ("internal error", "multi-line error", "non-finite written")
NAMES = ["time", "gyro_x", "gyro_y", "gyro_z", "accel_z", "temperature", "Time", " gyro_z ", "GyrZ", ""]
CELLS = ["", "nan", "inf", "-inf", "1e308", "1e999", "abc", '"1"', "1,5", "0x10", " 3 ", "-0", "1e-320"]


def run_command(args: list[str]) -> tuple[int, list[str]]:
    """Exit status and stderr lines of one ``gyrocomp`` command run in this process."""
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()), warnings.catch_warnings():
        warnings.simplefilter("always")
        status = main([str(a) for a in args])
    return status, [line for line in err.getvalue().splitlines() if line.strip()]


def classify(status: int, lines: list[str], output: Path) -> str:
    warned = any(line.startswith("gyrocomp: warning:") for line in lines)
    errors = [line for line in lines if not line.startswith("gyrocomp: warning:")]
    if status == 1:
        return "internal error"
    if status == 2:
        return "refused" if len(errors) == 1 else "multi-line error"
    if status != 0:
        return "internal error"
    table = pd.read_csv(output) if output.exists() else pd.DataFrame()
    values = table.select_dtypes("number").to_numpy(dtype=float)
    if not np.isfinite(values).all():
        return "warned" if warned else "non-finite written"
    return "warned" if warned else "clean"


def mutated_logs(source: Path, count: int, rng: np.random.Generator):
    blob = source.read_bytes()[:400_000]
    for k in range(count):
        if k % 2 == 0:
            yield "truncated", blob[:int(rng.integers(1, len(blob)))]
        else:
            damaged = bytearray(blob)
            for at in rng.integers(0, len(blob), size=int(rng.integers(1, 17))):
                damaged[at] = int(rng.integers(0, 256))
            yield "byte-flipped", bytes(damaged)


def malformed_csv(rng: np.random.Generator) -> str:
    """A plausible table (time, gyro, temperature; 20 rows) with some header names and cells damaged."""
    header = ["time", "gyro_x", "gyro_y", "gyro_z", "temperature"][:int(rng.integers(2, 6))]
    header = [str(rng.choice(NAMES)) if rng.random() < 0.15 else name for name in header]
    rows = [[repr(float(k)), *(repr(float(v)) for v in rng.normal(0.1, 0.01, len(header) - 1))] for k in range(20)]
    for row in rows:
        for j in range(len(row)):
            if rng.random() < 0.02:
                row[j] = str(rng.choice(CELLS))
        if rng.random() < 0.005:
            del row[-1]  # a short row (in about one table in ten)
    delimiter = str(rng.choice([",", ";", "\t"]))
    return "\n".join(delimiter.join(r) for r in [header, *rows]) + "\n"


def _leaves(node, prefix=()):
    if isinstance(node, dict):
        for key, value in node.items():
            yield (*prefix, key)
            yield from _leaves(value, (*prefix, key))
    elif isinstance(node, list):
        for i, value in enumerate(node):
            yield (*prefix, i)
            yield from _leaves(value, (*prefix, i))


def mutated_model(model: dict, rng: np.random.Generator) -> str:
    paths = list(_leaves(model))
    path = paths[int(rng.integers(len(paths)))]
    copy = json.loads(json.dumps(model))
    parent = copy
    for key in path[:-1]:
        parent = parent[key]
    replacements = [None, True, -5, 10 ** 300, "../../etc/passwd", [], {}, [1.0] * 5000, "NaN", 1e308, -1e308]
    if rng.random() < 0.3:
        del parent[path[-1]]
    else:
        parent[path[-1]] = replacements[int(rng.integers(len(replacements)))]
    text = json.dumps(copy, allow_nan=True)
    if rng.random() < 0.2:  # a damaged file besides: cut short or a stray byte
        cut = int(rng.integers(1, len(text)))
        text = text[:cut] if rng.random() < 0.5 else text[:cut] + "\x00" + text[cut:]
    return text


def sweep(datasets: Path, seed: int, work: Path) -> dict[str, collections.Counter]:
    rng = np.random.default_rng(seed)
    results: dict[str, collections.Counter] = {}
    logs = [("PX4 ULog", datasets / "px4-pyulog-samples" / "sample_log_small.ulg"),
            ("ArduPilot DataFlash", datasets / "ardupilot-pymavlink-sample" / "test.BIN")]
    for label, source in logs:
        counter = results.setdefault(f"{label} (250 corrupted)", collections.Counter())
        for k, (_, blob) in enumerate(mutated_logs(source, 250, rng)):
            path, out = work / f"log{k}{source.suffix}", work / f"log{k}.csv"
            path.write_bytes(blob)
            status, lines = run_command(["convert", path, out])
            counter[classify(status, lines, out)] += 1
    counter = results.setdefault("CSV tables (150 malformed)", collections.Counter())
    for k in range(150):
        path, out = work / f"table{k}.csv", work / f"table{k}_out.csv"
        path.write_text(malformed_csv(rng), encoding="utf-8")
        status, lines = run_command(["convert", path, out, *(["--drop-nan"] if k % 2 else [])])
        counter[classify(status, lines, out)] += 1
    run = simulate("mti10", profile="chamber", duration_s=1800, rate_hz=2, seed=seed).recording
    data = work / "data.csv"
    write(run, data)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = fit_calibration([run], temperature=Polynomial(2)).to_dict()
    counter = results.setdefault("model files (150 mutated)", collections.Counter())
    for k in range(150):
        path, out = work / f"model{k}.json", work / f"applied{k}.csv"
        path.write_text(mutated_model(model, rng), encoding="utf-8")
        status, lines = run_command(["apply", path, data, "-o", out])
        counter[classify(status, lines, out)] += 1
    # the malformed tables again, through the commands that read them in chunks and write no table
    model_path = work / "model.json"
    model_path.write_text(json.dumps(model), encoding="utf-8")
    for label, command in (("allan", ["allan"]), ("evaluate", ["evaluate", model_path])):
        counter = results.setdefault(f"the same CSV tables through {label}", collections.Counter())
        for k in range(150):
            path = work / f"table{k}.csv"
            status, lines = run_command([*command, path, *(["--drop-nan"] if k % 2 else [])])
            counter[classify(status, lines, work / "none.csv")] += 1
    return results


def summary(results: dict[str, collections.Counter], seed: int) -> str:
    kinds = ["clean", "warned", "refused", *BAD]
    rows = ["| inputs | " + " | ".join(kinds) + " |", "|---" * (len(kinds) + 1) + "|"]
    for label, counter in results.items():
        rows.append(f"| {label} | " + " | ".join(str(counter.get(k, 0)) for k in kinds) + " |")
    total = {k: sum(c.get(k, 0) for c in results.values()) for k in kinds}
    rows.append("| **all** | " + " | ".join(f"**{total[k]}**" for k in kinds) + " |")
    return (f"Mutation sweep, seed {seed} (`python tools/mutation_sweep.py --seed {seed}`):\n\n" + "\n".join(rows)
            + "\n")


def main_cli() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--datasets", type=Path, default=Path(__file__).resolve().parents[2] / "shared" / "datasets")
    parser.add_argument("--seed", type=int, default=2026)
    parser.add_argument("--docs", type=Path, help="rewrite the summary between the markers of this file")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        results = sweep(args.datasets, args.seed, Path(tmp))
    text = summary(results, args.seed)
    print(text)
    if args.docs:
        start, end = "<!-- sweep -->\n", "<!-- /sweep -->\n"
        page = args.docs.read_text(encoding="utf-8")
        head, rest = page.split(start, 1)
        args.docs.write_text(head + start + text + end + rest.split(end, 1)[1], encoding="utf-8")
    return 1 if any(c.get(k, 0) for c in results.values() for k in BAD) else 0


if __name__ == "__main__":
    raise SystemExit(main_cli())
