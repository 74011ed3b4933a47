"""Reliability sweep (#20, #35): corrupted logs, malformed CSV and model files, and hostile or unlucky inputs
through the real command line.

Makes 500 corrupted logs (truncations and byte flips of the shared PX4 ULog and ArduPilot DataFlash samples,
250 each), 150 malformed CSV tables and 150 mutated model files, runs each through ``gyrocomp convert`` (logs,
tables; every other table with ``--drop-nan``) or ``gyrocomp apply`` (models) in this process, and classifies the outcome:

- ``clean``: exit 0, every number written finite, no warning;
- ``warned``: exit 0 with a warning, every number written finite;
- ``refused``: exit 2 with one line on stderr (besides warnings);
- ``internal error``: exit 1 (a bug);
- ``multi-line error``: a refusal of more than one line;
- ``non-finite written``: a NaN or infinity in the output without a warning.

The hostile part (``--hostile-only`` runs it alone) adds, each with what it must not do:

- model files with a text field made hostile (comment closers, line splices, preprocessor lines, control
  characters) through ``export --format c`` and ``--format px4``: the C must compile to the same object and the
  parameter lines must be the same as the plain model's, else a ``security hole``;
- HDF5 files that point at other files (external storage, an external link, a virtual dataset) through
  ``convert``: anything but a refusal is a ``security hole``;
- fleet stores: serials that map to one file name or run long, and ``fleet report -o`` onto the store: every unit
  must come back with its own model and the store must be intact, else ``silently wrong``;
- number options given ``inf``, ``nan``, ``1e999``, 25-digit integers, and learner states with 5000-digit integers
  or 1e308: a non-finite value taken is ``silently wrong``;
- tables with two columns for one channel, nanosecond time (``allan``), one impossible temperature (``fit``), and
  file names that are not UTF-8: taken without a word is ``silently wrong``.

The last five kinds must be zero. Usage: python tools/mutation_sweep.py [--datasets DIR] [--seed N] [--docs FILE]
(``--docs docs/reliability.md`` rewrites the summary there).
"""

from __future__ import annotations

import argparse
import collections
import contextlib
import io
import json
import os
import re
import shutil
import subprocess
import tempfile
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from gyrocomp import Polynomial, fit_calibration, write
from gyrocomp.cli import main
from gyrocomp.simulation import simulate

BAD = ("internal error", "multi-line error", "non-finite written", "security hole", "silently wrong")
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


def simulated_model(seed: int, data: Path) -> tuple[Path, dict]:
    """A simulated chamber run written to ``data``, and the model fitted on it (as a dict)."""
    run = simulate("mti10", profile="chamber", duration_s=1800, rate_hz=2, seed=seed).recording
    write(run, data)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return data, fit_calibration([run], temperature=Polynomial(2)).to_dict()


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
    data, model = simulated_model(seed, work / "data.csv")
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


HOSTILE_TEXT = ['*/ int evil(void) { return system("id"); } /*', "a??/\nb", "\\\n#include <stdlib.h>",
                "x\nTC_G0_X0_0\t1e9", "\r\x00\x1b[2J", "*" * 300, "\u2028 */ \u00e8", '"; DROP TABLE runs; --']
CC = shutil.which("cc") or shutil.which("gcc")


def _string_paths(node, prefix=()):
    if isinstance(node, dict):
        for key, value in node.items():
            yield from _string_paths(value, (*prefix, key))
    elif isinstance(node, list):
        for i, value in enumerate(node):
            yield from _string_paths(value, (*prefix, i))
    elif isinstance(node, str):
        yield prefix


def _compiled(folder: Path) -> bytes | None:
    """The object compiled from an exported C folder, or None when it does not compile."""
    done = subprocess.run([CC, "-std=c99", "-O2", "-Wall", "-Werror", "-c", "-o", str(folder / "g.o"),
                           str(folder / "gyrocomp.c")], capture_output=True, cwd=folder)
    return (folder / "g.o").read_bytes() if done.returncode == 0 else None


def _parameter_lines(path: Path) -> list[str]:
    return [line for line in path.read_text(encoding="utf-8").splitlines() if not line.startswith("#")]


