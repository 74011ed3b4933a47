"""Damaged binary files (seeded cuts, overwritten bytes and zeroed stretches of every binary format gyrocomp
reads): each is read as a recording every sensor could give, or refused with one error naming the file; never
another exception. A bag that lost messages its index counts says so."""

from __future__ import annotations

import shutil
import warnings

import h5py
import numpy as np
import pytest

from gyrocomp.errors import DataQualityWarning, GyrocompError
from gyrocomp.io import read
from gyrocomp.io.tables import write_recording
from gyrocomp.recording import POSSIBLE
from gyrocomp.simulation import simulate

from ..conftest import shared_dataset
from tests.io.log_writers import write_bag

pytest.importorskip("rosbags", reason="the [ros] extra (rosbags) is not installed")

DAMAGES = 24


def _hdf5(folder):
    rec = simulate("mti10", profile="chamber", duration_s=300, rate_hz=2, seed=3).recording
    path = folder / "run.h5"
    with h5py.File(path, "w") as fh:
        fh["time"] = rec.time_s
        fh["gyro"] = rec.gyro_dps
        fh["temperature"] = rec.temperature_degc
    return path, path


def _parquet(folder):
    path = folder / "run.parquet"
    write_recording(simulate("mti10", profile="chamber", duration_s=300, rate_hz=2, seed=3).recording, path)
    return path, path


def _bag(kind):
    def make(folder):
        if kind == "ros1":
            path = folder / "run.bag"
            write_bag(path, ros2=False, n=300)
            return path, path
        write_bag(folder / "bag", ros2=True, n=300, mcap=kind == "mcap")
        return folder / "bag", next(p for p in (folder / "bag").iterdir() if p.suffix in (".db3", ".mcap"))

    return make


def _shared(dataset, name):
    def make(folder):
        path = shared_dataset(dataset) / name
        copy = folder / name
        shutil.copyfile(path, copy)
        return copy, copy

    return make


MAKERS = {
    "hdf5": _hdf5,
    "parquet": _parquet,
    "ros1": _bag("ros1"),
    "ros2-sqlite3": _bag("sqlite3"),
    "ros2-mcap": _bag("mcap"),
    "ulog": _shared("px4-pyulog-samples", "sample_log_small.ulg"),
    "dataflash": _shared("ardupilot-pymavlink-sample", "test.BIN"),
}


def _damaged(blob: bytes, rng: np.random.Generator, k: int) -> bytes:
    """Damage k of three kinds: cut short, 1..16 bytes overwritten, or a stretch of up to 4 KiB zeroed (a flash
    page or card sector lost; in a DataFlash log it made pymavlink loop for ever on a format of length 0)."""
    if k % 3 == 0:
        return blob[: int(rng.integers(1, len(blob)))]
    damaged = bytearray(blob)
    if k % 3 == 2:
        at, length = int(rng.integers(0, len(blob))), int(rng.integers(1, 4097))
        damaged[at : at + length] = bytes(len(damaged[at : at + length]))
        return bytes(damaged)
    for at in rng.integers(0, len(blob), size=int(rng.integers(1, 17))):
        damaged[at] = int(rng.integers(0, 256))
    return bytes(damaged)


@pytest.mark.parametrize("fmt", sorted(MAKERS))
def test_a_damaged_binary_is_read_as_possible_values_or_refused_naming_it(fmt, tmp_path):
    if fmt in ("hdf5",):
        pytest.importorskip("h5py")
    intact, inner = MAKERS[fmt](tmp_path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        whole = read(intact).n_samples
    blob = inner.read_bytes()
    rng = np.random.default_rng(sorted(MAKERS).index(fmt))
    outcomes = {"read": 0, "refused": 0}
    for k in range(DAMAGES):
        copy = tmp_path / f"damaged{k}"
        if intact.is_dir():
            shutil.copytree(intact, copy)
            target = copy
            (copy / inner.name).write_bytes(_damaged(blob, rng, k))
        else:
            target = copy.with_suffix(intact.suffix)
            target.write_bytes(_damaged(blob, rng, k))
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always")
            try:
                rec = read(target)
            except GyrocompError as exc:
                assert str(target) in str(exc) and "\n" not in str(exc), str(exc)
                outcomes["refused"] += 1
                continue
        outcomes["read"] += 1
        for kind, values in (("gyro", rec.gyro_dps), ("accel", rec.accel_g), ("temperature", rec.temperature_degc)):
            if values is not None:
                lo, hi, _ = POSSIBLE[kind]
                assert np.all((values >= lo) & (values <= hi)), (kind, k)
        if k % 3 and fmt.startswith("ros") and rec.n_samples < whole:  # bytes overwritten or zeroed, the length kept
            assert any(issubclass(w.category, DataQualityWarning) for w in said), (k, rec.n_samples, whole)
    assert outcomes["refused"] > 0, outcomes  # the damage is real: some copies cannot be read
