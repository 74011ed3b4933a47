"""Reliability sweep (#20, #35): corrupted logs, malformed CSV and model files, and hostile or unlucky inputs
through the real command line.

Makes 500 corrupted logs (truncations, byte flips and zeroed stretches of the shared PX4 ULog and ArduPilot
DataFlash samples, 250 each), 350 corrupted binaries written here (an HDF5 file, a MATLAB MAT-file, a NumPy .npz, a
Parquet table, a ROS 1 bag, ROS 2 bags in sqlite3 and MCAP storage, 50 each), 150 malformed CSV tables and 240
mutated model files (60 each of four kinds: a polynomial, the default fit with lag, memory and g-sensitivity, gyro
and accelerometer triads, a network), runs each through ``gyrocomp convert`` (logs, binaries, tables; every other
table with ``--drop-nan``) or ``gyrocomp apply`` (models) in this process, and classifies the outcome:

- ``clean``: exit 0, every number written finite, no warning (for a model: none beyond the intact model's);
- ``warned``: exit 0 with a warning, every number written finite;
- ``refused``: exit 2 with one line on stderr (besides warnings);
- ``internal error``: exit 1 (a bug);
- ``multi-line error``: a refusal of more than one line;
- ``non-finite written``: a NaN or infinity in the output without a warning;
- ``silently wrong``: without a word, a converted log holding values no sensor gives (beyond 5000 deg/s, outside
  -100..200 degC) or, with its length kept, fewer rows than the intact file; a model file that is no valid model
  (one the published schema refuses) applied to other numbers than the intact model's.

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
import gzip
import io
import json
import os
import re
import resource
import shutil
import sqlite3
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import scipy.io
import pyarrow as pa
import pyarrow.parquet as pq

from gyrocomp import Calibration, Network, Polynomial, fit, fit_calibration, write
from gyrocomp.calibration.schema import validate_model
from gyrocomp.cli import main
from gyrocomp.errors import InputError
from gyrocomp.simulation import simulate

BAD = ("internal error", "multi-line error", "non-finite written", "security hole", "silently wrong", "data loss")
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


def judged(outcome: str, lines: list[str], output: Path, intact_rows: int | None = None) -> str:
    """``outcome`` (:func:`classify`) made ``silently wrong`` when a written table holds what no sensor gives
    (a gyro beyond 5000 deg/s, a temperature outside -100..200 degC) or, for a damaged file whose length is kept,
    fewer rows than the intact file's, and nothing was said."""
    if outcome != "clean" or not output.exists():
        return outcome
    table = pd.read_csv(output)
    gyro = table[[c for c in table.columns if c.startswith("gyro_")]].to_numpy(dtype=float)
    temperature = table[[c for c in table.columns if c.startswith("temperature")]].to_numpy(dtype=float)
    if (np.abs(gyro) > 5000).any() or ((temperature < -100) | (temperature > 200)).any():
        return "silently wrong"
    if intact_rows is not None and len(table) < intact_rows:
        return "silently wrong"
    return outcome


def mutated_logs(source: Path, count: int, rng: np.random.Generator, limit: int | None = 400_000):
    blob = source.read_bytes()[:limit]
    for k in range(count):
        if k % 3 == 0:
            yield "truncated", blob[: int(rng.integers(1, len(blob)))]
        elif k % 3 == 1:
            damaged = bytearray(blob)
            for at in rng.integers(0, len(blob), size=int(rng.integers(1, 17))):
                damaged[at] = int(rng.integers(0, 256))
            yield "byte-flipped", bytes(damaged)
        else:  # a lost flash page or card sector
            at, length = int(rng.integers(0, len(blob))), int(rng.integers(1, 4097))
            damaged = bytearray(blob)
            damaged[at : at + length] = bytes(len(damaged[at : at + length]))
            yield "zeroed", bytes(damaged)


def malformed_csv(rng: np.random.Generator) -> str:
    """A plausible table (time, gyro, temperature; 20 rows) with some header names and cells damaged."""
    header = ["time", "gyro_x", "gyro_y", "gyro_z", "temperature"][: int(rng.integers(2, 6))]
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