def hostile_exports(model: dict, work: Path, rng: np.random.Generator, count: int) -> collections.Counter:
    """Model files with one text field hostile, exported as C (compiled) and as PX4 parameters."""
    counter: collections.Counter = collections.Counter()
    plain = work / "plain.json"
    plain.write_text(json.dumps(model), encoding="utf-8")
    run_command(["export", plain, "--format", "c", "-o", work / "plain_c", "--rate", 2])
    run_command(["export", plain, "--format", "px4", "-o", work / "plain.params", "--device-id", 1])
    reference = _compiled(work / "plain_c") if CC else None
    paths = list(_string_paths(model))
    for k in range(count):
        copy = json.loads(json.dumps(model))
        path = paths[int(rng.integers(len(paths)))]
        parent = copy
        for key in path[:-1]:
            parent = parent[key]
        parent[path[-1]] = HOSTILE_TEXT[int(rng.integers(len(HOSTILE_TEXT)))]
        source = work / f"hostile{k}.json"
        source.write_text(json.dumps(copy), encoding="utf-8")
        status, lines = run_command(["export", source, "--format", "c", "-o", work / f"c{k}", "--rate", 2])
        outcome = classify(status, lines, work / "none.csv")
        if status == 0 and CC and _compiled(work / f"c{k}") != reference:
            outcome = "security hole"
        status, lines = run_command(["export", source, "--format", "px4", "-o", work / f"p{k}.params",
                                     "--device-id", 1])
        if status == 0 and _parameter_lines(work / f"p{k}.params") != _parameter_lines(work / "plain.params"):
            outcome = "security hole"
        counter[outcome] += 1
    return counter


def hostile_hdf5(work: Path) -> collections.Counter:
    """HDF5 files whose gyro data live in another file: each must be refused."""
    import h5py

    counter: collections.Counter = collections.Counter()
    secret = work / "secret.bin"
    secret.write_bytes(np.arange(64, dtype=np.float64).tobytes())
    other = work / "other.h5"
    with h5py.File(other, "w") as fh:
        fh["gyro_z"] = np.arange(8.0)
    makers = {
        "external storage": lambda fh: fh.create_dataset("gyro_z", (8,), "f8", external=[(str(secret), 0, 64)]),
        "external link": lambda fh: fh.__setitem__("gyro_z", h5py.ExternalLink(str(other), "/gyro_z")),
        "virtual dataset": lambda fh: fh.create_virtual_dataset(
            "gyro_z", _virtual_layout(h5py, other)),
    }
    for k, (kind, make) in enumerate(makers.items()):
        path = work / f"pointing{k}.h5"
        with h5py.File(path, "w") as fh:
            fh["time"] = np.arange(8.0)
            fh["temperature"] = np.full(8, 25.0)
            make(fh)
        status, lines = run_command(["convert", path, work / f"pointing{k}.csv"])
        counter["refused" if status == 2 and len(lines) == 1 else
                classify(status, lines, work / "none.csv") if status != 0 else "security hole"] += 1
    return counter


def _virtual_layout(h5py, other: Path):
    layout = h5py.VirtualLayout(shape=(8,), dtype="f8")
    layout[:] = h5py.VirtualSource(str(other), "gyro_z", shape=(8,))
    return layout


def hostile_store(run_path: Path, work: Path) -> collections.Counter:
    """Fleets whose serials map to one file name or run long, and a report written onto the store."""
    counter: collections.Counter = collections.Counter()
    cases = [("a/b", "a_b"), ("x" * 300,), ("../../up", "..%2F..%2Fup"), ("UNIT", "unit"), ("con", "nul.json")]
    for k, serials in enumerate(cases):
        fleet = work / f"fleet{k}"
        manifest = work / f"manifest{k}.csv"
        rows = []
        for j, serial in enumerate(serials):
            copy = work / f"unit{k}_{j}.csv"
            copy.write_bytes(run_path.read_bytes())
            rows.append({"path": str(copy), "serial": serial})
        pd.DataFrame(rows).to_csv(manifest, index=False)
        status, lines = run_command(["fleet", "fit", "--manifest", manifest, "-o", fleet, "--scheduler", "serial"])
        outcome = classify(status, lines, work / "none.csv")
        if status == 0:
            for j, serial in enumerate(serials):
                out = work / f"export{k}_{j}.json"
                got, _ = run_command(["fleet", "export", serial, "--store", fleet, "--format", "json", "-o", out])
                files = [] if got else [i["file"] for i in json.loads(out.read_text())["provenance"].get("inputs", [])]
                if got or not any(f.endswith(f"unit{k}_{j}.csv") for f in files):
                    outcome = "silently wrong"  # a unit lost, or given another unit's model
            store = fleet / "calibrations.sqlite"
            before = store.read_bytes()
            got, _ = run_command(["fleet", "report", fleet, "-o", store])
            if got != 2 or store.read_bytes() != before:
                outcome = "silently wrong"
        counter[outcome] += 1
    return counter


BAD_NUMBERS = ["inf", "-inf", "nan", "1e999", "-1", "0", "1" * 25]


