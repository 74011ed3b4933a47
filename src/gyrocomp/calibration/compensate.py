"""Applying a calibration: one streaming implementation, used for whole recordings too."""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np

from .calibration import Calibration
from ..curves.protocol import memory_offset
from ..effects import estimate_turn_on_bias, g_sensitivity_offset, temperature_rate, thermal_lag
from ..errors import DataQualityWarning, InputError, TemperatureRangeWarning, user_stacklevel
from ..io.stream import CHUNK_ROWS
from ..measures.plausibility import BlockMeans, ScaleAgreement, agreement_concern, recording_concerns, scale_agreement
from ..recording import ACCEL_AXES, GYRO_AXES, TEMPERATURE_COLUMN, Recording


class Compensator:
    """Streaming compensation: feed chunks with :meth:`update`, then call :meth:`finish`.

    Concatenating every returned block gives exactly what :func:`apply` gives for the
    whole recording, whatever the chunk sizes.

    Parameters
    ----------
    calibration : Calibration
    gyro_axes : tuple of str
        Names of the gyro columns in the chunks; axes the model does not know pass through unchanged.
    turn_on_window_s : float, optional
        Estimate each axis's turn-on constant as the mean residual over the first
        ``turn_on_window_s`` seconds [s] (output is held back until that window is complete).
        Default: subtract the mean turn-on constant of the calibration runs.
    rate_hz : float, optional
        Nominal sample rate of the stream [Hz]; needed when the model has thermal lag (its filter
        steps one nominal period per sample and bridges longer gaps exactly).

    Models with thermal lag or hysteresis carry their state (lag filter, turning-point detector)
    from one chunk to the next, so the chunking never changes the result. A model with accelerometer
    axes also compensates the accelerations (read them with :meth:`take_accel`), and its g-sensitivity
    reads the compensated ones.
    """

    def __init__(
        self,
        calibration: Calibration,
        gyro_axes: tuple[str, ...],
        *,
        turn_on_window_s: float | None = None,
        rate_hz: float | None = None,
        source: str = "<stream>",
    ):
        if not isinstance(calibration, Calibration):
            raise InputError(
                f"calibration: expected a Calibration (from fit_calibration or Calibration.load), "
                f"got {type(calibration).__name__}"
            )
        if turn_on_window_s is not None and not turn_on_window_s > 0:
            raise InputError(f"turn_on_window_s: must be a positive number of seconds, got {turn_on_window_s}")
        self.calibration = calibration
        self.gyro_axes = tuple(gyro_axes)
        self.turn_on_window_s = turn_on_window_s
        self.source = source
        self._modelled = [(j, calibration.axes[a]) for j, a in enumerate(self.gyro_axes) if a in calibration.axes]
        # each accelerometer axis with its error at the reference temperature, which the correction keeps; an axis
        # the fit left without a temperature model (none beat its constant) is not corrected
        reference = np.array([calibration.accel_reference_degc])
        self._accel_modelled = [
            (j, a, ax, float(np.asarray(ax.temperature.shape(reference), dtype=float)[0]))
            for j, a in enumerate(ACCEL_AXES)
            if (ax := calibration.accel_axes.get(a)) is not None and ax.temperature is not None
        ]
        self._triad_columns = self._gyro_triad_columns()
        if not self._modelled and not self._accel_modelled and calibration.accel_triad is None:
            raise InputError(
                f"{source}: the model covers {', '.join(calibration.axes)}, the data has "
                f"{', '.join(self.gyro_axes)}; no axis in common"
            )
        if rate_hz is not None and not rate_hz > 0:
            raise InputError(f"rate_hz: must be positive, got {rate_hz}")
        every = [ax for _, ax in self._modelled] + [ax for _, _, ax, _ in self._accel_modelled]
        if rate_hz is None and any(ax.lag_time_constant_s > 0 for ax in every):
            raise InputError(f"{source}: the model has thermal lag; give the stream's sample rate (rate_hz)")
        if rate_hz is None and any(ax.rate_term is not None for ax in every):
            raise InputError(
                f"{source}: the model has a temperature-rate term; give the stream's sample rate (rate_hz)"
            )
        self.rate_hz = rate_hz
        self._lag_states: dict[str, object] = {}
        self._rate_states: dict[str, object] = {}
        self._turn_states: dict[str, object] = {}
        self._accel_out: list[np.ndarray] = []
        self._warned = False
        self._t0: float | None = None
        self._constants: np.ndarray | None = None
        if turn_on_window_s is None:
            self._constants = np.array([ax.mean_turn_on_bias_dps for _, ax in self._modelled])
        self._last_time_s: float | None = None
        self._pending: list[np.ndarray] = []  # residuals (gyro - shape) held during the turn-on window
        self._pending_time: list[np.ndarray] = []
        self._pending_temp: list[np.ndarray | None] = []
        # the block means of each modelled axis's output and of the error the model predicts for it
        # (and of the temperature: the direction of its change tells a branch the model lacks from a unit mistake)
        self._agreement_blocks = BlockMeans(2 * len(self._modelled) + 1)

    def _gyro_triad_columns(self) -> list[int] | None:
        """The data's columns of gyro_x, gyro_y and gyro_z when the model has a gyro triad (None otherwise)."""
        if self.calibration.gyro_triad is None:
            return None
        missing = [a for a in GYRO_AXES if a not in self.gyro_axes]
        if missing:
            raise InputError(
                f"{self.source}: the model corrects scale factor and misalignment across gyro_x, gyro_y "
                f"and gyro_z; the data has no {', '.join(missing)}"
            )
        return [self.gyro_axes.index(a) for a in GYRO_AXES]

    def _model_temperature(self, key: str, ax, time_s: np.ndarray, temperature_degc: np.ndarray) -> np.ndarray:
        """The temperature the axis model reads: reported, or through the thermal lag (state carried)."""
        if ax.lag_time_constant_s <= 0:
            return temperature_degc
        lagged, self._lag_states[key] = thermal_lag(
            time_s,
            temperature_degc,
            ax.lag_time_constant_s,
            period_s=1.0 / self.rate_hz,
            state=self._lag_states.get(key),
        )
        return lagged

    def _temperature_error(
        self, key: str, ax, time_s: np.ndarray, t: np.ndarray, accel_g: np.ndarray | None
    ) -> np.ndarray:
        """The axis's temperature-driven error (shape, hysteresis and rate term) [deg/s, or g for an accelerometer]."""
        t_model = self._model_temperature(key, ax, time_s, t)
        if not self._warned and ax.temperature.outside_range(t_model):
            lagged = f" (through its {ax.lag_time_constant_s:.3g} s thermal lag)" if ax.lag_time_constant_s else ""
            warnings.warn(
                f"{self.source}: temperature{lagged} outside the model's range "
                f"{ax.temperature.t_min_degc:.2f}..{ax.temperature.t_max_degc:.2f} degC; "
                f"the model is {ax.temperature.beyond_range} there",
                TemperatureRangeWarning,
                stacklevel=user_stacklevel(),
            )
            self._warned = True
        error = np.asarray(ax.temperature.shape(t_model, accel_g if ax.temperature.needs_accel else None), dtype=float)
        if ax.hysteresis is not None:
            offset, self._turn_states[key] = memory_offset(ax.hysteresis, t_model, self._turn_states.get(key))
            error = error + offset
        if ax.rate_term is not None:
            rate, self._rate_states[key] = temperature_rate(
                time_s, t_model, ax.rate_term.smoothing_s, period_s=1.0 / self.rate_hz, state=self._rate_states.get(key)
            )
            error = error + ax.rate_term.offset(rate)
        return error

    def _compensate_accel(
        self, time_s: np.ndarray, temperature_degc: np.ndarray | None, accel_g: np.ndarray | None
    ) -> np.ndarray | None:
        """Accelerometer axes with their temperature error removed, relative to the model's reference [g]."""
        if not self._accel_modelled or accel_g is None or time_s.size == 0:
            return accel_g
        if temperature_degc is None:
            raise InputError(
                f"{self.source}: the model compensates the accelerometer for temperature; the data has no temperature"
            )
        t = temperature_degc if temperature_degc.ndim == 1 else temperature_degc.mean(axis=1)
        out = np.array(accel_g, dtype=float, copy=True)
        for j, name, ax, at_reference in self._accel_modelled:
            out[:, j] -= self._temperature_error(name, ax, time_s, t, None) - at_reference
        return out

    def _accel_output(
        self, time_s: np.ndarray, temperature_degc: np.ndarray | None, accel_g: np.ndarray | None
    ) -> np.ndarray | None:
        """The accelerations the gyro's g-sensitivity reads (temperature-compensated, as it was fitted), and the
        accelerometer output queued for :meth:`take_accel` (also bias, scale and misalignment corrected)."""
        accel_g = self._compensate_accel(time_s, temperature_degc, accel_g)
        if accel_g is not None and self.compensates_accel:
            triad = self.calibration.accel_triad
            if triad is None:
                self._accel_out.append(accel_g)
            else:
                self._accel_out.append(triad.correct(accel_g, self._triad_temperature(triad, temperature_degc)))
        return accel_g

    def _triad_temperature(self, triad, temperature_degc: np.ndarray | None) -> np.ndarray | None:
        """The temperature a triad's K(T) reads [degC] (the mean of several columns), None when K is constant."""
        if not triad.temperature_order:
            return None
        if temperature_degc is None:
            raise InputError(f"{self.source}: the model's scale factor depends on temperature; the data has none")
        return temperature_degc if temperature_degc.ndim == 1 else temperature_degc.mean(axis=1)

    @property
    def compensates_accel(self) -> bool:
        """Whether the model corrects the accelerometer (temperature models or a triad calibration; then
        :meth:`take_accel` gives the corrected accelerations)."""
        return bool(self._accel_modelled) or self.calibration.accel_triad is not None

    def take_accel(self) -> np.ndarray:
        """The compensated accelerometer rows [g] (n, 3) of the chunks given since the last call (empty when
        the model has no accelerometer axes); never held back. A stream calls it after each :meth:`update`,
        so the rows do not pile up."""
        rows = np.concatenate(self._accel_out) if self._accel_out else np.empty((0, 3))
        self._accel_out = []
        return rows

    def _residual(
        self,
        time_s: np.ndarray,
        gyro_dps: np.ndarray,
        temperature_degc: np.ndarray | None,
        accel_g: np.ndarray | None = None,
    ) -> np.ndarray:
        out = np.array(gyro_dps, dtype=float, copy=True)
        accel_g = self._accel_output(time_s, temperature_degc, accel_g)
        for j, ax in self._modelled:
            if ax.needs_accel and time_s.size:
                if accel_g is None:
                    raise InputError(
                        f"{self.source}: the model has g-sensitivity; the data needs accel_x, accel_y "
                        "and accel_z columns [g] (map them with columns=)"
                    )
                if ax.g_sensitivity_dps_per_g is not None or ax.g_squared_dps_per_g2 is not None:
                    g = np.zeros(3) if ax.g_sensitivity_dps_per_g is None else np.asarray(ax.g_sensitivity_dps_per_g)
                    q = None if ax.g_squared_dps_per_g2 is None else np.asarray(ax.g_squared_dps_per_g2)[None, :]
                    out[:, j] -= g_sensitivity_offset(accel_g, g[None, :], q)[:, 0]
                if ax.acceleration_network is not None:
                    out[:, j] -= ax.acceleration_network.shape(np.zeros(time_s.size), accel_g)
            if ax.temperature is None:
                continue
            if temperature_degc is None:
                raise InputError(f"{self.source}: the model needs temperature, the data has none")
            t = self._temperature_of(self.gyro_axes[j], ax, temperature_degc, j)
            if time_s.size == 0:
                continue
            out[:, j] -= self._temperature_error(self.gyro_axes[j], ax, time_s, t, accel_g)
        return out

    def _temperature_of(self, axis: str, ax, temperature_degc: np.ndarray, j: int) -> np.ndarray:
        """The temperature column the model of ``axis`` reads (its ``temperature_column``): the one shared column, or
        the axis's own of one per axis; a model fitted on one of them is not applied to the other without a word."""
        shared = ax.temperature_column == TEMPERATURE_COLUMN
        if temperature_degc.ndim == 1:
            if not shared:
                raise InputError(
                    f"{self.source}: the model of {axis} reads {ax.temperature_column!r} (one temperature "
                    "per axis); the data has one temperature column (map its columns with columns=)"
                )
            return temperature_degc
        if shared:
            raise InputError(
                f"{self.source}: the model of {axis} reads one temperature column ('temperature'); the "
                "data has one per axis (map the one to read with columns={'temperature': 'NAME'})"
            )
        return temperature_degc[:, j]

    def _subtract_constants(self, residual: np.ndarray, temperature_degc: np.ndarray | None) -> np.ndarray:
        """The bias-free residual, then (with a gyro triad) K(T)^-1 applied to the three axes [deg/s]."""
        for k, (j, _) in enumerate(self._modelled):
            residual[:, j] -= self._constants[k]
        triad = self.calibration.gyro_triad
        if triad is not None and residual.shape[0]:
            cols = self._triad_columns
            residual[:, cols] = triad.correct(residual[:, cols], self._triad_temperature(triad, temperature_degc))
        return residual

    def update(
        self,
        time_s: np.ndarray,
        gyro_dps: np.ndarray,
        temperature_degc: np.ndarray | None = None,
        accel_g: np.ndarray | None = None,
    ) -> np.ndarray:
        """Compensate one chunk: time [s] (m,), gyro [deg/s] (m, k), temperature [degC] (m,) or (m, k),
        specific force [g] (m, 3) on accel_x, accel_y, accel_z (needed by a model with g-sensitivity).

        Returns the compensated gyro rows [deg/s] that are ready: all of them, except while the
        turn-on window is still filling (those come out of a later call or :meth:`finish`).
        """
        time_s, gyro_dps, temperature_degc, accel_g = self._checked(time_s, gyro_dps, temperature_degc, accel_g)
        residual = self._residual(time_s, gyro_dps, temperature_degc, accel_g)
        if self._modelled:
            columns = [j for j, _ in self._modelled]
            output = gyro_dps[:, columns]
            temp = (
                np.full(time_s.size, np.nan) if temperature_degc is None else np.asarray(temperature_degc, dtype=float)
            )
            if temp.ndim == 2:  # one temperature per axis: their mean tells the direction of change as well
                temp = temp.mean(axis=1)
            self._agreement_blocks.add(time_s, [output, output - residual[:, columns], temp])
        if self._constants is not None:
            return self._subtract_constants(residual, temperature_degc)
        if self._t0 is None and time_s.size:
            self._t0 = float(time_s[0])
        self._pending.append(residual)
        self._pending_time.append(time_s)
        self._pending_temp.append(temperature_degc)
        if time_s.size and time_s[-1] - self._t0 >= self.turn_on_window_s:
            return self._release()
        return np.empty((0, len(self.gyro_axes)))

    def agreement(self) -> dict[str, ScaleAgreement | None]:
        """How each modelled gyro axis's output so far follows the error the model predicts for it
        (:func:`gyrocomp.measures.plausibility.scale_agreement` on 60 s block means; None with too little data or a
        prediction that does not vary): the slope is 1 when the model describes the data."""
        means = self._agreement_blocks.means()
        k = len(self._modelled)
        return {
            self.gyro_axes[j]: scale_agreement(means[:, i], means[:, k + i], means[:, 2 * k])
            for i, (j, _) in enumerate(self._modelled)
        }

    def _checked(self, time_s, gyro_dps, temperature_degc, accel_g):
        """The chunk as float arrays of the documented shapes, its time increasing from the previous chunk's and
        its temperature finite; anything else is refused naming the argument."""
        try:
            time_s = np.asarray(time_s, dtype=float).reshape(-1)
            n, k = time_s.size, len(self.gyro_axes)
            shapes = {"gyro_dps": (n, k), "temperature_degc": None, "accel_g": (n, 3)}
            arrays = {"gyro_dps": gyro_dps, "temperature_degc": temperature_degc, "accel_g": accel_g}
            for name, value in arrays.items():
                if value is None:
                    continue
                value = np.asarray(value, dtype=float)
                want = shapes[name]
                if name == "temperature_degc":
                    if value.shape not in ((n,), (n, k)) and not (value.ndim == 2 and value.shape[0] == n):
                        raise InputError(
                            f"temperature_degc: shape {value.shape}; give ({n},) or ({n}, {k}) for {n} time stamps"
                        )
                elif value.size != n * want[1]:
                    raise InputError(f"{name}: shape {value.shape}; give {want} for {n} time stamps")
                arrays[name] = value.reshape(want) if want else value
        except (TypeError, ValueError) as exc:
            raise InputError(f"{self.source}: a chunk that is not numbers ({exc})") from None
        if n and self._last_time_s is not None and time_s[0] <= self._last_time_s:
            raise InputError(
                f"{self.source}: time_s goes back from {self._last_time_s:.9g} s to {time_s[0]:.9g} s "
                "between chunks; give the chunks in time order"
            )
        if n > 1 and np.any(np.diff(time_s) <= 0):
            raise InputError(
                f"{self.source}: time_s does not increase within the chunk "
                f"(row {int(np.argmax(np.diff(time_s) <= 0)) + 1})"
            )
        temp = arrays["temperature_degc"]
        if temp is not None and temp.size and not np.all(np.isfinite(temp)):
            row = int(np.argmax(~np.isfinite(temp.reshape(n, -1)).any(axis=1)))
            raise InputError(
                f"{self.source}: temperature_degc is not finite at row {row} of this chunk; the "
                "compensation would be NaN (drop such rows or fill them before compensating)"
            )
        if n:
            self._last_time_s = float(time_s[-1])
        return time_s, arrays["gyro_dps"], temp, arrays["accel_g"]

    def _release(self) -> np.ndarray:
        residual = np.concatenate(self._pending)
        time_s = np.concatenate(self._pending_time)
        temps = None if any(t is None for t in self._pending_temp) else np.concatenate(self._pending_temp)
        self._pending, self._pending_time, self._pending_temp = [], [], []
        self._constants = np.array(
            [estimate_turn_on_bias(residual[:, j], time_s, self.turn_on_window_s) for j, _ in self._modelled]
        )
        return self._subtract_constants(residual, temps)

    def finish(self) -> np.ndarray:
        """Release rows still held back (a stream shorter than the turn-on window)."""
        if self._constants is not None or not self._pending:
            return np.empty((0, len(self.gyro_axes)))
        held_s = float(np.concatenate(self._pending_time)[-1] - self._t0)
        warnings.warn(
            f"{self.source}: the data lasts {held_s:.3g} s, shorter than the turn-on window of "
            f"{self.turn_on_window_s:g} s; the constant was estimated from all of it",
            UserWarning,
            stacklevel=user_stacklevel(),
        )
        return self._release()