def mutated_model(model: dict, rng: np.random.Generator) -> tuple[str, bool]:
    """One field of ``model`` deleted or replaced (None, true, -5, 1e300, a path, [], {}, 5000 ones, "NaN",
    +-1e308), sometimes the text damaged besides; and whether the file is still a valid model: another model, which
    may apply without a word. Valid is what the published schema (``model.schema.json``, checked by jsonschema)
    allows: -5 for a number, and also an optional field deleted (a polynomial's ``extrapolation``: held at the
    edge, as files without it always were), a polynomial's coefficient deleted (one order lower; order 0 is a bias
    alone) or its curve null (no temperature term), other turn-on biases."""
    paths = list(_leaves(model))
    path = paths[int(rng.integers(len(paths)))]
    copy = json.loads(json.dumps(model))
    parent = copy
    for key in path[:-1]:
        parent = parent[key]
    replacements = [None, True, -5, 10**300, "../../etc/passwd", [], {}, [1.0] * 5000, "NaN", 1e308, -1e308]
    if rng.random() < 0.3:
        del parent[path[-1]]
    else:
        replacement = replacements[int(rng.integers(len(replacements)))]
        parent[path[-1]] = replacement
    valid = _follows_schema(copy)
    text = json.dumps(copy, allow_nan=True)
    if rng.random() < 0.2:  # a damaged file besides: cut short or a stray byte
        cut = int(rng.integers(1, len(text)))
        text = text[:cut] if rng.random() < 0.5 else text[:cut] + "\x00" + text[cut:]
        valid = False
    return text, valid


def _follows_schema(model: dict) -> bool:
    """Whether ``model`` (a model file's content at the current version) follows the published schema."""
    try:
        validate_model(model)
    except InputError:
        return False
    return True


def model_kinds(seed: int, work: Path) -> dict[str, tuple[Path, dict]]:
    """Four kinds of model file, each with the run it applies to: a polynomial (mti10, 2 Hz chamber run), the
    default fit of a consumer part (thermal lag, heating/cooling memory, g-sensitivity; chamber runs with static
    positions), the same with the accelerometer (triads), and a network."""
    chamber = simulate("mti10", profile="chamber", duration_s=1800, rate_hz=2, seed=seed).recording
    runs = [
        simulate("consumer", profile="combined", duration_s=3600, rate_hz=2, seed=seed + s, unit=3).recording
        for s in (0, 1)
    ]
    write(chamber, work / "chamber.csv")
    write(runs[1], work / "combined.csv")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return {
            "polynomial": (work / "chamber.csv", fit_calibration([chamber], temperature=Polynomial(2)).to_dict()),
            "default (lag, memory, g-sensitivity)": (work / "combined.csv", fit(runs).to_dict()),
            "gyro and accelerometer triads": (work / "combined.csv", fit(runs, channels=("gyro", "accel")).to_dict()),
            "network": (
                work / "combined.csv",
                fit_calibration(runs, temperature=Network(), hysteresis="none").to_dict(),
            ),
        }


def mutated_models(seed: int, work: Path, rng: np.random.Generator, count: int) -> dict[str, collections.Counter]:
    """``count`` mutations of each kind of model file, applied: a file that applies without a word (none beyond
    what the intact model says of the run) to other numbers than the intact model's, though it is no valid model,
    is silently wrong."""
    results = {}
    for label, (data, model) in model_kinds(seed, work).items():
        counter = results.setdefault(f"model files: {label} ({count} mutated)", collections.Counter())
        intact, reference = work / "intact.json", work / "intact_applied.csv"
        intact.write_text(json.dumps(model), encoding="utf-8")
        _, baseline = run_command(["apply", intact, data, "-o", reference])  # what the intact model says
        expected = pd.read_csv(reference).select_dtypes("number").to_numpy(dtype=float)
        for k in range(count):
            path, out = work / f"model{k}.json", work / f"applied{k}.csv"
            text, valid = mutated_model(model, rng)
            path.write_text(text, encoding="utf-8")
            out.unlink(missing_ok=True)
            status, lines = run_command(["apply", path, data, "-o", out])
            outcome = classify(status, [line for line in lines if line not in baseline], out)
            if outcome == "clean" and not valid:
                got = pd.read_csv(out).select_dtypes("number").to_numpy(dtype=float)
                if got.shape != expected.shape or not np.allclose(got, expected, rtol=0, atol=1e-9):
                    outcome = "silently wrong"
            counter[outcome] += 1
    return results


