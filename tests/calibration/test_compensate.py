import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gyrocomp import Calibration, Compensator, Polynomial, apply, fit_calibration, read
from gyrocomp.errors import DataQualityWarning, InputError, TemperatureRangeWarning
from gyrocomp.recording import Recording
from gyrocomp.simulation import simulate

#: the run compensated: 120 s at 10 Hz
DURATION_S, RATE_HZ = 120, 10


@pytest.fixture(scope="module")
def sim():
    return simulate(duration_s=DURATION_S, rate_hz=RATE_HZ, seed=5)


@pytest.fixture(scope="module")
def cal():
    """A cubic fitted on two 10-minute runs (at first use, not when the module is imported)."""
    return fit_calibration(
        [simulate(duration_s=600, rate_hz=RATE_HZ, seed=s).recording for s in (1, 2)], temperature=Polynomial(3)
    )


def stream(cal, rec, cuts, **kw):
    comp = Compensator(cal, rec.gyro_axes, **kw)
    edges = [0, *sorted(cuts), rec.n_samples]
    blocks = [
        comp.update(rec.time_s[a:b], rec.gyro_dps[a:b], rec.temperature_degc[a:b])
        for a, b in zip(edges[:-1], edges[1:])
    ]
    blocks.append(comp.finish())
    return np.concatenate(blocks)


@settings(max_examples=60, deadline=None)
@given(
    cuts=st.lists(st.integers(0, DURATION_S * RATE_HZ), max_size=12),
    window=st.one_of(st.none(), st.floats(0.05, 200.0)),
)
def test_any_chunking_equals_batch(sim, cal, cuts, window):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        batch = apply(cal, sim.recording, turn_on_window_s=window).gyro_dps
        streamed = stream(cal, sim.recording, cuts, turn_on_window_s=window)
    assert streamed.shape == batch.shape
    np.testing.assert_allclose(streamed, batch, rtol=0, atol=1e-12)


def test_turn_on_window_uses_the_first_seconds(sim, cal):
    out = apply(cal, sim.recording, turn_on_window_s=10.0)
    head = sim.recording.time_s < 10.0
    np.testing.assert_allclose(out.gyro_dps[head].mean(axis=0), 0.0, atol=1e-12)


def test_turn_on_window_removes_this_runs_constant(sim, cal):
    """With the window, a run whose turn-on bias is far from the calibration runs' is still centred."""
    shifted = sim.recording.with_gyro(sim.recording.gyro_dps + 0.5)
    default = apply(cal, shifted).gyro_dps.mean(axis=0)
    windowed = apply(cal, shifted, turn_on_window_s=60.0).gyro_dps.mean(axis=0)
    assert np.all(np.abs(default) > 0.4)
    assert np.all(np.abs(windowed) < 0.05)


def test_window_longer_than_data_warns(sim, cal):
    with pytest.warns(UserWarning, match=r"shorter than the turn-on window of 1000 s"):
        apply(cal, sim.recording, turn_on_window_s=1000.0)


def test_warns_once_across_chunks(sim, cal):
    rec = sim.recording
    hot = rec.temperature_degc + 200
    comp = Compensator(cal, rec.gyro_axes)
    with pytest.warns(TemperatureRangeWarning) as record:
        for a in range(0, rec.n_samples, 100):
            comp.update(rec.time_s[a : a + 100], rec.gyro_dps[a : a + 100], hot[a : a + 100])
    assert len(record) == 1


def test_an_axis_the_model_lacks_is_refused_unless_the_axes_are_named():
    t = np.arange(600) / 10.0
    temp = np.linspace(10, 40, t.size)
    z_only = Recording(time_s=t, gyro_dps=1e-3 * temp, gyro_axes=("gyro_z",), temperature_degc=temp)
    cal_z = fit_calibration([z_only], temperature=Polynomial(1))
    both = Recording(
        time_s=t,
        gyro_dps=np.column_stack([np.ones(t.size), 1e-3 * temp]),
        gyro_axes=("gyro_x", "gyro_z"),
        temperature_degc=temp,
        source="both.csv",
    )
    with pytest.raises(
        InputError,
        match=r"both.csv: the model has no curve for gyro_x \(it covers gyro_z\); "
        r"give axes= with the axes to compensate",
    ):
        apply(cal_z, both)
    with pytest.warns(DataQualityWarning, match=r"both.csv: gyro_x left raw \(not among the axes to compensate\)"):
        out = apply(cal_z, both, axes=("gyro_z",))
    np.testing.assert_array_equal(out.gyro_dps[:, 0], 1.0)
    np.testing.assert_allclose(out.gyro_dps[:, 1], 0.0, atol=1e-12)
    with pytest.raises(InputError, match=r"axes: 'gyro_y' is not in the model or both.csv"):
        apply(cal_z, both, axes=("gyro_y",))
    # the model may cover more axes than the data has: those it has are compensated
    np.testing.assert_allclose(apply(cal_z, z_only).gyro_dps[:, 0], 0.0, atol=1e-12)


def test_errors(cal):
    with pytest.raises(InputError, match=r"turn_on_window_s: must be a positive number of seconds, got -1"):
        Compensator(cal, ("gyro_z",), turn_on_window_s=-1)
    with pytest.raises(
        InputError, match=r"the model covers gyro_x, gyro_y, gyro_z, the data has gyro_w; no axis in common"
    ):
        Compensator(cal, ("gyro_w",))
    comp = Compensator(cal, ("gyro_x", "gyro_y", "gyro_z"))
    with pytest.raises(InputError, match="the model needs temperature, the data has none"):
        comp.update(np.arange(3.0), np.zeros((3, 3)))


def test_wrong_calls_raise_input_errors_that_name_the_argument(sim, cal):
    rec = sim.recording
    with pytest.raises(InputError, match=r"calibration: expected a Calibration .* got NoneType"):
        apply(None, rec)
    with pytest.raises(InputError, match=r"recording: expected a Recording .* got str"):
        apply(cal, "flight.csv")
    with pytest.raises(InputError, match=r"path: expected a file name or path, got NoneType"):
        read(None)
    with pytest.raises(InputError, match=r"path: expected a model file name or path, got int"):
        Calibration.load(3)
    with pytest.raises(InputError, match=r"recordings\[1\]: expected a Recording .* got NoneType"):
        fit_calibration([rec, None])
    with pytest.raises(InputError, match=r"fit: give at least one calibration run"):
        fit_calibration(None)


def test_stream_chunks_are_checked(sim, cal):
    rec = sim.recording
    comp = Compensator(cal, rec.gyro_axes)
    t, g, temp = rec.time_s, rec.gyro_dps, rec.temperature_degc
    with pytest.raises(InputError, match=r"gyro_dps: shape \(10, 2\); give \(10, 3\) for 10 time stamps"):
        comp.update(t[:10], g[:10, :2], temp[:10])
    comp.update(t[:10], g[:10], temp[:10])
    with pytest.raises(InputError, match=r"time_s goes back from .* between chunks; give the chunks in time order"):
        comp.update(t[5:15], g[5:15], temp[5:15])
    bad = temp[10:20].copy()
    bad[3] = np.nan
    with pytest.raises(InputError, match=r"temperature_degc is not finite at row 3 of this chunk"):
        comp.update(t[10:20], g[10:20], bad)
    with pytest.raises(InputError, match=r"calibration: expected a Calibration"):
        Compensator({"axes": {}}, rec.gyro_axes)