def apply(
    calibration: Calibration,
    recording: Recording,
    *,
    turn_on_window_s: float | None = None,
    axes: tuple[str, ...] | None = None,
) -> Recording:
    """Compensate a whole recording; the result has the same rows, axes and other channels.

    The gyro axes the model covers are compensated [deg/s] (with a gyro triad, scale factor and misalignment
    corrected last); so are the accelerometer axes [g] when the model has accelerometer temperature models
    (then also a g-sensitivity term reads the compensated ones) or an accelerometer triad.

    Parameters
    ----------
    calibration : Calibration
        The model.
    recording : Recording
        The samples [s, deg/s, g, degC].
    turn_on_window_s : float, optional
        Estimate the run's turn-on constant from its first seconds [s] (default: the calibration runs' mean).
    axes : tuple of str, optional
        The gyro axes to compensate. By default every gyro axis of the recording, and a recording with a gyro
        axis the model has no curve for is refused (a model of another part, or a column mapped to the wrong
        axis, would otherwise leave it raw unnoticed); name axes to compensate only those, the others left raw
        with a warning saying which.
    """
    if not isinstance(recording, Recording):
        raise InputError(
            f"recording: expected a Recording (from gyrocomp.read or simulate), got {type(recording).__name__}"
        )
    if not isinstance(calibration, Calibration):
        raise InputError(
            f"calibration: expected a Calibration (from fit_calibration or Calibration.load), "
            f"got {type(calibration).__name__}"
        )
    comp = compensator_for(calibration, recording, axes=axes, turn_on_window_s=turn_on_window_s)
    accel, temperature = accel_xyz(recording), recording.temperature_degc
    parts = []
    # in the chunks a file is read in: the same output as one chunk, to the bit, and each chunk's intermediate
    # arrays a few MiB (a day at 100 Hz in one chunk allocates, and page-faults, several of 200 MiB)
    for start in range(0, recording.n_samples, CHUNK_ROWS):
        rows = slice(start, start + CHUNK_ROWS)
        parts.append(
            comp.update(
                recording.time_s[rows],
                recording.gyro_dps[rows],
                None if temperature is None else temperature[rows],
                None if accel is None else accel[rows],
            )
        )
    parts.append(comp.finish())
    warn_disagreement(comp)
    result = recording.with_gyro(np.concatenate(parts))
    if comp.compensates_accel:
        order = [ACCEL_AXES.index(a) for a in recording.accel_axes]
        result = dataclasses.replace(result, accel_g=comp.take_accel()[:, order])
    return result


