"""A large file read for a fit is gathered from its chunks into columns held in temporary files: the recording, its
warnings and the fitted model are those of reading it whole, the files go when the recording does, and a bad file
is refused as a whole read refuses it. The checks a fit makes of a run, taken a part at a time, give what they gave
over the whole run, however the parts fall."""

from __future__ import annotations

import gc
import json
import warnings

import numpy as np
import pytest

import gyrocomp.curves.hysteresis as hysteresis_module
import gyrocomp.fitting.selection as selection_module
import gyrocomp.measures.data_check as data_check_module
import gyrocomp.spilled_series as spilled_series
from gyrocomp.errors import InputError
from gyrocomp.files.chunks import ChunkSettings, GatheredRun, read_whole
from gyrocomp.io import read_input, write_recording
from gyrocomp.models.fit import fit_channels
from gyrocomp.recording import Recording
from gyrocomp.simulation import get_profile, simulate

from ..conftest import joined_recordings, run
from tests.io.log_writers import write_bag

#: every column of a recording
FIELDS = ("time_s", "gyro_dps", "temperature_degc", "accel_g", "row_numbers")
#: read in chunks of 700 rows, every column in a file from its first value
SMALL = ChunkSettings(chunk_rows=700, memory_bytes=0)


def _caught(func):
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        result = func()
    return result, sorted(str(w.message) for w in said)


@pytest.fixture(scope="module")
def chamber_with_gap():
    """A one-cycle chamber run of the consumer part at 2 Hz with its accelerometer, cut by a 60 s hole."""
    profile = get_profile("cycle", set_points_degc=(10.0, 50.0), cycles=1)
    rec = simulate("consumer", profile=profile, rate_hz=2.0, seed=3).recording
    half = rec.n_samples // 2
    shift = np.where(np.arange(rec.n_samples) >= half, 60.0, 0.0)
    return Recording(
        rec.time_s + shift,
        rec.gyro_dps,
        rec.gyro_axes,
        temperature_degc=rec.temperature_degc,
        accel_g=rec.accel_g,
        accel_axes=rec.accel_axes,
        source="chamber",
    )


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_a_large_table_gathered_from_its_chunks_is_the_whole_reads_recording(chamber_with_gap, suffix, tmp_path):
    path = tmp_path / f"run{suffix}"
    write_recording(chamber_with_gap, path)
    whole, said_whole = _caught(lambda: read_input(path).recording)
    gathered, said = _caught(lambda: read_whole(path, large_bytes=0, settings=SMALL))
    assert isinstance(gathered, GatheredRun) and said == said_whole
    rec = gathered.recording
    for name in FIELDS:
        np.testing.assert_array_equal(getattr(rec, name), getattr(whole, name))
    assert isinstance(rec.gyro_dps.base, np.memmap)  # the columns are files, read where they lie
    assert (rec.gaps, rec.rate_hz, rec.metadata, rec.source) == (
        whole.gaps,
        whole.rate_hz,
        whole.metadata,
        whole.source,
    )
    assert len(rec.gaps) == 1
    # below the size, the file is read whole, as read_input reads it
    small = read_whole(path, settings=SMALL)
    assert not isinstance(small, GatheredRun) and not isinstance(small.recording.gyro_dps.base, np.memmap)


def test_the_temporary_files_go_with_the_recording(chamber_with_gap, tmp_path):
    path = tmp_path / "run.parquet"
    write_recording(chamber_with_gap, path)
    rec = read_whole(
        path, large_bytes=0, settings=ChunkSettings(chunk_rows=700, scratch_dir=str(tmp_path), memory_bytes=0)
    )
    folders = [p for p in tmp_path.iterdir() if p.is_dir() and p.name.startswith("gyrocomp-")]
    assert len(folders) == len(FIELDS) and all(any(f.iterdir()) for f in folders)
    del rec
    gc.collect()
    assert not any(f.exists() for f in folders)


def test_a_gathered_bag_is_the_whole_reads_recording(tmp_path):
    """With a repeated stamp, a temperature topic that starts late and a stamp pair out of order: the same samples
    and the same warnings, once."""
    pytest.importorskip("rosbags", reason="bags need the [ros] extra (rosbags)")
    path = tmp_path / "in.bag"
    write_bag(path, ros2=False, n=3000, repeat=7, temperature_from=400, swap=1001)
    whole, said_whole = _caught(lambda: read_input(path).recording)
    gathered, said = _caught(lambda: read_whole(path, large_bytes=0, settings=SMALL).recording)
    assert said == said_whole and any("repeated time stamp" in m for m in said)
    for name in FIELDS:
        np.testing.assert_array_equal(getattr(gathered, name), getattr(whole, name))
    assert isinstance(gathered.gyro_dps.base, np.memmap) and gathered.metadata == whole.metadata