def _bag(path: Path, recording, kind: str) -> Path:
    """``recording`` written as a bag with an IMU and a temperature topic (``kind``: ros1, sqlite3 or mcap); the
    file holding its messages."""
    from rosbags.rosbag1 import Writer as Writer1
    from rosbags.rosbag2 import StoragePlugin, Writer as Writer2
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS1_NOETIC if kind == "ros1" else Stores.ROS2_HUMBLE)
    types = store.types
    writer = (
        Writer1(path)
        if kind == "ros1"
        else Writer2(path, version=9, storage_plugin=StoragePlugin.MCAP if kind == "mcap" else StoragePlugin.SQLITE3)
    )
    serialize = store.serialize_ros1 if kind == "ros1" else store.serialize_cdr
    zeros, g_mps2 = np.zeros(9), 9.80665
    rad = np.deg2rad(recording.gyro_dps)
    with writer:
        imu = writer.add_connection("/imu", "sensor_msgs/msg/Imu", typestore=store)
        thermo = writer.add_connection("/temperature", "sensor_msgs/msg/Temperature", typestore=store)
        for k, t in enumerate(recording.time_s + 100.0):
            sec = int(t)
            stamp = types["builtin_interfaces/msg/Time"](sec=sec, nanosec=int((t - sec) * 1e9))
            header = types["std_msgs/msg/Header"](**({"seq": k} if kind == "ros1" else {}), stamp=stamp, frame_id="imu")
            vector, quaternion = types["geometry_msgs/msg/Vector3"], types["geometry_msgs/msg/Quaternion"]
            msg = types["sensor_msgs/msg/Imu"](
                header=header,
                orientation=quaternion(x=0.0, y=0.0, z=0.0, w=1.0),
                orientation_covariance=zeros,
                angular_velocity=vector(*rad[k]),
                angular_velocity_covariance=zeros,
                linear_acceleration=vector(*(recording.accel_g[k] * g_mps2)),
                linear_acceleration_covariance=zeros,
            )
            writer.write(imu, int(t * 1e9), serialize(msg, "sensor_msgs/msg/Imu"))
            msg = types["sensor_msgs/msg/Temperature"](
                header=header, temperature=float(recording.temperature_degc[k]), variance=0.0
            )
            writer.write(thermo, int(t * 1e9), serialize(msg, "sensor_msgs/msg/Temperature"))
    return path if kind == "ros1" else next(p for p in path.iterdir() if p.suffix in (".db3", ".mcap"))


def _hdf5(path: Path, recording) -> Path:
    import h5py

    with h5py.File(path, "w") as fh:
        fh["time"] = recording.time_s
        for k, axis in enumerate(recording.gyro_axes):
            fh[axis] = recording.gyro_dps[:, k]
        for k, axis in enumerate(recording.accel_axes):
            fh[axis] = recording.accel_g[:, k]
        fh["temperature"] = recording.temperature_degc
    return path


def _arrays(path: Path, recording) -> Path:
    """The run as named arrays: a MATLAB v5 MAT-file (scipy) or a NumPy .npz, by ``path``'s suffix."""
    arrays = {
        "time": recording.time_s,
        "gyro": recording.gyro_dps,
        "accel": recording.accel_g,
        "temperature": recording.temperature_degc,
    }
    if path.suffix == ".mat":
        scipy.io.savemat(path, arrays)
    else:
        np.savez(path, **arrays)
    return path