def compensator_for(
    calibration: Calibration,
    recording: Recording,
    *,
    axes: tuple[str, ...] | None = None,
    turn_on_window_s: float | None = None,
) -> Compensator:
    """The :class:`Compensator` that :func:`apply` runs on ``recording`` (or on a file whose first chunk it is):
    the model limited to ``axes`` after checking the recording's axes against it, the recording's plausibility
    concerns warned about, the accelerometer's three axes required when the model compensates them."""
    calibration = _restricted(calibration, recording, axes)
    for concern in recording_concerns(recording):
        warnings.warn(concern.warning(), stacklevel=user_stacklevel())
    comp = Compensator(
        calibration,
        recording.gyro_axes,
        turn_on_window_s=turn_on_window_s,
        rate_hz=recording.rate_hz,
        source=recording.source,
    )
    if comp.compensates_accel and not set(ACCEL_AXES) <= set(recording.accel_axes):
        raise InputError(
            f"{recording.source}: the model compensates the accelerometer; the data needs accel_x, "
            "accel_y and accel_z columns [g]"
        )
    return comp


def warn_disagreement(comp: Compensator) -> None:
    """Warn (:class:`~gyrocomp.errors.PlausibilityWarning`, check ``agreement``) about each axis whose output did
    not follow the model (:meth:`Compensator.agreement`): a unit or sign mistake, or a model of another part."""
    for axis, agreement in comp.agreement().items():
        concern = agreement_concern(comp.source, axis, agreement)
        if concern is not None:
            warnings.warn(concern.warning(), stacklevel=user_stacklevel())


