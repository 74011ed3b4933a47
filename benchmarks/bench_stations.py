"""Stations at once on one store, on SQLite and on a throwaway PostgreSQL server (tools/postgres_cluster.py).

Protocol (issue: the production line):

1. 4 stations (``gyrocomp fleet fit --scheduler serial --station Sk``, each its own process and output folder)
   on 200 units with overlapping lists (station k: units 50k .. 50k + 74, wrapping: every unit in one or two
   lists): every unit stored exactly once, no claim left.
2. ``--trials`` (20) times: a station of 40 units killed (SIGKILL) at a random moment (0.3 .. 6 s after its
   start), then the store checked (every successful row holds a valid model, no unit stored twice from the same
   inputs, every model file the station wrote is its unit's newest row's), then the station run again: it must
   finish with every unit stored once, every model file there, and no claim left.

    python benchmarks/bench_stations.py [--trials 20]
"""

from __future__ import annotations

import argparse
import random
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from gyrocomp.errors import InputError
from gyrocomp.fleet import CalibrationStore, model_file_name
from gyrocomp.fleet.stations import claims
from gyrocomp.io.tables import write_recording
from gyrocomp.simulation import simulate

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))
import postgres_cluster  # noqa: E402

CMD = [str(Path(sys.executable).parent / "gyrocomp")]
UNITS, STATIONS, KILLED_UNITS = 200, 4, 40


def _runs(folder: Path) -> dict[str, Path]:
    out = {}
    for k in range(UNITS):
        path = folder / f"u{k:03d}.parquet"
        write_recording(simulate("consumer", profile="chamber", duration_s=600, rate_hz=2, seed=k).recording, path)
        out[f"SN{k:03d}"] = path
    return out


def _manifest(path: Path, runs: dict[str, Path], serials) -> Path:
    path.write_text("path,serial\n" + "".join(f"{runs[s]},{s}\n" for s in serials))
    return path


def _station(manifest: Path, out: Path, store: str, name: str) -> subprocess.Popen:
    return subprocess.Popen(
        [
            *CMD,
            "-q",
            "fleet",
            "fit",
            "--manifest",
            str(manifest),
            "-o",
            str(out),
            "--store",
            store,
            "--scheduler",
            "serial",
            "--station",
            name,
        ],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )


def _problems(store: str, outputs: list[Path], serials: list[str], complete: bool) -> list[str]:
    """What is inconsistent in the store (empty: consistent); ``complete``: every unit must be stored once."""
    try:
        db = CalibrationStore(store)
    except InputError:  # killed before it made the store (no file, or a database without the tables)
        return [] if not any(any(o.glob("models/*.json")) for o in outputs) else ["model files without a store"]
    found = []
    with db:
        for serial in serials:
            ok = [r for r in db.history(serial) if r.status == "ok"]
            if len({r.input_hash for r in ok}) != len(ok):
                found.append(f"{serial} stored twice from the same inputs")
            if complete and len(ok) != 1:
                found.append(f"{serial}: {len(ok)} successful rows")
            for r in ok:
                try:
                    r.calibration()
                except Exception as exc:  # noqa: BLE001 - any failure to read the model back is a finding
                    found.append(f"{serial} row {r.id}: {exc}")
            for out in outputs:
                file = out / "models" / model_file_name(serial)
                if file.exists() and (not ok or file.read_text() != ok[-1].model_json):
                    found.append(f"{file} is not its newest row's model")
                elif complete and ok and out == outputs[0] and len(outputs) == 1 and not file.exists():
                    found.append(f"{file} missing")
        if complete and claims(db):
            found.append(f"{len(claims(db))} claim(s) left")
    return found


def overlapping(store: str, runs: dict[str, Path], folder: Path) -> tuple[float, list[str]]:
    serials = sorted(runs)
    lists = [[serials[(50 * k + i) % UNITS] for i in range(75)] for k in range(STATIONS)]
    outputs = [folder / f"station{k}" for k in range(STATIONS)]
    started = time.perf_counter()
    procs = [
        _station(_manifest(folder / f"m{k}.csv", runs, lst), out, store, f"S{k}")
        for k, (lst, out) in enumerate(zip(lists, outputs))
    ]
    errors = [p.communicate()[1] for p in procs if p.wait() != 0]
    elapsed = time.perf_counter() - started
    return elapsed, errors + _problems(store, outputs, serials, complete=True)


def killed(new_store, runs: dict[str, Path], folder: Path, trials: int, rng: random.Random) -> list[str]:
    serials = sorted(runs)[:KILLED_UNITS]
    manifest = _manifest(folder / "killed.csv", runs, serials)
    found = []
    for trial in range(trials):
        out, store = folder / f"trial{trial}", new_store(folder / f"trial{trial}.sqlite")
        station = _station(manifest, out, store, "K")
        time.sleep(rng.uniform(0.3, 6.0))
        station.send_signal(signal.SIGKILL)
        station.wait()
        found += [f"trial {trial}, after the kill: {p}" for p in _problems(store, [out], serials, complete=False)]
        rerun = _station(manifest, out, store, "K")
        if rerun.wait() != 0:
            found.append(f"trial {trial}: the rerun failed: {rerun.communicate()[1]}")
        found += [f"trial {trial}, after the rerun: {p}" for p in _problems(store, [out], serials, complete=True)]
    return found


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--trials", type=int, default=20)
    args = parser.parse_args()
    rng = random.Random(2026)
    with tempfile.TemporaryDirectory() as tmp, postgres_cluster.throwaway_cluster() as new_database:
        folder = Path(tmp)
        (folder / "runs").mkdir()
        runs = _runs(folder / "runs")
        backends = {"SQLite": lambda path: str(path), "PostgreSQL": lambda _path: new_database()}
        for name, new_store in backends.items():
            work = folder / name
            work.mkdir()
            elapsed, problems = overlapping(new_store(work / "fleet.sqlite"), runs, work)
            print(
                f"{name}: {STATIONS} stations x 75 units (200 units, overlapping): {elapsed:.1f} s, "
                f"{'every unit stored once' if not problems else 'PROBLEMS: ' + '; '.join(problems[:5])}"
            )
            problems = killed(new_store, runs, work, args.trials, rng)
            print(
                f"{name}: {args.trials} trials of a station killed at a random moment: "
                f"{'consistent every time, each rerun completed' if not problems else 'PROBLEMS: ' + '; '.join(problems[:5])}"
            )


if __name__ == "__main__":
    main()