def corrupted_binaries(work: Path, rng: np.random.Generator, count: int) -> dict[str, collections.Counter]:
    """``count`` damaged copies each (a third each cut short, with 1..16 bytes overwritten, with up to 4 KiB
    zeroed) of an HDF5 file, a MATLAB MAT-file, a NumPy .npz, a Parquet table, a ROS 1 bag and ROS 2 bags in sqlite3
    and MCAP storage, all of one simulated run, converted; a copy whose length is kept must not lose rows without a
    word."""
    recording = simulate("mti10", profile="chamber", duration_s=600, rate_hz=2, seed=7).recording
    makers = {
        "HDF5": lambda p: _hdf5(p.with_suffix(".h5"), recording),
        "MATLAB MAT-file": lambda p: _arrays(p.with_suffix(".mat"), recording),
        "NumPy .npz": lambda p: _arrays(p.with_suffix(".npz"), recording),
        "Parquet": lambda p: (write(recording, p.with_suffix(".parquet")), p.with_suffix(".parquet"))[1],
        "ROS 1 bag": lambda p: _bag(p.with_suffix(".bag"), recording, "ros1"),
        "ROS 2 bag (sqlite3)": lambda p: _bag(p, recording, "sqlite3"),
        "ROS 2 bag (MCAP)": lambda p: _bag(p, recording, "mcap"),
    }
    results = {}
    for label, make in makers.items():
        seed_folder = work / f"seed_{len(results)}"
        seed_folder.mkdir()
        damaged_file = make(seed_folder / "intact")
        bag_folder = damaged_file.parent if damaged_file.parent != seed_folder else None
        intact = bag_folder or damaged_file
        status, _ = run_command(["convert", intact, work / "intact.csv"])
        intact_rows = len(pd.read_csv(work / "intact.csv")) if status == 0 else None
        counter = results.setdefault(f"{label} ({count} corrupted)", collections.Counter())
        for k, (how, blob) in enumerate(mutated_logs(damaged_file, count, rng, None)):
            copy = work / f"damaged_{len(results)}_{k}"
            if bag_folder:
                shutil.copytree(bag_folder, copy)
                (copy / damaged_file.name).write_bytes(blob)
                target = copy
            else:
                target = copy.with_suffix(damaged_file.suffix)
                target.write_bytes(blob)
            out = work / f"damaged_{len(results)}_{k}.csv"
            status, lines = run_command(["convert", target, out])
            counter[judged(classify(status, lines, out), lines, out, intact_rows if how != "truncated" else None)] += 1
    return results


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
    logs = [
        ("PX4 ULog", datasets / "px4-pyulog-samples" / "sample_log_small.ulg"),
        ("ArduPilot DataFlash", datasets / "ardupilot-pymavlink-sample" / "test.BIN"),
    ]
    for label, source in logs:
        counter = results.setdefault(f"{label} (250 corrupted)", collections.Counter())
        for k, (_, blob) in enumerate(mutated_logs(source, 250, rng)):
            path, out = work / f"log{k}{source.suffix}", work / f"log{k}.csv"
            path.write_bytes(blob)
            status, lines = run_command(["convert", path, out])
            counter[judged(classify(status, lines, out), lines, out)] += 1
    results.update(corrupted_binaries(work, rng, 50))
    counter = results.setdefault("CSV tables (150 malformed)", collections.Counter())
    for k in range(150):
        path, out = work / f"table{k}.csv", work / f"table{k}_out.csv"
        path.write_text(malformed_csv(rng), encoding="utf-8")
        status, lines = run_command(["convert", path, out, *(["--drop-nan"] if k % 2 else [])])
        counter[classify(status, lines, out)] += 1
    data, model = simulated_model(seed, work / "data.csv")
    results.update(mutated_models(seed, work, rng, 60))
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


HOSTILE_TEXT = [
    '*/ int evil(void) { return system("id"); } /*',
    "a??/\nb",
    "\\\n#include <stdlib.h>",
    "x\nTC_G0_X0_0\t1e9",
    "\r\x00\x1b[2J",
    "*" * 300,
    "\u2028 */ \u00e8",
    '"; DROP TABLE runs; --',
]
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
    done = subprocess.run(
        [CC, "-std=c99", "-O2", "-Wall", "-Werror", "-c", "-o", str(folder / "g.o"), str(folder / "gyrocomp.c")],
        capture_output=True,
        cwd=folder,
    )
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
        status, lines = run_command(
            ["export", source, "--format", "px4", "-o", work / f"p{k}.params", "--device-id", 1]
        )
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
        "virtual dataset": lambda fh: fh.create_virtual_dataset("gyro_z", _virtual_layout(h5py, other)),
    }
    for k, (_kind, make) in enumerate(makers.items()):
        path = work / f"pointing{k}.h5"
        with h5py.File(path, "w") as fh:
            fh["time"] = np.arange(8.0)
            fh["temperature"] = np.full(8, 25.0)
            make(fh)
        status, lines = run_command(["convert", path, work / f"pointing{k}.csv"])
        counter[
            "refused"
            if status == 2 and len(lines) == 1
            else classify(status, lines, work / "none.csv")
            if status != 0
            else "security hole"
        ] += 1
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
    commands = [
        (simulate_, "--rate"),
        (simulate_, "--ramp-rate"),
        (["evaluate", model, data], "--window"),
        (["apply", model, data, "-o", work / "applied.csv"], "--turn-on-window"),
        (["learn", data, "-o", work / "learned.json"], "--rate"),
        (["learn", data, "-o", work / "learned.json"], "--bin-width"),
        (["fit", data, "-o", work / "fitted.json"], "--min-static"),
    ]
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
            mutated.write_text(text[: match.start()] + replacement + text[match.end() :], encoding="utf-8")
            status, lines = run_command(["learn", data, "-o", work / f"relearned{k}.json", "--resume", mutated])
            counter[classify(status, lines, work / "none.csv")] += 1
    return counter