def accel_xyz(recording: Recording) -> np.ndarray | None:
    """The accelerometer in accel_x, accel_y, accel_z order [g] (what a :class:`Compensator` takes), or None
    without all three."""
    if recording.accel_g is None or not set(ACCEL_AXES) <= set(recording.accel_axes):
        return None
    if tuple(recording.accel_axes) == ACCEL_AXES:
        return recording.accel_g  # already in order: no copy of every chunk
    return recording.accel_g[:, [recording.accel_axes.index(a) for a in ACCEL_AXES]]


def _restricted(calibration: Calibration, recording: Recording, axes: tuple[str, ...] | None) -> Calibration:
    """The calibration limited to ``axes``, after checking the recording's gyro axes against the model's."""
    if not calibration.axes:  # an accelerometer-only model: the gyro passes through by design
        return calibration
    if axes is None:
        missing = [a for a in recording.gyro_axes if a not in calibration.axes]
        if missing:
            raise InputError(
                f"{recording.source}: the model has no curve for {', '.join(missing)} (it covers "
                f"{', '.join(calibration.axes)}); give axes= with the axes to compensate, the "
                "others are then left raw"
            )
        return calibration
    axes = tuple(axes)
    if calibration.gyro_triad is not None and set(axes) != set(GYRO_AXES):
        raise InputError(
            f"axes: {', '.join(axes)}; the model's scale-factor and misalignment correction couples "
            "gyro_x, gyro_y and gyro_z, compensate all three (or use calibration.without('scale-factor'))"
        )
    for axis in axes:
        where = [] if axis in calibration.axes else ["the model"]
        where += [] if axis in recording.gyro_axes else [recording.source]
        if where:
            raise InputError(
                f"axes: {axis!r} is not in {' or '.join(where)} (the model covers "
                f"{', '.join(calibration.axes)}; the data has {', '.join(recording.gyro_axes)})"
            )
    raw = [a for a in recording.gyro_axes if a not in axes]
    if raw:
        warnings.warn(
            f"{recording.source}: {', '.join(raw)} left raw (not among the axes to compensate)",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )
    return dataclasses.replace(calibration, axes={a: calibration.axes[a] for a in axes})


def predict_error(calibration: Calibration, recording: Recording) -> np.ndarray:
    """Predicted deterministic error (n, k) [deg/s] for the recording's gyro axes (0 where not modelled): the
    raw output less what :func:`apply` leaves, with the mean turn-on constant of the calibration runs."""
    return recording.gyro_dps - apply(calibration, recording).gyro_dps


def compensated_axes(
    calibration: Calibration, recording: Recording, axes: tuple[str, ...] | None, with_accel: bool
) -> tuple[str, ...]:
    """The axes :func:`apply` compensates in ``recording``: the gyro axes the model covers (those of ``axes``
    when given), and the accelerometer's when ``with_accel``."""
    done = [a for a in recording.gyro_axes if a in calibration.axes and (axes is None or a in axes)]
    return tuple(done + (list(recording.accel_axes) if with_accel else []))
