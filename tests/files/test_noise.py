"""Files analysed in chunks: the spilled series and its exact median, the one-pass phase integration, and
`analyse_noise_file` / `evaluate_file` against the whole-file analysis they replace (CSV and Parquet, any chunk
size, held in memory or spilled to temporary files that are removed after), with the whole-file path taken for
gaps and triads."""

from __future__ import annotations

import dataclasses
import errno
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings as hsettings, strategies as st

from gyrocomp.allan import PhaseAccumulator, allan_deviation, to_phase
from gyrocomp.errors import InputError
from gyrocomp.evaluation import evaluate
from gyrocomp.io.tables import read_table, write_recording
from gyrocomp.models.fit import fit_channels
from gyrocomp.measures.noise import analyse_noise
from gyrocomp.files import ChunkSettings, analyse_noise_file, evaluate_file
from gyrocomp.simulation import simulate
import gyrocomp.spilled_series as spilled_series
from gyrocomp.spilled_series import SpillArray, WindowSums, block_median

from ..conftest import run


@pytest.fixture(scope="module")
def run_files(tmp_path_factory):
    """A held-out chamber run (temperature drift, 3 gyro and 3 accelerometer axes) as CSV and Parquet, and the
    same run with a 30 s gap."""
    rec = simulate("consumer", profile="chamber", rate_hz=2, duration_s=3600, seed=9, unit=3).recording
    folder = tmp_path_factory.mktemp("noise_file")
    paths = {}
    for suffix in ("csv", "parquet"):
        paths[suffix] = folder / f"run.{suffix}"
        write_recording(rec, paths[suffix])
    keep = np.ones(rec.n_samples, dtype=bool)
    keep[3000:3060] = False
    paths["gap"] = folder / "gap.csv"
    write_recording(rec.take(keep), paths["gap"])
    return paths


# --- spilled series -----------------------------------------------------------------------------------------


def test_a_spilled_series_holds_what_was_appended_and_its_file_goes_on_close(tmp_path):
    rng = np.random.default_rng(0)
    blocks = [rng.standard_normal(int(n)) for n in rng.integers(0, 500, 20)]
    with SpillArray(memory_bytes=8 * 1000, directory=tmp_path) as spilled, SpillArray() as held:
        for block in blocks:
            spilled.append(block)
            held.append(block)
        assert spilled.on_disk and not held.on_disk
        assert len(list(tmp_path.iterdir())) == 1
        assert np.array_equal(spilled.finish(), np.concatenate(blocks))
        assert np.array_equal(held.finish(), np.concatenate(blocks))
        with pytest.raises(InputError, match="values: the series is finished"):
            spilled.append([1.0])
    assert not list(tmp_path.iterdir())


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full, a device that is always full")
@pytest.mark.parametrize("values", [2_000_000, 10], ids=["written at once", "buffered until finished"])
def test_a_full_disk_under_a_spilled_series_names_its_file_and_leaves_nothing(values, tmp_path, monkeypatch):
    """The series' file put on a full disk (a link to /dev/full): the error names the file, in one line through
    the command line's mapping, and closing the series removes its folder."""
    folder = tmp_path / "gyrocomp-full"
    folder.mkdir()
    (folder / "series.f64").symlink_to("/dev/full")
    monkeypatch.setattr(spilled_series.tempfile, "mkdtemp", lambda **kwargs: str(folder))
    series = SpillArray(memory_bytes=0)
    with pytest.raises(OSError, match="No space left on device") as full:
        series.append(np.ones(values))
        series.finish()
    assert full.value.errno == errno.ENOSPC and full.value.filename == str(folder / "series.f64")
    series.close()
    assert not folder.exists()


def test_a_spilled_series_refuses_a_negative_memory_limit():
    with pytest.raises(InputError, match="memory_bytes: a whole number of bytes >= 0"):
        SpillArray(memory_bytes=-1)