def unlucky_reads(work: Path) -> collections.Counter:
    """Reads that used to be silently wrong: each must be refused or warned."""
    counter: collections.Counter = collections.Counter()
    rows = "".join(f"{k},{0.1 + 1e-3 * k},{0.1},{20 + 0.01 * k}\n" for k in range(400))
    cases = {
        "duplicate.csv": ("time,Gyro_Z,GYRO_Z,temperature\n" + rows, ["convert"]),
        "twice.csv": ("time,gyro_z,temperature,Temperature\n" + rows, ["convert"]),
        "ns.csv": (
            "time,gyro_z,temperature\n" + "".join(f"{k * 10_000_000},{0.1},{20.0}\n" for k in range(400)),
            ["allan"],
        ),
        "hot.csv": (
            "time,gyro_z,temperature\n"
            + "".join(f"{k},{0.1 + 1e-4 * k},{1e6 if k == 123 else 20 + 0.05 * k}\n" for k in range(400)),
            ["fit"],
        ),
    }
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


def planted_links(data: Path, model: Path, work: Path) -> collections.Counter:
    """Every kind of output given as a symbolic link to a victim file, a name ending in ``/``, the standard
    streams; inputs that are pipes. A victim changed is a ``security hole``; an output accepted silently where it
    cannot be a file is ``silently wrong``."""
    counter: collections.Counter = collections.Counter()
    victim = work / "victim.txt"
    outputs = [
        lambda out: ["apply", model, data, "-o", out],
        lambda out: ["convert", data, out],
        lambda out: ["fit", data, "-o", out, "--temperature", "poly:1", "--hysteresis", "none"],
        lambda out: ["learn", data, "-o", work / "learned_link.json", "--save-state", out],
        lambda out: ["export", model, "--format", "px4", "-o", out],
        lambda out: ["simulate", "--profile", "chamber", "--duration", 60, "-o", out],
    ]
    suffixes = [".csv", ".csv", ".json", ".json", ".params", ".csv"]
    for k, (command, suffix) in enumerate(zip(outputs, suffixes)):
        victim.write_text("precious\n", encoding="utf-8")
        link = work / f"planted{k}{suffix}"
        with contextlib.suppress(FileNotFoundError):
            link.unlink()
        link.symlink_to(victim)
        status, lines = run_command(command(link))
        outcome = classify(status, lines, work / "none.csv")
        if victim.read_text(encoding="utf-8") != "precious\n" or not link.is_symlink():
            outcome = "security hole"
        counter[outcome] += 1
        for odd in (f"{work}/dir{k}{suffix}/", "/dev/stdout", "-"):
            status, lines = run_command(command(odd))
            counter["refused" if status == 2 and len(lines) == 1 else "silently wrong"] += 1
    fifo = work / "pipe.csv"
    with contextlib.suppress(FileNotFoundError):
        fifo.unlink()
    os.mkfifo(fifo)
    for command in (["fit", fifo, "-o", work / "fifo.json"], ["convert", fifo, work / "fifo.csv"]):
        status, lines = run_command(command)  # must not block waiting for a writer
        counter[classify(status, lines, work / "none.csv")] += 1
    return counter


