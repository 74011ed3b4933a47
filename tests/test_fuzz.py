"""Fuzzing (#20): malformed CSV and Parquet tables, mutated model files, truncated and byte-flipped logs.

Every outcome must be a clean read (finite values only), a read with a DataQualityWarning, or an InputError:
never another exception, and never a non-finite value passed on as data.
"""

from __future__ import annotations

import copy
import functools
import json
import math
import types
import warnings

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gyrocomp import Polynomial, apply, fit_calibration
from gyrocomp.calibration import Calibration
from gyrocomp.errors import InputError
from gyrocomp.io import TableLayout, read, read_table
from gyrocomp.io.stream import TableStream
from gyrocomp.simulation import simulate

from .conftest import shared_dataset

FUZZ = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])

NAMES = ["time", "gyro_x", "gyro_y", "gyro_z", "accel_z", "temperature", "Time", " gyro_z ", "GyrZ", "t", ""]
CELLS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(-(10**30), 10**30).map(str),
    st.sampled_from(["", "nan", "NaN", "inf", "-inf", "1e308", "1e999", "abc", '"1"', "1,5", "0x10", " 3 ", "\t"]),
)


def assert_clean(recording) -> None:
    """What a reader hands on holds finite numbers only."""
    assert np.isfinite(recording.time_s).all() and np.isfinite(recording.gyro_dps).all()
    if recording.temperature_degc is not None:
        assert np.isfinite(recording.temperature_degc).all()
    if recording.accel_g is not None:
        assert np.isfinite(recording.accel_g).all()


def read_or_refuse(reader, *args, **kwargs):
    """The reader's recording, or None when it refused with an InputError (any other exception fails)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # warnings are an allowed outcome; what matters is the data
        try:
            return reader(*args, **kwargs)
        except InputError as exc:
            assert "\n" not in str(exc).strip(), str(exc)  # one line
            return None


@FUZZ
@given(
    header=st.lists(st.sampled_from(NAMES), min_size=1, max_size=7),
    rows=st.lists(st.lists(CELLS, min_size=0, max_size=8), min_size=0, max_size=6),
    delimiter=st.sampled_from([",", ";", "\t"]),
    drop=st.booleans(),
)
def test_malformed_csv_is_read_cleanly_or_refused(tmp_path_factory, header, rows, delimiter, drop):
    path = tmp_path_factory.mktemp("csv") / "f.csv"
    path.write_text("\n".join(delimiter.join(r) for r in [header, *rows]) + "\n", encoding="utf-8")
    data = read_or_refuse(read_table, path, drop_nonfinite=drop)
    if data is not None:
        assert_clean(data.recording)


@FUZZ
@given(
    header=st.sampled_from([b"time,gyro_x,gyro_y,gyro_z\n", b"time;gyro_z\r", b"Fs,100\r\n", b""]),
    body=st.binary(max_size=400),
)
def test_any_bytes_named_as_a_table_are_read_cleanly_or_refused_whole_and_streamed(tmp_path_factory, header, body):
    """Bytes of any kind after a header (a lone CR among them, a NUL, no UTF-8): a clean read or one line."""
    path = tmp_path_factory.mktemp("bytes") / "f.csv"
    path.write_bytes(header + body)
    data = read_or_refuse(read_table, path)
    if data is not None:
        assert_clean(data.recording)
    for chunk in read_or_refuse(lambda: list(TableStream(path).chunks())) or []:
        assert_clean(chunk.recording)


@FUZZ
@given(
    columns=st.dictionaries(
        st.sampled_from(NAMES[:6]), st.sampled_from(["float", "int", "str", "nan", "bool"]), min_size=1, max_size=6
    ),
    n=st.integers(0, 5),
    drop=st.booleans(),
)
def test_malformed_parquet_is_read_cleanly_or_refused(tmp_path_factory, columns, n, drop):
    rng = np.random.default_rng(n)
    make = {
        "float": lambda: np.cumsum(rng.random(n)),
        "int": lambda: np.arange(n),
        "str": lambda: ["a"] * n,
        "nan": lambda: np.full(n, np.nan),
        "bool": lambda: np.ones(n, dtype=bool),
    }
    path = tmp_path_factory.mktemp("pq") / "f.parquet"
    pd.DataFrame({name: make[kind]() for name, kind in columns.items()}).to_parquet(path)
    data = read_or_refuse(read_table, path, drop_nonfinite=drop)
    if data is not None:
        assert_clean(data.recording)


@functools.lru_cache(maxsize=1)
def _model_and_run():
    run = simulate("mti10", profile="chamber", duration_s=1800, rate_hz=2, seed=3).recording
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        calibration = fit_calibration([run], temperature=Polynomial(2))
    return calibration.to_dict(), run


def _paths(node, prefix=()):
    yield prefix
    if isinstance(node, dict):
        for key, value in node.items():
            yield from _paths(value, (*prefix, key))
    elif isinstance(node, list):
        for i, value in enumerate(node):
            yield from _paths(value, (*prefix, i))


JSON_VALUES = st.recursive(
    st.one_of(
        st.none(),
        st.booleans(),
        st.integers(-(10**40), 10**40),
        st.floats(allow_nan=True, allow_infinity=True),
        st.text(max_size=12),
    ),
    lambda inner: st.one_of(st.lists(inner, max_size=4), st.dictionaries(st.text(max_size=6), inner, max_size=3)),
    max_leaves=8,
)


@FUZZ
@given(data=st.data(), delete=st.booleans(), value=JSON_VALUES)
def test_mutated_model_files_load_and_apply_cleanly_or_are_refused(data, delete, value):
    model, run = _model_and_run()
    paths = [p for p in _paths(model) if p]
    path = data.draw(st.sampled_from(paths))
    mutated = copy.deepcopy(model)
    parent = mutated
    for key in path[:-1]:
        parent = parent[key]
    if delete:
        del parent[path[-1]]
    else:
        parent[path[-1]] = value
    try:
        calibration = Calibration.from_dict(json.loads(json.dumps(mutated)), "m.json")
    except InputError as exc:
        assert "\n" not in str(exc)
        return
    result = read_or_refuse(apply, calibration, run.take(slice(0, 200)))
    if result is not None:
        assert np.isfinite(result.gyro_dps).all()


def _mutations(blob: bytes, seed: int, count: int):
    """``count`` truncations and ``count`` corrupted copies (1-8 random bytes replaced) of ``blob``."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        yield "cut", blob[: int(rng.integers(1, len(blob)))]
        damaged = bytearray(blob)
        for at in rng.integers(0, len(blob), size=int(rng.integers(1, 9))):
            damaged[at] = int(rng.integers(0, 256))
        yield "flip", bytes(damaged)


