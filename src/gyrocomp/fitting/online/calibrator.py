"""The online learner itself: :class:`OnlineCalibrator` (the algorithm is described in
:mod:`gyrocomp.fitting.online`)."""

from __future__ import annotations

import math
from typing import Literal

import numpy as np

from ...effects import lazy_lfilter
from ...errors import InputError, NotFittedError
from ...motion.stillness import MAX_ACCEL_NOISE_DENSITY, MAX_GYRO_NOISE_DENSITY
from .learner_files import LearnerFiles
from .settings import (
    GAP_PERIODS,
    LEVEL_GROWTH,
    LearnerSettings,
    LearnerStatus,
    MIN_OUTLIER_DOF,
    MIN_SESSION_POINTS,
    MIN_STEPS,
    PIECE_SPREAD_WEIGHT,
    POOL_PIECES,
    T_REF_DEGC,
    T_SCALE_DEGC,
    MAD_TO_SIGMA,
    chi2_quantile,
)
from .refit import shape_curve, design_matrix, forward_substitute, xyz_rows, tilted_axes, weighted_fit
from .blocks import fresh_dequantizer, c_quantile, block_statistics


class OnlineCalibrator(LearnerFiles):
    """The online learner (see the module).

    Parameters
    ----------
    settings : LearnerSettings or float
        The learner's settings, or only the stream's nominal sample rate [Hz] (the rest at their defaults).

    Use ``update(time_s, gyro_dps, accel_g, temperature_degc)`` for each chunk (a new power-on:
    :meth:`start_session`; :meth:`end_session` when a log ends), :attr:`status` for its state and confidence,
    :meth:`bias_dps` for the learned bias, :meth:`to_calibration` for a model file, :meth:`save`/:meth:`load`
    for its whole state.
    """

    def __init__(self, settings: LearnerSettings | float) -> None:
        if not isinstance(settings, LearnerSettings):
            settings = LearnerSettings(rate_hz=settings)
        self.settings = settings
        s = settings
        self._w = s.block_samples
        self._z = s.z_values()
        self._noise_factor = (self._w - 2) / chi2_quantile(self._z["noise"], self._w - 2)
        self._bounds = {c: chi2_quantile(self._z[f"variance{c}"], self._w - 2) / (self._w - 2) for c in (3, 6)}
        self._ceiling = np.array([MAX_GYRO_NOISE_DENSITY**2] * 3 + [MAX_ACCEL_NOISE_DENSITY**2] * 3) * s.rate_hz
        self._lags = len(s.lag_candidates_s)
        self._init_stream()
        self._init_points(s.max_points)
        self._init_model()

    def _init_stream(self) -> None:
        """The stream, its noise levels and step spreads, the last blocks, the run and its piece."""
        r = self.settings.history_blocks
        self._session = 0
        self._accel: bool | None = None
        self._buffer = np.zeros((self._w, 6 + self._lags))
        self._lag_state = np.zeros(self._lags)  # the lagged temperatures of the last good sample [degC]
        self._lag_t: float | None = None  # its time [s] (None: the filters start on the next sample)
        self._dq = fresh_dequantizer()
        self._fill = 0
        self._last_t: float | None = None
        self._t0 = 0.0
        self._base_clock = 0.0
        self._clock = 0.0
        self._broken = True
        # noise levels and step spreads
        self._var_ring = np.zeros((r, 6))
        self._var_count = np.zeros(6, dtype=int)
        self._step_ring = np.zeros((r, 6))
        self._step_count = np.zeros(6, dtype=int)
        self._ring_pos = np.zeros(6, dtype=int)
        self._step_pos = np.zeros(6, dtype=int)
        self._level = np.full(6, np.nan)
        # the last blocks: mean (6), temperature, quiet, agree, linked, still, accel
        self._recent: list[dict] = []
        # the run and its piece
        self._run_s = 0.0
        self._piece = np.zeros(7 + self._lags)  # sums of gyro (3), accelerometer (3), temperatures (lags); samples
        self._piece_bin = -1
        self._pool: list[tuple] = []  # the session's last rejected pieces: (bin, bias, accel, temperatures, s)

    def _init_points(self, n: int) -> None:
        self._pt_bias = np.zeros((n, 3))
        self._pt_t = np.zeros((n, self._lags))  # mean temperature through each candidate lag [degC]
        self._pt_accel = np.zeros((n, 3))
        self._pt_s = np.zeros(n)
        self._pt_clock = np.zeros(n)
        self._pt_session = np.zeros(n, dtype=int)  # 0: a free slot
        self._pt_bin = np.full(n, -1)  # the temperature bin of each point

    def _init_model(self) -> None:
        self._degree = -1
        self._coef = np.zeros((3, 3))
        self._g = np.zeros((3, 3))  # g-sensitivity [deg/s/g], gyro axis x accelerometer axis
        self._tilted = np.zeros(3, dtype=bool)  # the accelerometer axes whose g-sensitivity is fitted
        self._lower = np.zeros((0, 0))  # Cholesky factor of the last fit's normal matrix
        self._scale2 = np.zeros(3)  # rms^2 sum(w) / n of the last fit, per axis
        self._dof = 0  # its residual degrees of freedom
        self._piece_var = np.full(3, np.nan)  # running mean square of accepted pieces' residuals [(deg/s)^2]
        self._offset_cache: tuple[int, np.ndarray] | None = None  # (session, its median offset)
        self._residual: np.ndarray | None = None
        self._sessions = np.zeros(0, dtype=int)
        self._constants = np.zeros((0, 3))
        self._rms = np.zeros(3)
        self._t_range = (0.0, 0.0)
        self._lag_index = 0  # the candidate lag the model uses
        self._saved: dict | None = None
        self._should_save = False
        self._counts = {"still_s": 0.0, "rejected_bound": 0, "rejected_outliers": 0, "stale_dropped": 0}
        self._lineage: tuple[str, ...] = ()  # the ids of the saved states this one goes on from, its own last

    # ---------------------------------------------------------------- the stream
    def start_session(self) -> None:
        """A new power-on: its own turn-on constant; the stream restarts (time may start again from zero)."""
        self.end_session()
        self._session += 1
        self._pool = []
        self._accel = None
        self._last_t = None
        self._lag_t = None
        self._dq = fresh_dequantizer()
        self._base_clock = self._clock
        self._drop_old_sessions()

    def end_session(self) -> None:
        """The log ends: a still piece being gathered is counted now (its run is over)."""
        if self._session:
            self._close_piece()
            self._run_s = 0.0
            self._recent = []
            self._fill = 0
            self._broken = True

    def update(self, time_s, gyro_dps, accel_g=None, temperature_degc=None) -> None:
        """Take the next samples: ``time_s`` (m,) [s] increasing, ``gyro_dps`` (m, 3) [deg/s] (x, y, z),
        ``accel_g`` (m, 3) [g] or None, ``temperature_degc`` (m,) [degC]. A sample with a non-finite value breaks
        the stream (it is skipped, and the block it falls in is dropped)."""
        if self._session == 0:
            self.start_session()
        t = np.asarray(time_s, dtype=float).reshape(-1)
        m = t.size
        if temperature_degc is None:
            raise InputError("temperature_degc: the learner needs the temperature of every sample")
        gyro = xyz_rows(gyro_dps, m, "gyro_dps")
        temperature = np.asarray(temperature_degc, dtype=float).reshape(-1)
        if temperature.size != m:
            raise InputError(f"temperature_degc: {temperature.size} values for {m} times")
        has_accel = accel_g is not None
        if self._accel is not None and has_accel != self._accel:
            raise InputError("accel_g: given in some chunks of a session and not in others")
        accel = xyz_rows(accel_g, m, "accel_g") if has_accel else np.zeros((m, 3))
        if m == 0:
            return
        if not np.all(np.isfinite(t)):
            raise InputError(f"time_s: not finite at sample {int(np.flatnonzero(~np.isfinite(t))[0])}")
        previous = self._last_t if self._last_t is not None else t[0] - 1.0 / self.settings.rate_hz
        steps = np.diff(np.concatenate([[previous], t]))
        if np.any(steps <= 0):
            raise InputError(
                f"time_s: does not increase at sample {int(np.flatnonzero(steps <= 0)[0])} of this "
                f"chunk ({t[np.flatnonzero(steps <= 0)[0]]!r} s after {previous!r} s)"
            )
        self._accel = has_accel
        if self._last_t is None:
            self._t0 = float(t[0])
        bad = ~(np.all(np.isfinite(gyro), axis=1) & np.all(np.isfinite(accel), axis=1) & np.isfinite(temperature))
        gap = GAP_PERIODS / self.settings.rate_hz
        breaks = (steps > gap) | bad
        rows = np.column_stack([gyro, accel, self._lagged(t, temperature, bad)])
        self._last_t = float(t[-1])
        clocks = self._base_clock + (t - self._t0)
        self._clock = float(clocks[-1])
        cuts = np.append(np.flatnonzero(breaks), m)
        start = 0
        for cut in cuts:
            if cut > start:
                self._feed(rows[start:cut], clocks[start:cut])
            if cut < m:  # a break before sample ``cut``: the partial block is dropped; a bad sample is skipped
                self._fill = 0
                self._broken = True
                start = cut + 1 if bad[cut] else cut

    def _lagged(self, t: np.ndarray, temperature: np.ndarray, bad: np.ndarray) -> np.ndarray:
        """The temperature through each candidate lag (m, lags) [degC]: y <- y + a (x - y), a = 1 - exp(-h/tau),
        h the nominal period, or the time since the last good sample across a gap; the filters start on the
        session's first good sample. Bad samples are skipped (NaN rows)."""
        out = np.full((t.size, self._lags), np.nan)
        good = np.flatnonzero(~bad)
        if good.size == 0:
            return out
        period = 1.0 / self.settings.rate_hz
        taus = self.settings.lag_candidates_s
        nominal = [1.0 - math.exp(-period / tau) if tau > 0 else 1.0 for tau in taus]
        steps = np.diff(np.concatenate([[np.nan if self._lag_t is None else self._lag_t], t[good]]))
        # runs of good samples each step within the gap threshold; the first sample of a run (and of the chunk)
        # is taken alone, with the nominal coefficient unless it follows a gap
        regular = steps <= GAP_PERIODS * period
        starts = np.union1d([0], np.flatnonzero(~regular))
        ends = np.append(starts[1:], good.size)
        x = self._dequantized(t[good], temperature[good])
        y = np.zeros((good.size, self._lags))
        state = self._lag_state.copy()
        for first, end in zip(starts, ends):
            for k, tau in enumerate(taus):
                if self._lag_t is None and first == 0:  # the session's first sample: in equilibrium
                    state[k] = x[0]
                elif tau > 0:
                    a = nominal[k] if regular[first] else 1.0 - math.exp(-steps[first] / tau)
                    state[k] = a * x[first] + (1.0 - a) * state[k]
                else:
                    state[k] = x[first]
                y[first, k] = state[k]
                if end > first + 1:
                    a = nominal[k]
                    if tau > 0:
                        y[first + 1 : end, k] = lazy_lfilter(
                            [a], [1.0, -(1.0 - a)], x[first + 1 : end], zi=[(1.0 - a) * state[k]]
                        )[0]
                    else:
                        y[first + 1 : end, k] = x[first + 1 : end]
                    state[k] = y[end - 1, k]
        self._lag_state = state
        self._lag_t = float(t[good[-1]])
        out[good] = y
        return out

    def _dequantized(self, t: np.ndarray, x: np.ndarray) -> np.ndarray:
        """The reported temperature with its steps undone (see the module, step 2): at a change the true value
        crossed the midpoint c = (x_i + x_(i-1))/2; between changes it moves on at the rate between the last two
        crossings, r = (c_k - c_(k-1)) / (t_k - t_(k-1)) (0 before the second), held within half the last step of
        the reading."""
        dq = self._dq
        state_c = np.nan if dq["crossing"] is None else dq["crossing"]
        previous = np.concatenate([[x[0] if dq["previous"] is None else dq["previous"]], x[:-1]])
        where = np.flatnonzero(x != previous)
        crossing = (x[where] + previous[where]) / 2.0
        half = np.abs(x[where] - previous[where]) / 2.0
        prior_c = np.concatenate([[state_c], crossing])[: where.size]
        prior_t = np.concatenate([[dq["time"]], t[where]])[: where.size]
        known = ~np.isnan(prior_c)
        rates = np.zeros(where.size)
        rates[known] = (crossing[known] - prior_c[known]) / (t[where][known] - prior_t[known])
        # the latest change at or before each sample (0: the state's)
        k = np.searchsorted(where, np.arange(x.size), side="right")
        c_k = np.concatenate([[state_c], crossing])[k]
        t_k = np.concatenate([[dq["time"]], t[where]])[k]
        r_k = np.concatenate([[dq["rate"]], rates])[k]
        h_k = np.concatenate([[dq["half"]], half])[k]
        with np.errstate(invalid="ignore"):
            out = np.where(np.isnan(c_k), x, np.minimum(np.maximum(c_k + r_k * (t - t_k), x - h_k), x + h_k))
        out[where] = crossing
        if where.size:
            dq.update(
                crossing=float(crossing[-1]), time=float(t[where[-1]]), rate=float(rates[-1]), half=float(half[-1])
            )
        dq["previous"] = float(x[-1])
        return out

    def _feed(self, rows: np.ndarray, clocks: np.ndarray) -> None:
        """Samples without a break: complete the pending block, then whole blocks, then keep the rest."""
        w = self._w
        i = 0
        if self._fill:
            take = min(w - self._fill, rows.shape[0])
            self._buffer[self._fill : self._fill + take] = rows[:take]
            self._fill += take
            i = take
            if self._fill < w:
                return
            self._blocks(self._buffer[None], clocks[i - 1 : i])
            self._fill = 0
        whole = (rows.shape[0] - i) // w
        if whole:
            self._blocks(
                rows[i : i + whole * w].reshape(whole, w, rows.shape[1]), clocks[i + w - 1 : i + whole * w : w]
            )
            i += whole * w
        rest = rows.shape[0] - i
        if rest:
            self._buffer[:rest] = rows[i:]
            self._fill = rest

    def _blocks(self, blocks: np.ndarray, clocks: np.ndarray) -> None:
        mean, var = block_statistics(blocks[:, :, :6])
        temperature = block_statistics(blocks[:, :, 6:])[0]
        for k in range(blocks.shape[0]):
            self._block(mean[k], var[k], temperature[k], float(clocks[k]))

    # ---------------------------------------------------------------- one block
    def _block(self, mean: np.ndarray, var: np.ndarray, temperature: np.ndarray, now: float) -> None:
        channels = 6 if self._accel else 3
        linked = not self._broken
        self._broken = False
        for c in range(channels):
            self._var_ring[self._ring_pos[c], c] = var[c]
            self._ring_pos[c] = (self._ring_pos[c] + 1) % self.settings.history_blocks
            self._var_count[c] = min(self._var_count[c] + 1, self.settings.history_blocks)
        quiet = True
        estimates = self._ring_quantiles(self._var_ring, self._var_count, channels, self.settings.noise_quantile)
        for c in range(channels):
            if self._var_count[c] < self.settings.history_blocks // 2:
                quiet = False
                continue
            estimate = float(estimates[c]) * self._noise_factor
            held = self._level[c] * LEVEL_GROWTH
            self._level[c] = estimate if not held < estimate else held
            if self._level[c] > self._ceiling[c]:
                quiet = False
            elif self._level[c] > 0 and var[c] > self._level[c] * self._bounds[channels]:
                quiet = False
        record = {
            "mean": mean,
            "temperature": temperature,
            "quiet": quiet,
            "linked": linked,
            "agree": True,
            "still": False,
        }
        previous = self._recent[-1] if self._recent and linked else None
        if previous is not None:
            record["agree"] = self._agree(previous, record, channels)
        if not self._recent:
            self._recent.append({"still": False, "linked": False})  # the start of the stream: never still
        self._recent.append(record)
        if len(self._recent) >= 3 and "mean" in self._recent[-2]:
            before = self._recent[-2]
            before["still"] = before["quiet"] and before["agree"] and record["agree"]
        if len(self._recent) >= 4:
            a, b, c_ = self._recent[-4], self._recent[-3], self._recent[-2]
            interior = a["still"] and b["still"] and c_["still"] and b["linked"] and c_["linked"]
            self._interior(b, interior, now)
            del self._recent[0]

    def _agree(self, previous: dict, record: dict, channels: int) -> bool:
        step = np.abs(record["mean"] - previous["mean"])
        both_quiet = previous["quiet"] and record["quiet"]
        agree = True
        medians = self._ring_quantiles(self._step_ring, self._step_count, channels, 0.5)
        for c in range(channels):
            level = self._level[c]
            if not level > 0:
                continue
            scale = math.sqrt(2.0 * level / self._w)
            if self._step_count[c] >= MIN_STEPS:
                robust = float(medians[c]) / MAD_TO_SIGMA
                scale = max(scale, robust)
            if step[c] > self._z[f"step{channels}"] * scale:
                agree = False
        if agree and both_quiet:
            for c in range(channels):
                self._step_ring[self._step_pos[c], c] = step[c]
                self._step_pos[c] = (self._step_pos[c] + 1) % self.settings.history_blocks
                self._step_count[c] = min(self._step_count[c] + 1, self.settings.history_blocks)
        return agree

    @staticmethod
    def _ring_quantiles(ring: np.ndarray, counts: np.ndarray, channels: int, q: float) -> np.ndarray:
        """The ``q`` quantile of each channel's filled part of a ring (NaN where empty); one sort for all
        channels when they hold as many values (the usual case), the same numbers as one channel at a time."""
        first = int(counts[0])
        if first and np.all(counts[:channels] == first):
            return c_quantile(ring[:first, :channels], q)
        return np.array([c_quantile(ring[: int(counts[c]), c], q) if counts[c] else np.nan for c in range(channels)])

    def _interior(self, block: dict, interior: bool, now: float) -> None:
        s = self.settings
        index = math.floor((block["temperature"][0] - s.t_low_degc) / s.bin_width_degc)
        if not interior or not 0 <= index < s.bins:
            self._close_piece(now)
            self._run_s = 0.0
            return
        if self._piece_bin >= 0 and index != self._piece_bin:
            self._close_piece(now)
        self._piece_bin = index
        self._piece[:6] += block["mean"] * self._w
        self._piece[6:-1] += block["temperature"] * self._w
        self._piece[-1] += self._w
        self._run_s += self._w / s.rate_hz
        if self._piece[-1] / s.rate_hz >= s.piece_s:
            self._close_piece(now)

    def _close_piece(self, now: float | None = None) -> None:
        if self._piece_bin >= 0 and self._run_s >= self.settings.min_still_s:
            samples = self._piece[-1]
            self._commit(
                self._piece_bin,
                self._piece[:3] / samples,
                self._piece[3:6] / samples,
                self._piece[6:-1] / samples,
                samples / self.settings.rate_hz,
                self._clock if now is None else now,
            )
        self._piece[:] = 0.0
        self._piece_bin = -1

    # ---------------------------------------------------------------- pieces, bins, the model
    def _commit(
        self, bin_index: int, bias: np.ndarray, accel: np.ndarray, temperature: np.ndarray, seconds: float, now: float
    ) -> None:
        s = self.settings
        if np.any(np.abs(bias) > s.max_bias_dps):
            self._counts["rejected_bound"] += 1
            return
        if self._is_outlier(bias, accel, temperature, piece=True):
            self._counts["rejected_outliers"] += 1
            self._to_pool(bin_index, bias, accel, temperature, seconds, now)
            return
        if self._residual is not None:  # the scatter of accepted pieces about the model, a running mean square
            square = self._residual * self._residual
            self._piece_var = (
                square
                if np.isnan(self._piece_var[0])
                else (1.0 - PIECE_SPREAD_WEIGHT) * self._piece_var + PIECE_SPREAD_WEIGHT * square
            )
        self._store(bin_index, bias, accel, temperature, seconds, now)
        self._refit(now)
        # the session's points judged again by the model they made: a bad first piece, accepted while its
        # session's constant was unknown, is found once the session has points enough for a robust constant
        mine = np.flatnonzero(self._pt_session == self._session)
        bad = [i for i in mine if self._is_outlier(self._pt_bias[i], self._pt_accel[i], self._pt_t[i])]
        if bad:
            dropped = [
                (
                    int(self._pt_bin[i]),
                    self._pt_bias[i].copy(),
                    self._pt_accel[i].copy(),
                    self._pt_t[i].copy(),
                    float(self._pt_s[i]),
                )
                for i in bad
            ]
            self._counts["rejected_outliers"] += len(bad)
            self._counts["still_s"] -= float(self._pt_s[bad].sum())
            self._pt_session[bad] = 0
            self._refit(now)
            for piece in dropped:
                self._to_pool(*piece, now)

    def _to_pool(
        self, bin_index: int, bias: np.ndarray, accel: np.ndarray, temperature: np.ndarray, seconds: float, now: float
    ) -> None:
        """A rejected piece (or a dropped point) into the session's pool; the pool replaces the session's points
        when it outvotes them."""
        self._pool = (self._pool + [(bin_index, bias, accel, temperature, seconds)])[-POOL_PIECES:]
        if self._pool_outvotes():
            self._swap_for_pool(now)

    def _pool_outvotes(self) -> bool:
        """Whether the session's last rejected pieces agree among themselves (each within the outlier limit of
        their median offset from the curve) and hold more still time than the session's points: then the
        points, not the pieces, were wrong (the power-on began with a slow turn)."""
        if len(self._pool) < MIN_SESSION_POINTS or self._degree < 0:
            return False
        offsets = np.array(
            [bias - self._shape(temps[self._lag_index]) - self._g @ accel for _, bias, accel, temps, _ in self._pool]
        )
        limit = np.maximum(self.settings.outlier_dps, self.settings.outlier_sigmas * self._rms)
        if np.any(np.abs(offsets - np.median(offsets, axis=0)) > limit):
            return False
        mine = self._pt_session == self._session
        return sum(piece[4] for piece in self._pool) > float(self._pt_s[mine].sum())

    def _swap_for_pool(self, now: float) -> None:
        mine = np.flatnonzero(self._pt_session == self._session)
        self._counts["rejected_outliers"] += mine.size - len(self._pool)
        self._counts["still_s"] -= float(self._pt_s[mine].sum())
        self._pt_session[mine] = 0
        for piece in self._pool:
            self._store(*piece, now)
        self._pool = []
        self._refit(now)

    def _store(
        self, bin_index: int, bias: np.ndarray, accel: np.ndarray, temperature: np.ndarray, seconds: float, now: float
    ) -> None:
        """A piece into its bin's point of this session, or a new point."""
        self._counts["still_s"] += seconds
        same = np.flatnonzero((self._pt_session == self._session) & (self._pt_bin == bin_index))
        if same.size:
            index = int(same[0])
            old = self._pt_s[index] * self._decay(now - self._pt_clock[index])
            total = old + seconds
            self._pt_bias[index] = (old * self._pt_bias[index] + seconds * bias) / total
            self._pt_t[index] = (old * self._pt_t[index] + seconds * temperature) / total
            self._pt_accel[index] = (old * self._pt_accel[index] + seconds * accel) / total
            self._pt_s[index] = total
        else:
            free = np.flatnonzero(self._pt_session == 0)
            # a free slot, else the point updated longest ago (a newer one replaces it)
            index = int(free[0]) if free.size else int(np.argmin(self._pt_clock))
            self._pt_bin[index] = bin_index
            self._pt_bias[index] = bias
            self._pt_t[index] = temperature
            self._pt_accel[index] = accel
            self._pt_s[index] = seconds
            self._pt_session[index] = self._session
        self._pt_clock[index] = now

    def _decay(self, age_s: float) -> float:
        return 2.0 ** (-age_s / (self.settings.half_life_h * 3600.0))

    def _is_outlier(
        self, bias: np.ndarray, accel: np.ndarray, temperatures: np.ndarray, *, piece: bool = False
    ) -> bool:
        """Whether a piece (``piece``: judged with the pieces' own scatter, which a point's averaging hides) or a
        point lies beyond the outlier limit (see the module, step 6); a judged piece's residual is kept in
        ``self._residual``."""
        self._residual = None
        if self._degree < 0:
            return False
        temperature = float(temperatures[self._lag_index])
        s = self.settings
        shape = self._shape(temperature) + self._g @ accel
        mine = np.flatnonzero(self._sessions == self._session)
        points = np.flatnonzero(self._pt_session == self._session)
        if points.size < MIN_SESSION_POINTS or mine.size == 0 or self._dof < MIN_OUTLIER_DOF:
            return False  # the session's constant is not known robustly yet, or the model is too young to judge
        predicted, spread2 = shape + self._session_offset(points), self._rms**2
        if piece and not np.isnan(self._piece_var[0]):
            spread2 = np.maximum(spread2, self._piece_var)
        sessions = np.zeros(self._sessions.size)
        sessions[mine[0]] = 1.0
        # the model's own uncertainty there: s^2 x' (X'WX)^-1 x, s^2 = rms^2 sum(w) / n
        u = (min(max(temperature, self._t_range[0]), self._t_range[1]) - T_REF_DEGC) / T_SCALE_DEGC
        x = np.concatenate([[u**k for k in range(1, self._degree + 1)], accel[self._tilted], sessions])
        z = forward_substitute(self._lower, x)
        spread2 = spread2 + self._scale2 * float(z @ z)
        # past the temperatures the model has seen it cannot judge a piece closely: the bias may move by up to
        # max_tempco_dps_per_degc for every degree beyond them
        low, high = self._t_range
        beyond = max(low - temperature, temperature - high, 0.0)
        limit = np.maximum(s.outlier_dps, s.outlier_sigmas * np.sqrt(spread2)) + s.max_tempco_dps_per_degc * beyond
        self._residual = bias - predicted
        return bool(np.any(np.abs(self._residual) > limit))

    def _session_offset(self, points: np.ndarray) -> np.ndarray:
        """This session's constant, robustly: the median of its points' offsets from the curve (kept until the
        model or the points change: every change is followed by a refit, which forgets it)."""
        if self._offset_cache is None or self._offset_cache[0] != self._session:
            offsets = (
                self._pt_bias[points]
                - self._shape(self._pt_t[points, self._lag_index])
                - self._pt_accel[points] @ self._g.T
            )
            self._offset_cache = (self._session, np.median(offsets, axis=0))
        return self._offset_cache[1]

    def _drop_old_sessions(self) -> None:
        old = (self._pt_session > 0) & (self._pt_session <= self._session - self.settings.max_sessions)
        if np.any(old):
            self._counts["stale_dropped"] += int(old.sum())
            self._pt_session[old] = 0
            self._refit(self._clock)

    def _refit(self, now: float) -> None:
        self._offset_cache = None
        s = self.settings
        stale = (self._pt_session > 0) & (now - self._pt_clock > s.stale_h * 3600.0)
        if np.any(stale):
            self._counts["stale_dropped"] += int(stale.sum())
            self._pt_session[stale] = 0
        used = np.flatnonzero(self._pt_session > 0)
        if used.size == 0:
            self._degree = -1
            return
        sessions = np.unique(self._pt_session[used])
        span = float(self._pt_t[used, 0].max() - self._pt_t[used, 0].min())
        degree = s.degree if span >= s.cubic_span_degc else (1 if span >= s.min_span_degc else 0)
        while degree > 0 and used.size < degree + sessions.size + 1:
            degree -= 1
        accel = self._pt_accel[used]
        tilted = tilted_axes(accel, self._pt_session[used], sessions, used.size - degree - sessions.size - 1)
        weights = np.array([self._pt_s[i] * self._decay(now - self._pt_clock[i]) for i in used])
        while True:
            # every candidate lag, the one leaving the smallest weighted residual kept (the first of equals)
            solution, chosen = None, -1
            for k in range(self._lags):
                fit = weighted_fit(
                    self._pt_t[used, k],
                    accel,
                    tilted,
                    self._pt_session[used],
                    sessions,
                    self._pt_bias[used],
                    weights,
                    degree,
                )
                if fit is not None and (solution is None or fit[-1] < solution[-1]):
                    solution, chosen = fit, k
            if solution is not None or degree == 0:
                break
            degree -= 1
        if solution is None:  # cannot happen with positive weights; kept as a guard
            return
        coef, g, constants, rms, self._lower, self._scale2, _ = solution
        self._dof = used.size - self._lower.shape[0]
        self._lag_index = chosen
        temps = self._pt_t[used, chosen]
        self._degree = degree
        self._coef = np.zeros((3, 3))
        self._coef[:, :degree] = coef.T
        self._g = np.zeros((3, 3))
        self._g[:, tilted] = g.T
        self._tilted = tilted
        self._sessions = sessions
        self._constants = constants
        self._rms = rms
        self._t_range = (float(temps.min()), float(temps.max()))
        self._should_save = self._changed()

    def _shape(self, temperature) -> np.ndarray:
        return shape_curve(self._coef, self._degree, self._t_range, temperature)

    def _changed(self) -> bool:
        if self._saved is None:
            return True
        if self._saved["degree"] != self._degree or self._saved["t_range"] != self._t_range:
            return True
        temps = self._pt_t[self._pt_session > 0, self._lag_index]
        now = self._shape(temps) + self._constants.mean(axis=0)
        before = shape_curve(self._saved["coef"], self._saved["degree"], self._t_range, temps) + self._saved["constant"]
        return bool(np.max(np.abs(now - before)) > self.settings.save_change_dps)

    def mark_saved(self) -> None:
        """The current model was saved: ``should_save`` turns false until it changes enough again."""
        if self._degree >= 0:
            self._saved = {
                "degree": self._degree,
                "coef": self._coef.copy(),
                "t_range": self._t_range,
                "constant": self._constants.mean(axis=0),
            }
        self._should_save = False

    # ---------------------------------------------------------------- results
    def bias_dps(
        self, temperature_degc, accel_g=None, *, session: Literal["current", "mean"] = "current"
    ) -> np.ndarray:
        """The learned bias [deg/s] (..., 3) at ``temperature_degc`` [degC] (the temperature the model reads:
        through its lag, :attr:`lag_time_constant_s`) and specific force ``accel_g`` (..., 3) [g] (None: no
        g-sensitivity term): the curve plus this session's constant (``"current"``, when it has one; else the
        mean) or the mean constant of the sessions kept (``"mean"``)."""
        if self._degree < 0:
            raise NotFittedError("the learner has no model yet: it has seen no still piece long enough")
        if session not in ("current", "mean"):
            raise InputError(f"session: {session!r}; use current or mean")
        mine = np.flatnonzero(self._sessions == self._session)
        constant = self._constants[mine[0]] if session == "current" and mine.size else self._constants.mean(axis=0)
        out = self._shape(temperature_degc) + constant
        if accel_g is not None:
            out = out + np.asarray(accel_g, dtype=float) @ self._g.T
        return out

    @property
    def model_temperature_degc(self) -> float:
        """The temperature the model reads now [degC]: the last good sample's, steps undone, through the model's
        lag (what :meth:`bias_dps` takes to give the bias at this moment)."""
        return float(self._lag_state[self._lag_index])

    @property
    def lag_time_constant_s(self) -> float:
        """The thermal lag [s] of the model: the candidate whose lagged temperature explains the bias best."""
        return self.settings.lag_candidates_s[self._lag_index]

    @property
    def should_save(self) -> bool:
        """Whether the model changed enough since :meth:`mark_saved` (or has never been saved)."""
        return self._should_save and self._degree >= 0

    @property
    def status(self) -> LearnerStatus:
        filled = self._pt_session > 0
        has = self._degree >= 0
        return LearnerStatus(
            sessions=self._session,
            points=int(filled.sum()),
            still_s=float(self._counts["still_s"]),
            rejected_bound=self._counts["rejected_bound"],
            rejected_outliers=self._counts["rejected_outliers"],
            stale_dropped=self._counts["stale_dropped"],
            degree=self._degree,
            lag_time_constant_s=self.lag_time_constant_s,
            t_min_degc=self._t_range[0] if has else None,
            t_max_degc=self._t_range[1] if has else None,
            rms_dps=tuple(float(v) for v in self._rms),
            uncertainty_dps=self._uncertainty(),
            should_save=self.should_save,
        )

    def _uncertainty(self) -> tuple[float, float, float]:
        used = np.flatnonzero(self._pt_session > 0)
        if self._degree < 0:
            return (math.inf,) * 3
        design = design_matrix(
            self._pt_t[used, self._lag_index],
            self._pt_accel[used],
            self._tilted,
            self._pt_session[used],
            self._sessions,
            self._degree,
        )
        sessions = self._sessions.size
        if used.size <= design.shape[1]:
            return (math.inf,) * 3
        weights = self._pt_s[used] * np.array([self._decay(self._clock - self._pt_clock[i]) for i in used])
        normal = design.T @ (design * weights[:, None])
        # the curve, the g-sensitivity and the mean constant at each bin's temperature and attitude
        at = np.column_stack([design[:, :-sessions], np.full((used.size, sessions), 1.0 / sessions)])
        # the covariance of the solution is s^2 (X'WX)^-1, s^2 = rms^2 sum(w) / n (the rms is per mean weight)
        leverage = np.einsum("ij,ij->i", at, np.linalg.solve(normal, at.T).T) * weights.sum() / used.size
        return tuple(float(r * math.sqrt(leverage.max())) for r in self._rms)


__all__ = ["OnlineCalibrator"]