def damaged_store_rows(run_path: Path, work: Path) -> collections.Counter:
    """A fleet store whose rows another program changed (cut-short model, non-JSON inputs or metadata, garbage
    time or status, damaged failures, figures or warnings) read by ``fleet show``, ``export``, ``report`` and the
    rerun of ``fleet fit``: refused in one line naming the row, or read as it was (the report of figures)."""
    counter: collections.Counter = collections.Counter()
    manifest = work / "store_manifest.csv"
    pd.DataFrame([{"path": str(run_path), "serial": "SN-1"}]).to_csv(manifest, index=False)
    fitted = work / "store_fitted"
    run_command(["fleet", "fit", "--manifest", manifest, "-o", fitted, "--scheduler", "serial"])
    damages = [
        ("model", '{"schema_version": 6, "axes"'),
        ("model", "[]"),
        ("inputs", "not json"),
        ("inputs", '{"a": 1}'),
        ("calibrated_utc", "garbage"),
        ("calibrated_utc", "9999-99-99"),
        ("status", "weird"),
        ("unit_metadata", "{"),
        ("failures", "[1"),
        ("figures", "{]"),
        ("warnings", "7"),
    ]
    for k, (column, value) in enumerate(damages):
        store = work / f"store_damaged{k}"
        shutil.copytree(fitted, store)
        with sqlite3.connect(store / "calibrations.sqlite") as conn:
            conn.execute(f"UPDATE calibrations SET {column} = ?", (value,))
        for command in (
            ["fleet", "show", "SN-1", "--store", store],
            ["fleet", "export", "SN-1", "--store", store, "--format", "json", "-o", work / f"e{k}.json"],
            ["fleet", "report", store, "-o", work / f"r{k}.html"],
            ["fleet", "fit", "--manifest", manifest, "-o", store, "--scheduler", "serial"],
        ):
            status, lines = run_command(command)
            outcome = classify(status, lines, work / "none.csv")
            if not _loads(store / "models" / "SN-1.json"):  # the unit's good model file replaced: lost
                outcome = "data loss"
            counter[outcome] += 1
    return counter


def _loads(model: Path) -> bool:
    """Whether ``model`` is a model file gyrocomp loads."""
    try:
        Calibration.load(model)
    except Exception:  # noqa: BLE001 - any failure to load is the answer
        return False
    return True


def _gyrocomp(*args, **popen) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-m", "gyrocomp", *map(str, args)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        **popen,
    )


def concurrent_writers(data: Path, other: Path, work: Path, repeats: int) -> collections.Counter:
    """Two learners resuming one state and saving to one file at once, and two fleet fits of one unit from other
    inputs into one store at once: one learner refused in one line (both saving, one's work gone, is ``data
    loss``); the unit's model file always the store's newest row's (else ``silently wrong``)."""
    counter: collections.Counter = collections.Counter()
    state = work / "shared_state.json"
    run_command(["learn", data, "-o", work / "first.json", "--save-state", state])
    for k in range(repeats):
        target = work / f"next_state{k}.json"
        learners = [
            _gyrocomp("learn", log, "--resume", state, "-o", work / f"m{k}_{j}.json", "--save-state", target)
            for j, log in enumerate((data, other))
        ]
        results = [(p.wait(timeout=600), p.stderr.read()) for p in learners]
        codes = sorted(code for code, _ in results)
        refusal = next((err for code, err in results if code == 2), "")
        counter[
            "refused"
            if codes == [0, 2] and refusal.count("\n") == 1
            else "data loss"
            if codes == [0, 0]
            else "internal error"
        ] += 1
    for k in range(repeats):
        store = work / f"race_store{k}"
        manifests = []
        for j, path in enumerate((data, other)):
            manifests.append(work / f"race{k}_{j}.csv")
            pd.DataFrame([{"path": str(path), "serial": "SN-R"}]).to_csv(manifests[-1], index=False)
        fits = [_gyrocomp("fleet", "fit", "--manifest", m, "-o", store, "--scheduler", "serial") for m in manifests]
        codes = [p.wait(timeout=600) for p in fits]
        with sqlite3.connect(store / "calibrations.sqlite") as conn:
            newest = conn.execute(
                "SELECT model FROM calibrations WHERE serial = 'SN-R' ORDER BY id DESC LIMIT 1"
            ).fetchone()[0]
        model_file = store / "models" / "SN-R.json"
        agree = model_file.exists() and json.loads(model_file.read_text()) == json.loads(newest)
        counter["clean" if codes == [0, 0] and agree else "silently wrong" if not agree else "internal error"] += 1
    return counter