@pytest.fixture(scope="module")
def monkeypatch_passes():
    """The passes :func:`block_median` makes over a series (each a walk of :func:`_inside`), listed as made."""
    passes = []
    inside = spilled_series._inside

    def counted(*args):
        passes.append(args[1:3])
        return inside(*args)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(spilled_series, "_inside", counted)
        yield passes


@hsettings(max_examples=60, deadline=None)
@given(
    st.integers(1, 3000),
    st.integers(1, 64),
    st.sampled_from(["normal", "rounded", "mostly equal", "ulps", "every exponent"]),
    st.integers(0, 2**31),
)
def test_block_median_is_numpys_median_exactly(monkeypatch_passes, n, block, kind, seed):
    """Whatever the values' spread, in at most six passes over the series after the one for its extremes."""
    rng = np.random.default_rng(seed)
    values = {
        "normal": lambda: rng.standard_normal(n),
        "rounded": lambda: np.round(rng.standard_normal(n), 1),
        "mostly equal": lambda: np.where(rng.random(n) < 0.01, rng.standard_normal(n), 0.01),
        # time steps of k / rate_hz stamps: a few distinct values float64 steps apart
        "ulps": lambda: 0.01 + rng.integers(-2, 3, n) * np.spacing(0.01),
        # second differences of an interpolated temperature: zeros and rounding errors of every size, both signs
        "every exponent": lambda: rng.choice([-1.0, 0.0, 1.0], n) * 10.0 ** rng.uniform(-310, -3, n),
    }[kind]()
    block = max(block, n // 40 + 1)  # up to 40 blocks: several, without a Python loop over thousands
    monkeypatch_passes.clear()
    assert block_median(values, block=block, whole=0) == np.median(values)
    assert len(monkeypatch_passes) <= 2 * 6 + 2  # each order statistic: six counting passes and its gathering


@hsettings(max_examples=60, deadline=None)
@given(
    st.integers(1, 40),
    st.lists(st.integers(0, 50), min_size=1, max_size=12),
    st.integers(1, 3),
    st.integers(0, 2**32 - 1),
)
def test_window_sums_given_in_any_parts_are_the_whole_series_cumsums_to_the_bit(w, lengths, columns, seed):
    """A window's sum is c[k + w] - c[k] of one np.cumsum over the whole series, however the series is parted."""
    x = np.random.default_rng(seed).normal(size=(sum(lengths), columns)) * 1e3
    c = np.cumsum(np.concatenate([np.zeros((1, columns)), x]), axis=0)
    expected = c[w:] - c[:-w] if x.shape[0] >= w else np.empty((0, columns))
    sums, got, start = WindowSums(w), [], 0
    for length in lengths:
        got.append(sums.add(x[start : start + length]))
        start += length
    np.testing.assert_array_equal(np.concatenate(got), expected)


def test_block_median_of_nothing_is_refused():
    with pytest.raises(InputError, match="values: the median of an empty series"):
        block_median(np.empty(0))


# --- phases in one pass -------------------------------------------------------------------------------------


@hsettings(max_examples=25, deadline=None)
@given(st.lists(st.integers(0, 700), min_size=1, max_size=8), st.sampled_from([0, 1 << 20]), st.integers(0, 2**31))
def test_any_chunking_gives_the_phase_to_phase_gives(sizes, memory_bytes, seed):
    rng = np.random.default_rng(seed)
    rate = rng.standard_normal((sum(sizes) + 2, 2)) * 0.01 + [1.5, -40.0] + np.linspace(0, 3, sum(sizes) + 2)[:, None]
    cuts = np.cumsum([0, *sizes, 2])
    with PhaseAccumulator(2, memory_bytes=memory_bytes) as accumulator:
        for a, b in zip(cuts[:-1], cuts[1:]):
            accumulator.update(rate[a:b])
        phases = accumulator.finish(50.0)
        np.testing.assert_allclose(accumulator.mean, rate.mean(axis=0), rtol=1e-13)
        for j in range(2):
            expected = to_phase(rate[:, j], 50.0)
            # the sums are about the first chunk's mean: equal to rounding of the largest partial sum
            scale = np.abs(np.cumsum(rate[:, j] - rate[: cuts[1] or 1, j].mean())).max() / 50.0 + 1e-300
            assert np.max(np.abs(phases[j] - expected)) <= 1e-12 * max(scale, np.abs(expected).max())


def test_a_phase_accumulator_refuses_wrong_shapes_and_short_data():
    with PhaseAccumulator(3) as accumulator:
        with pytest.raises(InputError, match=r"rate: expected shape \(n, 3\)"):
            accumulator.update(np.zeros((4, 2)))
        accumulator.update(np.zeros((1, 3)))
        with pytest.raises(InputError, match="rate: need at least 2 samples, got 1"):
            accumulator.finish(10.0)


def test_the_allan_deviation_of_the_accumulated_phase_is_the_rates(tmp_path):
    """Against the overlapping Allan deviation summed term by term in extended precision: the long factors
    (lag products of a phase dominated by the ramp's parabola) round at some 1e-8 on either path."""
    rng = np.random.default_rng(4)
    rate = rng.standard_normal(50_000) * 0.02 + np.linspace(-1, 1, 50_000)
    factors = np.array([1, 2, 7, 64, 391, 450, 1000, 5000, 12000])
    with PhaseAccumulator(1, memory_bytes=0, directory=tmp_path) as accumulator:
        for chunk in np.array_split(rate[:, None], 7):
            accumulator.update(chunk)
        phase = accumulator.finish(100.0)[0]
        assert isinstance(phase, np.memmap)
        from_phase = allan_deviation(phase, 100.0, data_type="phase", taus=factors / 100.0)
    direct = allan_deviation(rate, 100.0, taus=factors / 100.0)
    np.testing.assert_array_equal(from_phase.alpha, direct.alpha)
    exact = np.concatenate([[0], np.cumsum((rate - rate.mean()).astype(np.longdouble))]) / 100
    np.testing.assert_array_equal(np.round(from_phase.tau * 100).astype(int), factors)
    for j, m in enumerate(factors):
        d = exact[2 * m :] - 2 * exact[m:-m] + exact[: -2 * m]
        reference = float(np.sqrt(np.sum(d * d) / (2 * (m / 100) ** 2 * d.size)))
        assert from_phase.deviation[j] == pytest.approx(reference, rel=1e-7), m
        assert direct.deviation[j] == pytest.approx(reference, rel=1e-7), m
    assert not list(tmp_path.iterdir())


# --- a file's noise -----------------------------------------------------------------------------------------


def _same_noise(chunked, whole):
    assert chunked.rate_hz == whole.rate_hz and list(chunked.axes) == list(whole.axes)
    for name, axis in chunked.axes.items():
        other = whole.axes[name]
        for curve, reference in ((axis.curve, other.curve), (axis.allan, other.allan)):
            np.testing.assert_array_equal(curve.tau, reference.tau)
            np.testing.assert_allclose(curve.deviation, reference.deviation, rtol=1e-8)
            np.testing.assert_array_equal(curve.alpha, reference.alpha)
            np.testing.assert_allclose(curve.ci_high, reference.ci_high, rtol=1e-8)
        for key, value in axis.noise.summary().items():
            assert value == pytest.approx(other.noise.summary()[key], rel=1e-6, nan_ok=True), key


@pytest.mark.parametrize("suffix", ["csv", "parquet"])
@pytest.mark.parametrize("chunk_rows, memory_bytes", [(777, 0), (5000, 1 << 25)])
def test_a_files_noise_in_chunks_is_the_whole_files(run_files, tmp_path, suffix, chunk_rows, memory_bytes):
    chunks = ChunkSettings(chunk_rows=chunk_rows, memory_bytes=memory_bytes, scratch_dir=str(tmp_path))
    for kind, axes, accel, names in (
        ("oadev", None, False, ["gyro_x", "gyro_y", "gyro_z"]),
        ("mdev", ["gyro_z", "accel_x"], True, ["gyro_z", "accel_x", "accel_y", "accel_z"]),
    ):
        chunked = analyse_noise_file(run_files[suffix], axes, with_accel=accel, kind=kind, chunks=chunks)
        whole = analyse_noise(read_table(run_files[suffix]).recording, names, kind=kind)
        _same_noise(chunked, whole)
    assert not list(tmp_path.iterdir())  # the spilled phases are removed


def test_a_file_with_a_gap_is_refused_or_split_as_a_whole_file_is(run_files):
    with pytest.raises(InputError, match=r"gap\.csv: time gap of 30\.5 s after row 3000 .*split_gaps=True"):
        analyse_noise_file(run_files["gap"], chunks=ChunkSettings(chunk_rows=500))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        whole = analyse_noise(read_table(run_files["gap"]).recording, split_gaps=True)
    split = analyse_noise_file(run_files["gap"], split_gaps=True, chunks=ChunkSettings(chunk_rows=500))
    assert split.stretches == 2 and split.how == whole.how
    _same_noise(split, whole)


def test_an_axis_the_file_lacks_is_named(run_files):
    with pytest.raises(InputError, match=r"axes: 'gyro_w' is not in .*run\.csv; it has gyro_x, gyro_y, gyro_z"):
        analyse_noise_file(run_files["csv"], ["gyro_w"])
    with pytest.raises(InputError, match=r"axes: 'accel_q' is not in .*run\.parquet; it has gyro_x"):
        analyse_noise_file(run_files["parquet"], ["accel_q"])


# --- a file's evaluation ------------------------------------------------------------------------------------


def _same_evaluation(chunked, whole):
    assert len(chunked.runs) == len(whole.runs) == 1
    a, b = chunked.runs[0], whole.runs[0]
    assert a.file == b.file and a.window_s == pytest.approx(b.window_s, rel=1e-12)
    assert list(a.axes) == list(b.axes) and list(a.accel_axes) == list(b.accel_axes)
    for mine, theirs in [(a.axes[k], b.axes[k]) for k in a.axes] + [
        (a.accel_axes[k], b.accel_axes[k]) for k in a.accel_axes
    ]:
        assert mine.unit == theirs.unit
        for key, value in mine.to_dict().items():
            assert value == pytest.approx(theirs.to_dict()[key], rel=1e-8), key


@pytest.mark.parametrize("suffix", ["csv", "parquet"])
@pytest.mark.parametrize("window", [None, 120.0])
def test_a_files_evaluation_in_chunks_is_the_whole_files(consumer_model, run_files, tmp_path, suffix, window):
    chunks = ChunkSettings(chunk_rows=611, memory_bytes=0, scratch_dir=str(tmp_path))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        whole = evaluate(consumer_model, read_table(run_files[suffix]).recording, turn_on_window_s=window)
        chunked = evaluate_file(consumer_model, run_files[suffix], turn_on_window_s=window, chunks=chunks)
        fixed = evaluate_file(consumer_model, run_files[suffix], window_s=30.0, chunks=chunks)
        fixed_whole = evaluate(consumer_model, read_table(run_files[suffix]).recording, window_s=30.0)
    _same_evaluation(chunked, whole)
    _same_evaluation(fixed, fixed_whole)
    # the compensation did something: the figures are not those of the raw run
    assert chunked.runs[0].axes["gyro_x"].offset_improvement > 2
    assert not list(tmp_path.iterdir())


def test_a_files_evaluation_with_a_gap_is_the_whole_files(consumer_model, run_files):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        whole = evaluate(consumer_model, read_table(run_files["gap"]).recording)
        chunked = evaluate_file(consumer_model, run_files["gap"], chunks=ChunkSettings(chunk_rows=500))
    _same_evaluation(chunked, whole)


def test_evaluate_file_refuses_what_is_no_calibration(run_files):
    with pytest.raises(InputError, match="calibration: expected a Calibration"):
        evaluate_file({"axes": {}}, run_files["csv"])


def test_a_bad_row_half_way_leaves_no_temporary_file(consumer_model, run_files, tmp_path):
    lines = run_files["csv"].read_text().splitlines()
    cells = lines[5000].split(",")
    cells[2] = "nan"
    lines[5000] = ",".join(cells)
    bad = tmp_path / "bad.csv"
    bad.write_text("\n".join(lines) + "\n")
    scratch = tmp_path / "scratch"
    scratch.mkdir()
    chunks = ChunkSettings(chunk_rows=700, memory_bytes=0, scratch_dir=str(scratch))
    with pytest.raises(InputError, match=r"bad\.csv: row 5000, column 'gyro_y'"):
        analyse_noise_file(bad, chunks=chunks)
    with pytest.raises(InputError, match=r"bad\.csv: row 5000, column 'gyro_y'"):
        evaluate_file(consumer_model, bad, chunks=chunks)
    assert not list(scratch.iterdir())


def test_a_model_with_the_accelerometer_is_judged_on_both_sensors_in_chunks(run_files, tmp_path):
    runs = [
        simulate("consumer", profile="chamber", rate_hz=2, duration_s=3600, seed=s, unit=3).recording for s in range(2)
    ]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = fit_channels(runs, ("gyro", "accel"))
        whole = evaluate(model, read_table(run_files["parquet"]).recording)
        chunked = evaluate_file(
            model, run_files["parquet"], chunks=ChunkSettings(chunk_rows=450, memory_bytes=0, scratch_dir=str(tmp_path))
        )
    assert model.accel_axes and list(chunked.runs[0].accel_axes) == ["accel_x", "accel_y", "accel_z"]
    _same_evaluation(chunked, whole)
    assert not list(tmp_path.iterdir())


def test_a_compensation_beyond_any_sensors_range_is_refused_naming_its_row(consumer_model, run_files, tmp_path):
    """A corrupt temperature (1e308 degC) would send the model's tangent far past any rate a gyro measures (the
    mutation sweep found an internal error here); no sensor gives it, so it is refused where the file is read, in
    one line with its row, in chunks and whole."""
    lines = run_files["csv"].read_text().splitlines()
    header = lines[0].split(",")
    cells = lines[3001].split(",")
    cells[header.index("temperature")] = "1e308"
    lines[3001] = ",".join(cells)
    bad = tmp_path / "hot.csv"
    bad.write_text("\n".join(lines) + "\n")
    message = r"hot\.csv: row 3001, column 'temperature': 1e\+308 degC is beyond what any sensor gives"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for chunk_rows in (700, 10**6):
            with pytest.raises(InputError, match=message):
                evaluate_file(consumer_model, bad, chunks=ChunkSettings(chunk_rows=chunk_rows))
        with pytest.raises(InputError, match=message):
            evaluate(consumer_model, read_table(bad).recording)


@pytest.mark.slow
def test_allan_warns_when_the_log_moves_most_of_the_time(tmp_path):
    """As fit tells a field log: a log turning most of the time gets one warning, chunked or whole, and a still
    one none."""
    rec = simulate("consumer", profile="static", duration_s=1200, rate_hz=50, seed=4).recording
    t = rec.time_s
    turning = rec.gyro_dps + 30.0 * np.sin(2 * np.pi * t / 7.0)[:, None] * (np.sin(t / 40.0)[:, None] > -0.8)
    write_recording(rec, tmp_path / "still.csv")
    write_recording(dataclasses.replace(rec, gyro_dps=turning), tmp_path / "moving.csv")
    for extra in ([], ["--time", "0:"]):  # chunked, and the whole-file path
        moving = run("allan", tmp_path / "moving.csv", *extra)
        assert moving.returncode == 0, moving.stderr
        assert "moving.csv: the log moves most of the time" in moving.stderr and "--time" in moving.stderr
        still = run("allan", tmp_path / "still.csv", *extra)
        assert still.returncode == 0 and "moves most of the time" not in still.stderr