def hostile_numbers(data: Path, model: Path, work: Path) -> collections.Counter:
    """Number options given non-finite, negative, zero and huge values: refused in one line or taken as numbers,
    never an internal error; a non-finite value taken is silently wrong."""
    counter: collections.Counter = collections.Counter()
    simulate_ = ["simulate", "--preset", "mti10", "--profile", "chamber", "-o", work / "sim.csv", "--duration", 60]
    commands = [(simulate_, "--rate"), (simulate_, "--ramp-rate"), (["evaluate", model, data], "--window"),
                (["apply", model, data, "-o", work / "applied.csv"], "--turn-on-window"),
                (["learn", data, "-o", work / "learned.json"], "--rate"),
                (["learn", data, "-o", work / "learned.json"], "--bin-width"),
                (["fit", data, "-o", work / "fitted.json"], "--min-static")]
    for command, option in commands:
        for value in BAD_NUMBERS:
            status, lines = run_command([*command, option, value])
            outcome = classify(status, lines, work / "none.csv")
            if status == 0 and value in ("inf", "-inf", "nan", "1e999"):
                outcome = "silently wrong"
            counter[outcome] += 1
    return counter


def hostile_states(data: Path, work: Path) -> collections.Counter:
    """Learner states with 5000-digit integers or 1e308 in their fields, resumed."""
    counter: collections.Counter = collections.Counter()
    state = work / "state.json"
    run_command(["learn", data, "-o", work / "learned.json", "--save-state", state])
    text = state.read_text(encoding="utf-8")
    numbers = [m for m in re.finditer(r"(?<![\w.])-?\d+(\.\d+)?(e-?\d+)?(?![\w.])", text)]
    for k, match in enumerate(numbers[:: max(1, len(numbers) // 20)]):
        for replacement in ("9" * 5000, "1e308", "-1e308"):
            mutated = work / f"state{k}.json"
            mutated.write_text(text[:match.start()] + replacement + text[match.end():], encoding="utf-8")
            status, lines = run_command(["learn", data, "-o", work / f"relearned{k}.json", "--resume", mutated])
            counter[classify(status, lines, work / "none.csv")] += 1
    return counter


def unlucky_reads(work: Path) -> collections.Counter:
    """Reads that used to be silently wrong: each must be refused or warned."""
    counter: collections.Counter = collections.Counter()
    rows = "".join(f"{k},{0.1 + 1e-3 * k},{0.1},{20 + 0.01 * k}\n" for k in range(400))
    cases = {"duplicate.csv": ("time,Gyro_Z,GYRO_Z,temperature\n" + rows, ["convert"]),
             "twice.csv": ("time,gyro_z,temperature,Temperature\n" + rows, ["convert"]),
             "ns.csv": ("time,gyro_z,temperature\n" + "".join(f"{k * 10_000_000},{0.1},{20.0}\n" for k in range(400)),
                        ["allan"]),
             "hot.csv": ("time,gyro_z,temperature\n" + "".join(
                 f"{k},{0.1 + 1e-4 * k},{1e6 if k == 123 else 20 + 0.05 * k}\n" for k in range(400)), ["fit"])}
    for name, (text, command) in cases.items():
        path = work / name
        path.write_text(text, encoding="utf-8")
        out = work / f"{name}.out.csv" if command == ["convert"] else work / f"{name}.json"
        args = [*command, path] + ([out] if command == ["convert"] else ["-o", out] if command == ["fit"] else [])
        status, lines = run_command(args)
        outcome = classify(status, lines, out if command == ["convert"] else work / "none.csv")
        if outcome == "clean":
            outcome = "silently wrong"
        counter[outcome] += 1
    name = os.fsdecode(b"r\xff\xfe.csv")
    (work / name).write_text("time,gyro_z,temperature\n" + rows.replace(",0.1,", ","), encoding="utf-8")
    status, lines = run_command(["convert", work / name, work / os.fsdecode(b"out\xff.csv")])
    counter[classify(status, lines, work / os.fsdecode(b"out\xff.csv")) if status != 2 else "silently wrong"] += 1
    return counter


def hostile_sweep(seed: int, work: Path) -> dict[str, collections.Counter]:
    rng = np.random.default_rng(seed + 1)
    data, model = simulated_model(seed, work / "hostile_data.csv")
    model_path = work / "hostile_model.json"
    model_path.write_text(json.dumps(model), encoding="utf-8")
    return {"model text fields made hostile, exported (60)": hostile_exports(model, work, rng, 60),
            "HDF5 pointing at other files (3)": hostile_hdf5(work),
            "fleet stores: colliding and long serials, -o onto the store (5)": hostile_store(data, work),
            "number options: inf, nan, 1e999, -1, 0, 25 digits (49)": hostile_numbers(data, model_path, work),
            "learner states with huge numbers (resumed)": hostile_states(data, work),
            "ambiguous columns, ns time, 1e6 degC, non-UTF-8 name (5)": unlucky_reads(work)}


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
    parser.add_argument("--hostile-only", action="store_true", help="run only the hostile and unlucky inputs")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        results = {} if args.hostile_only else sweep(args.datasets, args.seed, Path(tmp))
        results.update(hostile_sweep(args.seed, Path(tmp)))
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