def _limited(rlimit: int, value: int):
    return lambda: resource.setrlimit(rlimit, (value, value))


def resource_limits(data: Path, work: Path) -> collections.Counter:
    """Limits reached: a header of a million columns, a gzip of one 1 GiB line, a Parquet file of 10^5 row
    groups, a 2e6-row table under a 1.5 GB address-space limit (and the libraries under 300 MB), a glob through a
    link loop (each run fitted once, else ``silently wrong``), a fleet on Dask with 40 file descriptors, a table
    cut short while ``apply`` streams it (exit 0 is ``silently wrong``)."""
    counter: collections.Counter = collections.Counter()
    wide = work / "wide.csv"
    wide.write_text(",".join(f"c{i}" for i in range(10**6)) + "\n" + ",".join("1" * 10**6) + "\n")
    bomb = work / "bomb.csv.gz"
    with gzip.open(bomb, "wb", compresslevel=9) as fh:
        fh.write(b"time,gyro_z,temperature\n0,0.1,25\n")
        for _ in range(1024):
            fh.write(b"1" * (1 << 20))
    groups = work / "groups.parquet"
    n = 100_000
    pq.write_table(
        pa.table({"time": np.arange(n) / 10.0, "gyro_z": np.full(n, 0.1), "temperature": np.linspace(20, 30, n)}),
        groups,
        row_group_size=1,
    )
    for path in (wide, bomb, groups):
        for command in (["init", path, "-o", work / "p.toml"], ["fit", path, "-o", work / "wide.json"]):
            status, lines = run_command(command)
            counter[classify(status, lines, work / "none.csv")] += 1
    big = work / "big.csv"
    run_command(["simulate", "--profile", "chamber", "--duration", 20000, "--rate", 100, "-o", big])
    for limit, path in ((3 << 29, big), (300 << 20, data)):
        process = _gyrocomp("fit", path, "-o", work / "limited.json", preexec_fn=_limited(resource.RLIMIT_AS, limit))
        status, stderr = process.wait(timeout=600), process.stderr.read()
        counter[
            classify(status, stderr.splitlines(), work / "none.csv") if status in (0, 1, 2) else "internal error"
        ] += 1
    loop = work / "looped"
    loop.mkdir()
    shutil.copy(data, loop / "r1.csv")
    shutil.copy(data, loop / "r2.csv")
    (loop / "back").symlink_to("..")
    status, lines = run_command(["fit", f"{loop}/**/*.csv", "-o", work / "looped.json", "--hysteresis", "none"])
    outcome = classify(status, lines, work / "none.csv")
    if status == 0 and len(json.loads((work / "looped.json").read_text())["provenance"]["inputs"]) != 2:
        outcome = "silently wrong"
    counter[outcome] += 1
    fleet = work / "fd_fleet"
    (fleet / "SN1").mkdir(parents=True)
    shutil.copy(data, fleet / "SN1" / "run_1.csv")
    process = _gyrocomp(
        "fleet",
        "fit",
        fleet,
        "--unit-from",
        "{serial}/run_{n}.csv",
        "-o",
        work / "fd_out",
        "--scheduler",
        "local",
        "--workers",
        2,
        preexec_fn=_limited(resource.RLIMIT_NOFILE, 40),
    )
    status, stderr = process.wait(timeout=600), process.stderr.read()
    counter[classify(status, stderr.splitlines(), work / "none.csv")] += 1
    growing = work / "cut_short.csv"
    shutil.copy(big, growing)
    model = work / "cut_model.json"
    run_command(["fit", data, "-o", model, "--hysteresis", "none"])
    process = _gyrocomp("apply", model, growing, "-o", work / "cut_out.csv")
    time.sleep(1.0)
    with open(growing, "r+b") as fh:  # another program cuts the file while apply streams it
        fh.truncate(growing.stat().st_size // 3)
    status, stderr = process.wait(timeout=600), process.stderr.read()
    counter["silently wrong" if status == 0 else classify(status, stderr.splitlines(), work / "none.csv")] += 1
    return counter


def serial_logs(rng: np.random.Generator, work: Path, count: int) -> collections.Counter:
    """Serial-terminal logs (a banner, no header, no time, garbled lines at random): ``init --names --rate``,
    then ``fit`` and ``apply`` with no reading option; every row that holds its numbers must come out (fewer,
    without a word, is ``silently wrong``); ``fit`` without the names is refused in one line."""
    counter: collections.Counter = collections.Counter()
    run = simulate("mti10", profile="chamber", duration_s=1800, rate_hz=2, seed=int(rng.integers(1 << 30))).recording
    temperature = np.asarray(run.temperature_degc).reshape(run.n_samples, -1)[:, 0]
    samples = np.column_stack([np.asarray(run.gyro_dps).reshape(run.n_samples, -1), temperature])
    names = ",".join([*run.gyro_axes, "temperature"])
    for k in range(count):
        folder = work / f"serial{k}"
        folder.mkdir()
        lines, rows = [b"MPU ready"], 0
        for row in samples:
            if rng.random() < 0.01:
                garbage = rng.integers(0, 256, size=int(rng.integers(1, 30)), dtype=np.uint8).tobytes()
                lines.append(garbage.replace(b"\n", b"").replace(b"\r", b""))
            lines.append(",".join(f"{v:.5f}" for v in row).encode())
            rows += 1
        (folder / "log.txt").write_bytes(b"\r\n".join(lines) + b"\r\n")
        status, errors = run_command(["fit", folder / "log.txt", "-o", folder / "m.json"])
        counter["refused" if status == 2 and len(errors) == 1 else "silently wrong"] += 1
        cwd = os.getcwd()
        try:
            os.chdir(folder)
            status, errors = run_command(["init", "log.txt", "--names", names, "--rate", 2])
            if status == 0:
                status, errors = run_command(["fit", "log.txt", "-o", "m.json", "--hysteresis", "none"])
            if status == 0:
                status, errors = run_command(["apply", "m.json", "log.txt", "-o", "out.csv"])
            outcome = judged(classify(status, errors, folder / "out.csv"), errors, folder / "out.csv")
            if (
                status == 0
                and len(pd.read_csv(folder / "out.csv")) < rows
                and not any("skipped" in line for line in errors)
            ):
                outcome = "silently wrong"
        finally:
            os.chdir(cwd)
        counter[outcome] += 1
    return counter


def hostile_sweep(seed: int, work: Path) -> dict[str, collections.Counter]:
    rng = np.random.default_rng(seed + 1)
    data, model = simulated_model(seed, work / "hostile_data.csv")
    other, _ = simulated_model(seed + 7, work / "hostile_other.csv")
    model_path = work / "hostile_model.json"
    model_path.write_text(json.dumps(model), encoding="utf-8")
    return {
        "model text fields made hostile, exported (60)": hostile_exports(model, work, rng, 60),
        "HDF5 pointing at other files (3)": hostile_hdf5(work),
        "fleet stores: colliding and long serials, -o onto the store (5)": hostile_store(data, work),
        "number options: inf, nan, 1e999, -1, 0, 25 digits (49)": hostile_numbers(data, model_path, work),
        "learner states with huge numbers (resumed)": hostile_states(data, work),
        "ambiguous columns, ns time, 1e6 degC, non-UTF-8 name (5)": unlucky_reads(work),
        "outputs through planted links, odd names, pipes as inputs (26)": planted_links(data, model_path, work),
        "store rows changed by another program, read four ways (44)": damaged_store_rows(data, work),
        "concurrent learners and fleet fits (6)": concurrent_writers(data, other, work, 3),
        "resource limits: wide, bomb, row groups, memory, link loop, fds, cut short (11)": resource_limits(data, work),
        "serial-terminal logs with garbled lines (20)": serial_logs(rng, work, 10),
    }


def summary(results: dict[str, collections.Counter], seed: int) -> str:
    kinds = ["clean", "warned", "refused", *BAD]
    rows = ["| inputs | " + " | ".join(kinds) + " |", "|---" * (len(kinds) + 1) + "|"]
    for label, counter in results.items():
        rows.append(f"| {label} | " + " | ".join(str(counter.get(k, 0)) for k in kinds) + " |")
    total = {k: sum(c.get(k, 0) for c in results.values()) for k in kinds}
    rows.append("| **all** | " + " | ".join(f"**{total[k]}**" for k in kinds) + " |")
    return f"Mutation sweep, seed {seed} (`python tools/mutation_sweep.py --seed {seed}`):\n\n" + "\n".join(rows) + "\n"


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