def test_a_bad_value_in_a_later_chunk_is_refused_as_a_whole_read_refuses_it(chamber_with_gap, tmp_path):
    path = tmp_path / "run.csv"
    write_recording(chamber_with_gap, path)
    lines = path.read_text().splitlines()
    fields = lines[2001].split(",")
    fields[1] = "nan"
    lines[2001] = ",".join(fields)
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError) as whole:
        read_input(path)
    with pytest.raises(InputError, match="row 2001, column 'gyro_x': nan is not a finite number") as gathered:
        read_whole(path, large_bytes=0, settings=SMALL)
    assert str(gathered.value) == str(whole.value)


def test_a_fit_of_a_gathered_file_is_the_fit_of_it_read_whole(chamber_with_gap, tmp_path):
    path = tmp_path / "run.parquet"
    write_recording(chamber_with_gap, path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        whole = fit_channels([read_input(path).recording]).to_dict()
        gathered = fit_channels([read_whole(path, large_bytes=0, settings=SMALL).recording]).to_dict()
    for d in (whole, gathered):
        d["provenance"].pop("created_utc")
    assert gathered == whole


@pytest.fixture
def small_parts(monkeypatch):
    """Every check a fit makes of a run taken 333 samples at a time (the parts fall anywhere)."""
    monkeypatch.setattr(spilled_series, "PART_ROWS", 333)


def test_the_fits_checks_in_small_parts_give_the_model_of_the_whole_run(chamber_with_gap, small_parts, tmp_path):
    """Block means, the still mask, the data check, the turning threshold and the temperature step, the
    recording's own checks: the model is the same to the bit."""
    path = tmp_path / "run.parquet"
    write_recording(chamber_with_gap, path)
    expected = tmp_path / "expected.json"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        parted = fit_channels([read_input(path).recording]).to_dict()
    assert run("--quiet", "fit", str(path), "-o", str(expected)).returncode == 0  # another process: the default parts
    whole = json.loads(expected.read_text())
    for d in (whole, parted):
        d["provenance"].pop("created_utc")
    assert parted == whole


def test_the_temperature_checks_in_parts_are_the_whole_series(small_parts):
    """The turning threshold, the register's step (a temperature read in 0.5 degC steps), the data check's
    quantization step and levels: the values of the formulas over the whole series."""
    rng = np.random.default_rng(5)
    ramp = np.concatenate([np.linspace(10, 50, 2000), np.linspace(50, 20, 1500)])
    noisy = ramp + rng.normal(0, 0.02, ramp.size)
    stepped = np.round(noisy / 0.5) * 0.5
    for t in (noisy, stepped):
        second = np.diff(t, 2)
        steps = np.abs(np.diff(t))
        steps = steps[steps > 0]
        lsb = steps.min() if np.allclose(steps / steps.min(), np.round(steps / steps.min()), atol=1e-6) else 0.0
        expected = max(10 * 1.4826 * np.median(np.abs(second)) / np.sqrt(6.0), 1.5 * lsb, 0.1)
        assert hysteresis_module.turn_threshold_degc(t) == expected
        assert data_check_module._levels([t[:1000], t[1000:]]) == np.unique(np.round(t, 1)).size
    assert selection_module.temperature_step_degc(stepped) == 0.5
    assert selection_module.temperature_step_degc(noisy) == 0.0
    assert data_check_module._quantization_step(stepped) == 0.5
    assert data_check_module._quantization_step(noisy) == 0.0


def test_a_recordings_checks_in_parts_name_the_rows_the_whole_names(small_parts):
    t = np.arange(2000) * 0.01
    gyro = np.zeros((2000, 3))
    gyro[1500, 2] = np.inf
    with pytest.raises(InputError, match=r"row 1501, column 'gyro_z': inf is not a finite number"):
        Recording(t, gyro, ("gyro_x", "gyro_y", "gyro_z"))
    gyro[1500, 2] = 2e6
    with pytest.raises(InputError, match=r"row 1501, column 'gyro_z': 2e\+06 deg/s is beyond what any sensor gives"):
        Recording(t, gyro, ("gyro_x", "gyro_y", "gyro_z"))
    gyro[1500, 2] = 0.0
    back = t.copy()
    back[1332] = back[1331]
    with pytest.raises(InputError, match=r"row 1333: time repeats \(13.31 s after 13.31 s\)"):
        Recording(back, gyro, ("gyro_x", "gyro_y", "gyro_z"))
    piece = Recording(t[:700], gyro[:700], ("gyro_x", "gyro_y", "gyro_z"), temperature_degc=np.full(700, 25.0))
    gapped = joined_recordings([piece] * 3, 5.0)
    assert [g.after_row for g in gapped.gaps] == [700, 1400] and gapped.rate_hz == 100.0