@pytest.mark.parametrize(
    "dataset, name, extra",
    [("px4-pyulog-samples", "sample_log_small.ulg", "pyulog"), ("ardupilot-pymavlink-sample", "test.BIN", "pymavlink")],
)
def test_truncated_and_byte_flipped_logs_read_cleanly_or_are_refused(tmp_path, dataset, name, extra):
    pytest.importorskip(extra)
    folder = shared_dataset(dataset)
    source = folder / name
    blob = source.read_bytes()[:400_000]  # the head of the log keeps each read short
    for k, (how, mutated) in enumerate(_mutations(blob, seed=11, count=12)):
        path = tmp_path / f"{k}_{how}{source.suffix}"
        path.write_bytes(mutated)
        recording = read_or_refuse(read, path)
        if recording is not None:
            assert_clean(recording)
            assert math.isfinite(recording.rate_hz)


def test_layout_fuzz_helpers_see_every_outcome(tmp_path):
    """The helpers above can fail: a non-InputError escapes, a multi-line refusal and NaN data are caught."""
    with pytest.raises(ZeroDivisionError):
        read_or_refuse(lambda: 1 / 0)
    with pytest.raises(AssertionError):
        read_or_refuse(lambda: (_ for _ in ()).throw(InputError("two\nlines")))
    with pytest.raises(AssertionError):
        assert_clean(
            types.SimpleNamespace(
                time_s=np.zeros(2), gyro_dps=np.full((2, 1), np.nan), temperature_degc=None, accel_g=None
            )
        )
    (tmp_path / "ok.csv").write_text("time,gyro_z\n0,1\n1,2\n")
    assert read_or_refuse(read_table, tmp_path / "ok.csv", TableLayout()).recording.n_samples == 2
