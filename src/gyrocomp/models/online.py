"""The online learner: a temperature model of the gyro bias learned from the still moments of a live stream.

:class:`OnlineCalibrator` takes samples as they arrive (any chunk size, one sample included) and does, with fixed
memory, what Android's over-temperature calibration (AOSP ``over_temp_cal``), ArduPilot's onboard learning
(``INS_TCALn_ENABLE=2``) and SlimeVR's tracker calibration do, in the way gyrocomp's batch stillness detector
(:mod:`gyrocomp.stillness`) decides what is still:

1. **Blocks.** The stream is cut into blocks of ``block_samples`` = max(10, round(block_s rate_hz)) samples; a
   time step longer than 1.5 nominal periods or a sample with a non-finite value breaks the stream (the partial
   block is dropped, and the next block has no neighbour). For each whole block and channel (gyro x, y, z
   [deg/s], accelerometer x, y, z [g] when given) the mean and the variance about the block's straight line
   (m - 2 degrees of freedom), from d_j = x_j - x_0: mean = x_0 + S1/m, var = (S2 - S1^2/m - SI^2/I2)/(m - 2),
   S1 = sum d_j, S2 = sum d_j^2, SI = sum (j - (m-1)/2) d_j, I2 = m(m^2 - 1)/12.
2. **The temperature** (degC) as the model reads it: first with the reported steps undone (a sensor that reports
   whole degrees is a staircase, which would make a longer lag look better): at each change of the reading the
   true value crossed the midpoint c = (x_i + x_(i-1))/2, and between changes it moves on at the rate between the
   last two crossings, held within half the last step of the reading (a continuous reading is barely touched);
   then through each candidate thermal lag of ``lag_candidates_s``: y <- y + a (x - y), a = 1 - exp(-h/tau), h the
   nominal period (or the time since the last good sample across a gap), starting on the session's first sample.
   The block keeps each one's mean.
3. **The noise level**, per channel, from the last ``history_blocks`` block variances: s^2 = Q_q(v) (m - 2) /
   chi2_q(m - 2) (q = ``noise_quantile``), held: s^2 <- min(estimate, s^2 * 1.001) per block, so a long move
   cannot raise it by more than 0.1 % a block (a sensor's noise does not jump); no level until half the history
   is filled. chi2 quantiles by Wilson and Hilferty (1931): chi2_p(k) = k (1 - 2/(9k) + z_p sqrt(2/(9k)))^3.
4. **Still blocks**: quiet (every channel's variance within s^2 chi2_{1-a}(m-2)/(m-2), a = alpha / channels,
   and the noise levels below the physical ceilings of :mod:`gyrocomp.stillness`), and its means agree with both
   neighbours' (|step| <= z_{1-a/2} d, d = max(sqrt(2 s^2/m), median |step| / 0.6745 over the last agreeing
   steps between quiet blocks), which tells a slow turn from stillness. A block inside a run of still blocks
   (both neighbours still, no break) is *interior*; the run's edges are dropped, as in batch.
5. **Pieces**: interior blocks accumulate into a piece while the temperature stays in one bin (``bin_width_degc``
   from ``t_low_degc``); a piece closes when the run ends, the bin changes or it reaches ``piece_s``; it counts
   only when its run has lasted ``min_still_s``. A piece is a bias estimate (its mean rate [deg/s]) at its mean
   temperature [degC] with its still time [s] as weight.
6. **Rejection**: a piece beyond ``max_bias_dps`` (no MEMS bias is that large: motion) is rejected. Once the
   model has MIN_OUTLIER_DOF residual degrees of freedom and the session MIN_SESSION_POINTS points, so is a piece
   farther from the model (curve, g-sensitivity and the session's constant, taken as the median offset of its
   points, so one bad point cannot poison it) than max(``outlier_dps``, ``outlier_sigmas`` sqrt(v + se^2)) on
   any axis (v the larger of the fit's residual mean square and the accepted pieces' running mean square residual,
   weight PIECE_SPREAD_WEIGHT, since a point averages many pieces; se the model's own standard error there), plus
   ``max_tempco_dps_per_degc`` for every degree it lies beyond the temperatures the model has seen: a bump, a slow
   turn read as still. After each refit the session's own points are judged the same way and those that fail are
   dropped (a bad first piece, accepted while the session's constant was unknown, goes once the session has
   points enough), and the model is refitted. The session's last POOL_PIECES rejected pieces are kept: when
   MIN_SESSION_POINTS of them or more agree among themselves (each within max(``outlier_dps``, ``outlier_sigmas``
   rms) of their median offset from the curve) and hold more still time than the session's points, the points
   were the wrong ones (a power-on that began with a slow turn): they are dropped and the pieces kept.
7. **Points** (at most ``max_points``) keep one estimate per temperature bin and session (bias [deg/s], mean
   specific force [g], the temperature through every candidate lag [degC], still time [s], and the time of the
   last update on the learner's clock, the operating time it has seen). A piece merges into its bin's point of
   the same session (weights: still times, the old one decayed); a new one takes a free slot or replaces the point
   updated longest ago. Points older than ``stale_h`` operating hours, or of a session older than the last
   ``max_sessions``, are dropped.
8. **The model**, refitted after every accepted piece by weighted least squares on the points: bias =
   sum_k c_k u^k + G a + b_session, u = (T_lag - 25) / 25 degC, one constant per session (each power-on has its own
   turn-on bias), G the g-sensitivity [deg/s/g] of the accelerometer axes the points excite (a range of
   MIN_TILT_G within one power-on, POINTS_PER_TILT spare points each); weights still time x 2^(-age / half_life_h). The degree is
   ``degree`` once the points span ``cubic_span_degc``, 1 from ``min_span_degc``, else 0 (constants only), and
   lower while there are too few points; solved by Cholesky on the normal equations for every candidate lag, the
   one leaving the smallest weighted residual kept. Past the temperatures it has seen the curve continues along
   its tangent (as the batch fit's).
9. **Saving**: ``should_save`` turns true when the model moved by more than ``save_change_dps`` at any point's
   temperature, or its range or degree changed, since :meth:`OnlineCalibrator.mark_saved`.

Batch and streaming are the same code (a chunk is cut into the same blocks, each block's statistics computed
from its own samples), so any chunking gives the same model; the C export's ``gyrocomp_learn_step`` does the
same sample by sample (:mod:`gyrocomp.export.c_learner`). The state saves to and loads from JSON
(:meth:`OnlineCalibrator.to_dict`), and :meth:`OnlineCalibrator.to_calibration` is a model file that
``gyrocomp apply`` takes.

Limits: a steady rotation about gravity looks still to any detector, and only the outlier test (against a model)
catches it, so a power-on whose first still piece turns slowly keeps a wrong constant; the lag is one of the
candidates (no finer); hysteresis is not modelled.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Iterable
from dataclasses import asdict, dataclass, fields
from pathlib import Path
from typing import Any, Literal

import numpy as np
from scipy.special import ndtri

from ..calibration import AxisCalibration, Calibration
from ..effects import lazy_lfilter
from .. import jsontext
from ..errors import InputError, NotFittedError
from ..io.atomic import write_text_atomic
from ..plausibility import TEMPERATURE_RANGE_DEGC
from ..recording import Recording
from ..stillness import MAX_ACCEL_NOISE_DENSITY, MAX_GYRO_NOISE_DENSITY, MIN_BLOCK_SAMPLES
from .base import provenance
from .temperature import PolynomialBias

LEARNER_FORMAT = "gyrocomp-learner"
LEARNER_SCHEMA_VERSION = 1
#: the curve's variable u = (T - T_REF_DEGC) / T_SCALE_DEGC
T_REF_DEGC = 25.0
T_SCALE_DEGC = 25.0
#: the held noise level may grow by this factor per block
LEVEL_GROWTH = 1.001
#: robust step spread once this many steps are known
MIN_STEPS = 10
#: a step between samples beyond this many nominal periods breaks the stream
GAP_PERIODS = 1.5
_MAD_TO_SIGMA = 0.6745
#: an accelerometer axis whose still means span this [g] has its g-sensitivity fitted
MIN_TILT_G = 0.3
#: spare points each fitted g-sensitivity column needs
POINTS_PER_TILT = 3
#: the outlier test waits for a fit with this many residual degrees of freedom, and for this many points of the
#: session (whose median offset is its constant)
MIN_OUTLIER_DOF = 5
MIN_SESSION_POINTS = 3
#: weight of each judged piece in the running mean square of the pieces' residuals
PIECE_SPREAD_WEIGHT = 0.05
#: the last rejected pieces of a session kept, to overrule its points when they agree and outweigh them
POOL_PIECES = 4
#: relative ridge on the normal equations' diagonal (guards a nearly singular system)
_RIDGE = 1e-12
GYRO_AXES = ("gyro_x", "gyro_y", "gyro_z")


def chi2_quantile(z: float, dof: float) -> float:
    """The chi-square quantile of ``dof`` degrees of freedom at the normal quantile ``z`` (Wilson-Hilferty)."""
    h = 2.0 / (9.0 * dof)
    return dof * (1.0 - h + z * math.sqrt(h)) ** 3


@dataclass(frozen=True)
class LearnerSettings:
    """What the learner is told (see the module): the stream's nominal rate ``rate_hz`` [Hz], blocks ``block_s``
    [s], the still time a piece's run needs and a piece's longest span (``min_still_s``, ``piece_s`` [s]), the
    tests' false-alarm probability ``alpha``, the noise estimate's quantile and history [blocks], the temperature
    bins (``bin_width_degc`` from ``t_low_degc`` to ``t_high_degc``), the curve's ``degree`` and the spans that allow
    it [degC], the weighting and forgetting (``half_life_h``, ``stale_h`` [operating hours]), the power-ons and
    points kept, the rejection bounds (``max_bias_dps``, ``outlier_dps`` [deg/s], ``outlier_sigmas``,
    ``max_tempco_dps_per_degc`` [deg/s/degC]), the change that asks for a save (``save_change_dps``), and the
    candidate thermal lags (``lag_candidates_s`` [s], the first 0)."""

    rate_hz: float
    block_s: float = 1.0
    min_still_s: float = 20.0
    piece_s: float = 120.0
    alpha: float = 1e-3
    noise_quantile: float = 0.1
    history_blocks: int = 64
    bin_width_degc: float = 1.0
    t_low_degc: float = -40.0
    t_high_degc: float = 85.0
    degree: Literal[1, 2, 3] = 3
    cubic_span_degc: float = 15.0
    min_span_degc: float = 5.0
    half_life_h: float = 50.0
    stale_h: float = 500.0
    max_sessions: int = 8
    max_points: int = 200
    max_bias_dps: float = 10.0
    outlier_dps: float = 0.05
    outlier_sigmas: float = 4.0
    max_tempco_dps_per_degc: float = 0.1
    save_change_dps: float = 0.005
    lag_candidates_s: tuple[float, ...] = (0.0, 15.0, 30.0, 60.0, 120.0, 240.0)

    def __post_init__(self) -> None:
        lags = self.lag_candidates_s
        if isinstance(lags, (str, bytes)) or not hasattr(lags, "__len__"):
            raise InputError(f"lag_candidates_s: expected a list of time constants [s], got {lags!r}")
        lags = tuple(lags)
        if not 1 <= len(lags) <= 8 or any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in lags) \
                or lags[0] != 0 or any(not (math.isfinite(v) and v > 0) for v in lags[1:]):
            raise InputError(f"lag_candidates_s: 1 to 8 time constants [s], the first 0 and the rest positive, got "
                             f"{list(lags)!r}")
        object.__setattr__(self, "lag_candidates_s", tuple(float(v) for v in lags))
        for f in fields(self):
            if f.name == "lag_candidates_s":
                continue
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise InputError(f"{f.name}: expected a finite number, got {value!r}")
        positive = ("rate_hz", "block_s", "min_still_s", "piece_s", "bin_width_degc", "half_life_h", "stale_h",
                    "max_bias_dps", "outlier_dps", "outlier_sigmas", "max_tempco_dps_per_degc", "save_change_dps")
        for name in positive:
            if not getattr(self, name) > 0:
                raise InputError(f"{name}: must be positive, got {getattr(self, name):.6g}")
        # what the learner holds in memory grows with these: bounded, so a state file cannot ask for gigabytes
        for name, high in (("rate_hz", 4e4), ("block_s", 60.0), ("min_still_s", 3600.0), ("piece_s", 3600.0),
                           ("bin_width_degc", 50.0)):
            if getattr(self, name) > high:
                raise InputError(f"{name}: at most {high:g}, got {getattr(self, name):.6g}")
        if self.rate_hz * self.block_s > 1e6:
            raise InputError(f"block_s: {self.block_s:.6g} s at rate_hz={self.rate_hz:.6g} is "
                             f"{self.rate_hz * self.block_s:.3g} samples a block; at most 1e6")
        if not 0 < self.alpha < 0.5:
            raise InputError(f"alpha: must lie in (0, 0.5), got {self.alpha}")
        if not 0 < self.noise_quantile < 0.5:
            raise InputError(f"noise_quantile: must lie in (0, 0.5), got {self.noise_quantile}")
        if self.degree not in (1, 2, 3):
            raise InputError(f"degree: 1, 2 or 3, got {self.degree!r}")
        for name, low, high in (("history_blocks", 16, 1024), ("max_sessions", 1, 64), ("max_points", 8, 4096)):
            value = getattr(self, name)
            if int(value) != value or not low <= value <= high:
                raise InputError(f"{name}: a whole number in {low}..{high}, got {value!r}")
        if not self.t_high_degc > self.t_low_degc:
            raise InputError(f"t_high_degc: must exceed t_low_degc ({self.t_low_degc}), got {self.t_high_degc}")
        if self.bins > 1000:
            raise InputError(f"bin_width_degc: {self.bins} bins from t_low_degc to t_high_degc; at most 1000")
        if not self.cubic_span_degc >= self.min_span_degc >= 0:
            raise InputError("cubic_span_degc and min_span_degc: need cubic_span_degc >= min_span_degc >= 0, got "
                             f"{self.cubic_span_degc} and {self.min_span_degc}")

    @property
    def block_samples(self) -> int:
        return max(MIN_BLOCK_SAMPLES, int(math.floor(self.block_s * self.rate_hz + 0.5)))

    @property
    def bins(self) -> int:
        return int(math.ceil((self.t_high_degc - self.t_low_degc) / self.bin_width_degc))

    def z_values(self) -> dict[str, float]:
        """The normal quantiles of the tests: the noise quantile's, and the variance and step tests' with three
        channels (gyro only) and six (gyro and accelerometer)."""
        out = {"noise": float(ndtri(self.noise_quantile))}
        for channels in (3, 6):
            per_test = self.alpha / channels
            out[f"variance{channels}"] = float(ndtri(1 - per_test))
            out[f"step{channels}"] = float(ndtri(1 - per_test / 2))
        return out

    def to_dict(self) -> dict[str, Any]:
        out = asdict(self)
        out["lag_candidates_s"] = list(self.lag_candidates_s)
        return out


@dataclass(frozen=True)
class LearnerStatus:
    """Where the learner stands: sessions seen, points kept, accepted still time [s], pieces rejected as beyond
    the bound or as outliers, points dropped as stale, the model's degree (-1: none yet), its thermal lag [s], the
    range it has seen [degC] (lagged), its residual RMS per axis [deg/s], its confidence (the largest standard
    error of the curve, g-sensitivity and mean constant over the points, per axis [deg/s]; inf while it has no
    residual to judge by) and whether it changed enough to be saved."""

    sessions: int
    points: int
    still_s: float
    rejected_bound: int
    rejected_outliers: int
    stale_dropped: int
    degree: int
    lag_time_constant_s: float
    t_min_degc: float | None
    t_max_degc: float | None
    rms_dps: tuple[float, float, float]
    uncertainty_dps: tuple[float, float, float]
    should_save: bool

    @property
    def has_model(self) -> bool:
        return self.degree >= 0


def _quantile(values: np.ndarray, q: float) -> np.ndarray:
    """Column quantiles by linear interpolation between order statistics (as the C code computes them)."""
    s = np.sort(values, axis=0)
    pos = q * (s.shape[0] - 1)
    low = int(math.floor(pos))
    if low + 1 >= s.shape[0]:
        return s[low]
    return s[low] + (pos - low) * (s[low + 1] - s[low])


def block_statistics(blocks: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Means and detrended variances of blocks (n, m, c) over their m samples (see the module, step 1)."""
    m = blocks.shape[1]
    x = np.ascontiguousarray(np.transpose(blocks, (0, 2, 1)))  # (n, c, m): each sum runs over a contiguous row
    d = x - x[:, :, :1]
    i = np.arange(m) - (m - 1) / 2.0
    s1 = d.sum(axis=2)
    s2 = (d * d).sum(axis=2)
    si = (d * i).sum(axis=2)
    i2 = m * (m * m - 1) / 12.0
    mean = x[:, :, 0] + s1 / m
    var = np.maximum(s2 - s1 * s1 / m - si * si / i2, 0.0) / (m - 2)
    return mean, var


class OnlineCalibrator:
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
        self._ceiling = np.array([MAX_GYRO_NOISE_DENSITY ** 2] * 3 + [MAX_ACCEL_NOISE_DENSITY ** 2] * 3) * s.rate_hz
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
        self._dq = _fresh_dequantizer()
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

    # ---------------------------------------------------------------- the stream
    def start_session(self) -> None:
        """A new power-on: its own turn-on constant; the stream restarts (time may start again from zero)."""
        self.end_session()
        self._session += 1
        self._pool = []
        self._accel = None
        self._last_t = None
        self._lag_t = None
        self._dq = _fresh_dequantizer()
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
        gyro = _matrix(gyro_dps, m, "gyro_dps")
        temperature = np.asarray(temperature_degc, dtype=float).reshape(-1)
        if temperature.size != m:
            raise InputError(f"temperature_degc: {temperature.size} values for {m} times")
        has_accel = accel_g is not None
        if self._accel is not None and has_accel != self._accel:
            raise InputError("accel_g: given in some chunks of a session and not in others")
        accel = _matrix(accel_g, m, "accel_g") if has_accel else np.zeros((m, 3))
        if m == 0:
            return
        if not np.all(np.isfinite(t)):
            raise InputError(f"time_s: not finite at sample {int(np.flatnonzero(~np.isfinite(t))[0])}")
        previous = self._last_t if self._last_t is not None else t[0] - 1.0 / self.settings.rate_hz
        steps = np.diff(np.concatenate([[previous], t]))
        if np.any(steps <= 0):
            raise InputError(f"time_s: does not increase at sample {int(np.flatnonzero(steps <= 0)[0])} of this "
                             f"chunk ({t[np.flatnonzero(steps <= 0)[0]]!r} s after {previous!r} s)")
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
                        y[first + 1:end, k] = lazy_lfilter([a], [1.0, -(1.0 - a)], x[first + 1:end],
                                                           zi=[(1.0 - a) * state[k]])[0]
                    else:
                        y[first + 1:end, k] = x[first + 1:end]
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
        prior_c = np.concatenate([[state_c], crossing])[:where.size]
        prior_t = np.concatenate([[dq["time"]], t[where]])[:where.size]
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
            dq.update(crossing=float(crossing[-1]), time=float(t[where[-1]]), rate=float(rates[-1]),
                      half=float(half[-1]))
        dq["previous"] = float(x[-1])
        return out

    def _feed(self, rows: np.ndarray, clocks: np.ndarray) -> None:
        """Samples without a break: complete the pending block, then whole blocks, then keep the rest."""
        w = self._w
        i = 0
        if self._fill:
            take = min(w - self._fill, rows.shape[0])
            self._buffer[self._fill:self._fill + take] = rows[:take]
            self._fill += take
            i = take
            if self._fill < w:
                return
            self._blocks(self._buffer[None], clocks[i - 1:i])
            self._fill = 0
        whole = (rows.shape[0] - i) // w
        if whole:
            self._blocks(rows[i:i + whole * w].reshape(whole, w, rows.shape[1]), clocks[i + w - 1:i + whole * w:w])
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
        record = {"mean": mean, "temperature": temperature, "quiet": quiet, "linked": linked, "agree": True,
                  "still": False}
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
                robust = float(medians[c]) / _MAD_TO_SIGMA
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
            return _quantile(ring[:first, :channels], q)
        return np.array([_quantile(ring[:int(counts[c]), c], q) if counts[c] else np.nan for c in range(channels)])

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
            self._commit(self._piece_bin, self._piece[:3] / samples, self._piece[3:6] / samples,
                         self._piece[6:-1] / samples,
                         samples / self.settings.rate_hz, self._clock if now is None else now)
        self._piece[:] = 0.0
        self._piece_bin = -1

    # ---------------------------------------------------------------- pieces, bins, the model
    def _commit(self, bin_index: int, bias: np.ndarray, accel: np.ndarray, temperature: np.ndarray, seconds: float,
                now: float) -> None:
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
            self._piece_var = square if np.isnan(self._piece_var[0]) else \
                (1.0 - PIECE_SPREAD_WEIGHT) * self._piece_var + PIECE_SPREAD_WEIGHT * square
        self._store(bin_index, bias, accel, temperature, seconds, now)
        self._refit(now)
        # the session's points judged again by the model they made: a bad first piece, accepted while its
        # session's constant was unknown, is found once the session has points enough for a robust constant
        mine = np.flatnonzero(self._pt_session == self._session)
        bad = [i for i in mine if self._is_outlier(self._pt_bias[i], self._pt_accel[i], self._pt_t[i])]
        if bad:
            dropped = [(int(self._pt_bin[i]), self._pt_bias[i].copy(), self._pt_accel[i].copy(), self._pt_t[i].copy(),
                        float(self._pt_s[i])) for i in bad]
            self._counts["rejected_outliers"] += len(bad)
            self._counts["still_s"] -= float(self._pt_s[bad].sum())
            self._pt_session[bad] = 0
            self._refit(now)
            for piece in dropped:
                self._to_pool(*piece, now)

    def _to_pool(self, bin_index: int, bias: np.ndarray, accel: np.ndarray, temperature: np.ndarray, seconds: float,
                 now: float) -> None:
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
        offsets = np.array([bias - self._shape(temps[self._lag_index]) - self._g @ accel
                            for _, bias, accel, temps, _ in self._pool])
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

    def _store(self, bin_index: int, bias: np.ndarray, accel: np.ndarray, temperature: np.ndarray, seconds: float,
               now: float) -> None:
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

    def _is_outlier(self, bias: np.ndarray, accel: np.ndarray, temperatures: np.ndarray, *,
                    piece: bool = False) -> bool:
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
        predicted, spread2 = shape + self._session_offset(points), self._rms ** 2
        if piece and not np.isnan(self._piece_var[0]):
            spread2 = np.maximum(spread2, self._piece_var)
        sessions = np.zeros(self._sessions.size)
        sessions[mine[0]] = 1.0
        # the model's own uncertainty there: s^2 x' (X'WX)^-1 x, s^2 = rms^2 sum(w) / n
        u = (min(max(temperature, self._t_range[0]), self._t_range[1]) - T_REF_DEGC) / T_SCALE_DEGC
        x = np.concatenate([[u ** k for k in range(1, self._degree + 1)], accel[self._tilted], sessions])
        z = _forward(self._lower, x)
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
            offsets = self._pt_bias[points] - self._shape(self._pt_t[points, self._lag_index]) \
                - self._pt_accel[points] @ self._g.T
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
        tilted = _tilted(accel, self._pt_session[used], sessions, used.size - degree - sessions.size - 1)
        weights = np.array([self._pt_s[i] * self._decay(now - self._pt_clock[i]) for i in used])
        while True:
            # every candidate lag, the one leaving the smallest weighted residual kept (the first of equals)
            solution, chosen = None, -1
            for k in range(self._lags):
                fit = _weighted_fit(self._pt_t[used, k], accel, tilted, self._pt_session[used], sessions,
                                    self._pt_bias[used], weights, degree)
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
        return _curve(self._coef, self._degree, self._t_range, temperature)

    def _changed(self) -> bool:
        if self._saved is None:
            return True
        if self._saved["degree"] != self._degree or self._saved["t_range"] != self._t_range:
            return True
        temps = self._pt_t[self._pt_session > 0, self._lag_index]
        now = self._shape(temps) + self._constants.mean(axis=0)
        before = _curve(self._saved["coef"], self._saved["degree"], self._t_range, temps) + self._saved["constant"]
        return bool(np.max(np.abs(now - before)) > self.settings.save_change_dps)

    def mark_saved(self) -> None:
        """The current model was saved: ``should_save`` turns false until it changes enough again."""
        if self._degree >= 0:
            self._saved = {"degree": self._degree, "coef": self._coef.copy(), "t_range": self._t_range,
                           "constant": self._constants.mean(axis=0)}
        self._should_save = False

    # ---------------------------------------------------------------- results
    def bias_dps(self, temperature_degc, accel_g=None, *, session: Literal["current", "mean"] = "current"
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
            sessions=self._session, points=int(filled.sum()), still_s=float(self._counts["still_s"]),
            rejected_bound=self._counts["rejected_bound"], rejected_outliers=self._counts["rejected_outliers"],
            stale_dropped=self._counts["stale_dropped"], degree=self._degree,
            lag_time_constant_s=self.lag_time_constant_s,
            t_min_degc=self._t_range[0] if has else None, t_max_degc=self._t_range[1] if has else None,
            rms_dps=tuple(float(v) for v in self._rms), uncertainty_dps=self._uncertainty(),
            should_save=self.should_save)

    def _uncertainty(self) -> tuple[float, float, float]:
        used = np.flatnonzero(self._pt_session > 0)
        if self._degree < 0:
            return (math.inf,) * 3
        design = _design(self._pt_t[used, self._lag_index], self._pt_accel[used], self._tilted, self._pt_session[used],
                         self._sessions, self._degree)
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

    def to_calibration(self, *, model: str = "online", require_curve: bool = True,
                       axes: Iterable[str] = GYRO_AXES, contributions: Iterable[LogContribution] = ()
                       ) -> Calibration:
        """The learned model as a model file's :class:`Calibration` (the curve continued along its tangent past
        the range seen, its lag, the g-sensitivity, the sessions' constants as turn-on biases); ``gyrocomp apply``
        takes it, for ``axes`` (those the logs had); ``contributions`` (from :func:`replay`) are listed in its
        provenance. With ``require_curve``, a learner whose still data span less
        than ``min_span_degc`` (constants only) is refused with :class:`InputError`."""
        axes = list(axes)
        if not axes or any(a not in GYRO_AXES for a in axes):
            raise InputError(f"axes: some of {', '.join(GYRO_AXES)}, got {axes!r}")
        if self._degree < 0:
            raise NotFittedError("the learner has no model yet: it has seen no still piece long enough "
                                 f"({self.settings.min_still_s:g} s) in {self._session} log(s)")
        if require_curve and self._degree == 0:
            used = self._pt_session > 0
            low, high = float(self._pt_t[used, 0].min()), float(self._pt_t[used, 0].max())
            raise InputError(f"the still data of {self._session} log(s) cover {low:.1f}..{high:.1f} degC; a "
                             f"temperature model needs at least {self.settings.min_span_degc:g} degC (min_span_degc)")
        low, high = self._t_range
        out = {}
        for j, name in enumerate(GYRO_AXES):
            if name not in axes:
                continue
            curve = None
            if self._degree > 0:
                curve = PolynomialBias(tuple(float(c) for c in self._coef[j, :self._degree]), T_REF_DEGC,
                                       T_SCALE_DEGC, low, high, extrapolation="linear")
            g = tuple(float(v) for v in self._g[j]) if self._tilted.any() else None
            out[name] = AxisCalibration(temperature=curve, g_sensitivity_dps_per_g=g,
                                         lag_time_constant_s=self.lag_time_constant_s,
                                         turn_on_biases=tuple(float(c) for c in self._constants[:, j]))
        status = self.status
        report = {"method": "online learner", "sessions": status.sessions, "points": status.points,
                  "still_s": status.still_s, "degree": self._degree,
                  "rejected": status.rejected_bound + status.rejected_outliers,
                  "settings": self.settings.to_dict()}
        origin = provenance([])
        origin["inputs"] = [{"file": Path(c.source).name, "duration_s": c.duration_s, "still_s": c.still_s,
                             "rejected_pieces": c.rejected} for c in contributions]
        return Calibration(axes=out, model=model, provenance=origin, fit_report=report)

    # ---------------------------------------------------------------- state as JSON
    def to_dict(self) -> dict[str, Any]:
        """The whole state (a learner loaded from it continues exactly where this one is)."""
        return {
            "format": LEARNER_FORMAT, "schema_version": LEARNER_SCHEMA_VERSION,
            "settings": self.settings.to_dict(),
            "stream": {"session": self._session, "accel": self._accel, "buffer": self._buffer[:self._fill].tolist(),
                       "last_t": self._last_t, "t0": self._t0, "base_clock": self._base_clock,
                       "clock": self._clock, "broken": self._broken, "lag_state_degc": self._lag_state.tolist(),
                       "lag_t": self._lag_t, "dequantizer": dict(self._dq),
                       "recent": [_record_to_dict(r) for r in self._recent]},
            "noise": {"var_ring": self._var_ring.tolist(), "var_count": self._var_count.tolist(),
                      "ring_pos": self._ring_pos.tolist(), "step_ring": self._step_ring.tolist(),
                      "step_count": self._step_count.tolist(), "step_pos": self._step_pos.tolist(),
                      "level": [None if math.isnan(v) else float(v) for v in self._level]},
            "piece": {"run_s": self._run_s, "sums": self._piece.tolist(), "bin": self._piece_bin,
                      "pool": [{"bin": b, "bias_dps": list(map(float, bias)), "accel_g": list(map(float, accel)),
                                "temperature_degc": list(map(float, temps)), "still_s": float(sec)}
                               for b, bias, accel, temps, sec in self._pool]},
            "points": {"bias_dps": self._pt_bias.tolist(), "temperature_degc": self._pt_t.tolist(),
                     "accel_g": self._pt_accel.tolist(),
                     "still_s": self._pt_s.tolist(), "clock_s": self._pt_clock.tolist(),
                     "session": self._pt_session.tolist(), "bin": self._pt_bin.tolist()},
            "model": {"degree": self._degree, "coef": self._coef.tolist(), "g_dps_per_g": self._g.tolist(),
                      "tilted": self._tilted.tolist(), "sessions": self._sessions.tolist(),
                      "constants_dps": self._constants.tolist(), "rms_dps": self._rms.tolist(),
                      "t_range_degc": list(self._t_range), "should_save": self._should_save,
                      "lag_index": self._lag_index, "dof": self._dof, "lower": self._lower.tolist(),
                      "piece_var": [None if math.isnan(v) else float(v) for v in self._piece_var],
                      "scale2": self._scale2.tolist(),
                      "saved": None if self._saved is None else {
                          "degree": self._saved["degree"], "coef": self._saved["coef"].tolist(),
                          "t_range": list(self._saved["t_range"]), "constant": self._saved["constant"].tolist()}},
            "counts": dict(self._counts),
        }

    @classmethod
    def from_dict(cls, d: Any, source: str = "<dict>") -> "OnlineCalibrator":
        """A learner from :meth:`to_dict`'s output, every field checked."""
        if not isinstance(d, dict) or d.get("format") != LEARNER_FORMAT:
            raise InputError(f"{source}: not a gyrocomp learner state (no \"format\": \"{LEARNER_FORMAT}\")")
        if d.get("schema_version") != LEARNER_SCHEMA_VERSION:
            raise InputError(f"{source}: learner state schema {d.get('schema_version')!r}; this gyrocomp reads "
                             f"{LEARNER_SCHEMA_VERSION}")
        try:
            return _restore(cls, d)
        except InputError as exc:
            raise InputError(f"{source}: {exc}") from None
        except (KeyError, TypeError, ValueError, IndexError) as exc:
            raise InputError(f"{source}: malformed learner state ({type(exc).__name__}: {exc})") from None

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), allow_nan=False) + "\n"

    def save(self, path: str | os.PathLike) -> None:
        """Write the state as JSON, atomically."""
        write_text_atomic(path, self.to_json())

    @classmethod
    def load(cls, path: str | os.PathLike) -> "OnlineCalibrator":
        path = Path(path)
        try:
            text = path.read_text(encoding="utf-8")
        except FileNotFoundError:
            raise InputError(f"{path}: no such learner state file") from None
        except (OSError, UnicodeDecodeError) as exc:
            raise InputError(f"{path}: cannot read the learner state ({type(exc).__name__})") from None
        return cls.from_dict(jsontext.loads(text, str(path), "learner state"), str(path))


def _fresh_dequantizer() -> dict:
    """The dequantizer's state: the last reading, the last crossing [degC], its time [s], the rate [degC/s] and
    half the step there [degC] (None/0: none yet)."""
    return {"previous": None, "crossing": None, "time": 0.0, "rate": 0.0, "half": 0.0}


@dataclass(frozen=True)
class LogContribution:
    """What one replayed log gave the learner: its gyro axes, its length [s], the still time accepted [s], the
    pieces rejected (beyond the bound or as outliers) and the temperature range of the log [degC]."""

    source: str
    gyro_axes: tuple[str, ...]
    duration_s: float
    still_s: float
    rejected: int
    temperature_min_degc: float
    temperature_max_degc: float


#: a log whose sample rate differs from the learner's by more than this fraction is refused
RATE_TOLERANCE = 0.1


def replay(learner: OnlineCalibrator, recordings: Iterable[Recording], *, chunk_samples: int = 65536
           ) -> list[LogContribution]:
    """Feed ``recordings`` to ``learner``, each one power-on (a session), in chunks of ``chunk_samples`` (any
    chunking gives the same model); what each gave. Raises :class:`InputError` for a log without temperature,
    without gyro_x, gyro_y and gyro_z, or at a rate the learner was not set up for."""
    out = []
    for rec in recordings:
        if rec.temperature_degc is None:
            raise InputError(f"{rec.source}: no temperature; the learner learns the bias against temperature")
        if not any(a in rec.gyro_axes for a in GYRO_AXES):
            raise InputError(f"{rec.source}: none of {', '.join(GYRO_AXES)}; the learner learns those axes")
        rate = learner.settings.rate_hz
        if abs(rec.rate_hz - rate) > RATE_TOLERANCE * rate:
            raise InputError(f"{rec.source}: sampled at {rec.rate_hz:.4g} Hz; the learner was set up for {rate:.4g} Hz "
                             "(rate_hz): its blocks and gaps count samples at that rate")
        gyro = np.zeros((rec.n_samples, 3))  # an axis the log lacks reads 0: no noise, never tested, learns 0
        for j, axis in enumerate(GYRO_AXES):
            if axis in rec.gyro_axes:
                gyro[:, j] = rec.gyro_dps[:, rec.gyro_axes.index(axis)]
        temperature = np.asarray(rec.temperature_degc, dtype=float)
        before = learner.status
        learner.start_session()
        for start in range(0, rec.n_samples, chunk_samples):
            part = slice(start, start + chunk_samples)
            learner.update(rec.time_s[part], gyro[part], None if rec.accel_g is None else rec.accel_g[part],
                           temperature[part])
        learner.end_session()
        after = learner.status
        out.append(LogContribution(
            rec.source, tuple(a for a in GYRO_AXES if a in rec.gyro_axes), rec.duration_s,
            after.still_s - before.still_s,
            after.rejected_bound + after.rejected_outliers - before.rejected_bound - before.rejected_outliers,
            float(np.nanmin(temperature)), float(np.nanmax(temperature))))
    return out


def _matrix(values, rows: int, name: str) -> np.ndarray:
    try:
        out = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name}: expected numbers, got {type(values).__name__}") from None
    if out.ndim == 1 and rows == 1 and out.size == 3:
        out = out.reshape(1, 3)
    if out.shape != (rows, 3):
        raise InputError(f"{name}: expected shape ({rows}, 3) (x, y, z for each time), got {out.shape}")
    return out


def _curve(coef: np.ndarray, degree: int, t_range: tuple[float, float], temperature) -> np.ndarray:
    """The shape sum_k c_k u^k per axis [deg/s] (..., 3) at ``temperature`` [degC], continued along its tangent
    past ``t_range`` (as :class:`PolynomialBias` with ``extrapolation="linear"``)."""
    t = np.asarray(temperature, dtype=float)
    clipped = np.clip(t, *t_range)
    u = np.expand_dims((clipped - T_REF_DEGC) / T_SCALE_DEGC, -1)
    beyond = np.expand_dims((t - clipped) / T_SCALE_DEGC, -1)
    out = np.zeros(np.shape(t) + (3,))
    slope = np.zeros(np.shape(t) + (3,))
    for k in range(degree - 1, -1, -1):
        out = (out + coef[:, k]) * u
        slope = slope * u + (k + 1) * coef[:, k]
    return out + slope * beyond


def _tilted(accel: np.ndarray, point_sessions: np.ndarray, sessions: np.ndarray, spare: int) -> np.ndarray:
    """Which accelerometer axes the points excite enough to fit their g-sensitivity: a range of MIN_TILT_G within
    one power-on (an attitude that changes only from one power-on to the next cannot be told from the power-ons'
    constants), POINTS_PER_TILT of the ``spare`` points (beyond the other unknowns) for each."""
    out = np.zeros(3, dtype=bool)
    for k in range(3):
        span = max(float(np.ptp(accel[point_sessions == q, k])) for q in sessions)
        if spare >= POINTS_PER_TILT and span >= MIN_TILT_G:
            out[k] = True
            spare -= POINTS_PER_TILT
    return out


def _design(temps: np.ndarray, accel: np.ndarray, tilted: np.ndarray, bin_sessions: np.ndarray, sessions: np.ndarray,
            degree: int) -> np.ndarray:
    u = (temps - T_REF_DEGC) / T_SCALE_DEGC
    columns = [u ** k for k in range(1, degree + 1)]
    columns += [accel[:, k] for k in range(3) if tilted[k]]
    columns += [(bin_sessions == s).astype(float) for s in sessions]
    return np.column_stack(columns)


def _weighted_fit(temps, accel, tilted, bin_sessions, sessions, bias, weights, degree):
    """Weighted least squares (see the module, step 7) by Cholesky on the normal equations, in the C code's order
    of operations: (coefficients (degree, 3), g-sensitivities (tilted axes, 3), constants (sessions, 3), residual
    RMS (3,)), or None when the system is not positive definite."""
    x = _design(temps, accel, tilted, bin_sessions, sessions, degree)
    n, p = x.shape
    # sums over the points in their order, each term w (x_r x_c): a reduction over the first axis of a contiguous
    # array adds the points one after the other, as the C code does
    w = np.asarray(weights, dtype=float)[:, None, None]
    a = np.ascontiguousarray(w * (x[:, :, None] * x[:, None, :])).sum(axis=0)
    b = np.ascontiguousarray(w * (x[:, :, None] * np.asarray(bias, dtype=float)[:, None, :])).sum(axis=0)
    for i in range(p):
        a[i, i] *= 1.0 + _RIDGE
    lower = _cholesky(a)
    if lower is None:
        return None
    beta = _cholesky_solve(lower, b)
    residual = bias - x @ beta
    dof = n - p
    rms = np.zeros(3)
    if dof > 0:
        rms = np.sqrt((weights @ (residual * residual)) / weights.sum() * n / dof)
    g_end = degree + int(tilted.sum())
    scale2 = rms * rms * weights.sum() / n
    ssr = float(np.sum(weights @ (residual * residual)))
    return beta[:degree], beta[degree:g_end], beta[g_end:], rms, lower, scale2, ssr


def _cholesky(a: np.ndarray) -> np.ndarray | None:
    p = a.shape[0]
    lower = np.zeros_like(a)
    for i in range(p):
        for j in range(i + 1):
            total = a[i, j]
            for k in range(j):
                total -= lower[i, k] * lower[j, k]
            if i == j:
                if not total > 0:
                    return None
                lower[i, i] = math.sqrt(total)
            else:
                lower[i, j] = total / lower[j, j]
    return lower


def _forward(lower: np.ndarray, x: np.ndarray) -> np.ndarray:
    """L^-1 x by forward substitution."""
    p = lower.shape[0]
    y = np.zeros(p)
    for i in range(p):
        total = x[i]
        for k in range(i):
            total -= lower[i, k] * y[k]
        y[i] = total / lower[i, i]
    return y


def _cholesky_solve(lower: np.ndarray, b: np.ndarray) -> np.ndarray:
    p = lower.shape[0]
    y = np.zeros_like(b)
    for i in range(p):
        total = b[i].copy()
        for k in range(i):
            total -= lower[i, k] * y[k]
        y[i] = total / lower[i, i]
    x = np.zeros_like(b)
    for i in range(p - 1, -1, -1):
        total = y[i].copy()
        for k in range(i + 1, p):
            total -= lower[k, i] * x[k]
        x[i] = total / lower[i, i]
    return x


def _record_to_dict(record: dict) -> dict:
    out = {k: bool(v) for k, v in record.items() if k not in ("mean", "temperature")}
    if "mean" in record:
        out["mean"] = [float(v) for v in record["mean"]]
        out["temperature"] = [float(v) for v in record["temperature"]]
    return out


#: the largest magnitude a number in a learner state has (rates [deg/s], g, sums of them, seconds); a larger one is
#: a damaged or forged file, refused before it overflows the refit
STATE_MAGNITUDE_MAX = 1e12
#: and a temperature [degC] in it (the plausible range's bound)
STATE_TEMPERATURE_MAX_DEGC = max(abs(t) for t in TEMPERATURE_RANGE_DEGC)


def _finite_array(values, shape: tuple | None, name: str, *, allow_nan: bool = False,
                  bound: float = STATE_MAGNITUDE_MAX) -> np.ndarray:
    try:
        out = np.array(values, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{name}: expected numbers") from None
    if shape is not None and out.shape != shape:
        raise InputError(f"{name}: expected shape {shape}, got {out.shape}")
    if not allow_nan and not np.all(np.isfinite(out)):
        raise InputError(f"{name}: holds a non-finite number")
    finite = out[np.isfinite(out)]
    if finite.size and np.max(np.abs(finite)) > bound:
        raise InputError(f"{name}: holds {float(finite[np.argmax(np.abs(finite))]):.3g}, beyond the {bound:g} a "
                         "learner state holds")
    return out


def _whole_array(values, name: str, lo: int, hi: int) -> np.ndarray:
    """Whole numbers in lo..hi, checked before numpy sees them (a 30-digit integer overflows its int64)."""
    flat = values if isinstance(values, list) else [values]
    if any(isinstance(v, bool) or not isinstance(v, int) or not lo <= v <= hi for v in flat):
        raise InputError(f"{name}: whole numbers in {lo}..{hi} expected")
    return np.array(flat, dtype=np.int64)


def _scalar(value, name: str, bound: float = STATE_MAGNITUDE_MAX) -> float:
    return float(_finite_array(value, (), name, bound=bound))


def _restore(cls, d: dict) -> OnlineCalibrator:
    self = cls(LearnerSettings(**d["settings"]))
    _restore_stream(self, d["stream"], d["piece"])
    _restore_noise(self, d["noise"])
    _restore_points(self, d["points"])
    _restore_model(self, d["model"])
    counts = d["counts"]
    self._counts = {"still_s": float(counts["still_s"]),
                    **{k: int(counts[k]) for k in ("rejected_bound", "rejected_outliers", "stale_dropped")}}
    return self


def _restore_stream(self: OnlineCalibrator, stream: dict, piece: dict) -> None:
    w = self._w
    self._session = int(_whole_array(stream["session"], "stream.session", 0, 10 ** 9)[0])
    self._accel = None if stream["accel"] is None else bool(stream["accel"])
    buffer = _finite_array(stream["buffer"], None, "stream.buffer", allow_nan=True)
    if buffer.size % (6 + self._lags):
        raise InputError(f"stream.buffer: rows of {6 + self._lags} numbers expected")
    buffer = buffer.reshape(-1, 6 + self._lags)
    if buffer.shape[0] >= w:
        raise InputError(f"stream.buffer: {buffer.shape[0]} samples; a block holds {w}")
    self._fill = buffer.shape[0]
    self._buffer[:self._fill] = buffer
    self._last_t = None if stream["last_t"] is None else _scalar(stream["last_t"], "stream.last_t")
    self._t0, self._base_clock, self._clock = (_scalar(stream[k], f"stream.{k}") for k in ("t0", "base_clock", "clock"))
    self._broken = bool(stream["broken"])
    self._lag_state = _finite_array(stream["lag_state_degc"], (self._lags,), "stream.lag_state_degc",
                                    bound=STATE_TEMPERATURE_MAX_DEGC)
    self._lag_t = None if stream["lag_t"] is None else _scalar(stream["lag_t"], "stream.lag_t")
    dq = stream["dequantizer"]
    self._dq = {"previous": None if dq["previous"] is None else _scalar(dq["previous"], "stream.dequantizer"),
                "crossing": None if dq["crossing"] is None else _scalar(dq["crossing"], "stream.dequantizer"),
                **{k: _scalar(dq[k], "stream.dequantizer") for k in ("time", "rate", "half")}}
    self._recent = []
    for rec in stream["recent"][-3:]:
        restored = {k: bool(rec[k]) for k in ("still", "linked")}
        if "mean" in rec:
            restored.update(mean=_finite_array(rec["mean"], (6,), "stream.recent.mean"),
                            temperature=_finite_array(rec["temperature"], (self._lags,), "stream.recent.temperature",
                                                      bound=STATE_TEMPERATURE_MAX_DEGC),
                            quiet=bool(rec["quiet"]), agree=bool(rec["agree"]))
        self._recent.append(restored)
    self._run_s = _scalar(piece["run_s"], "piece.run_s")
    self._piece = _finite_array(piece["sums"], (7 + self._lags,), "piece.sums")
    bins = int(2 * STATE_TEMPERATURE_MAX_DEGC / self.settings.bin_width_degc) + 1
    self._piece_bin = int(_whole_array(piece["bin"], "piece.bin", -bins, bins)[0])
    self._pool = [(int(_whole_array(p["bin"], "piece.pool.bin", -bins, bins)[0]),
                   _finite_array(p["bias_dps"], (3,), "piece.pool.bias_dps"),
                   _finite_array(p["accel_g"], (3,), "piece.pool.accel_g"),
                   _finite_array(p["temperature_degc"], (self._lags,), "piece.pool.temperature_degc",
                                 bound=STATE_TEMPERATURE_MAX_DEGC),
                   _scalar(p["still_s"], "piece.pool.still_s")) for p in piece["pool"][-POOL_PIECES:]]


def _restore_noise(self: OnlineCalibrator, noise: dict) -> None:
    r = self.settings.history_blocks
    self._var_ring = _finite_array(noise["var_ring"], (r, 6), "noise.var_ring")
    self._step_ring = _finite_array(noise["step_ring"], (r, 6), "noise.step_ring")
    for name in ("var_count", "ring_pos", "step_count", "step_pos"):
        values = _whole_array(noise[name], f"noise.{name}", 0, r)
        if values.shape != (6,):
            raise InputError(f"noise.{name}: six whole numbers in 0..{r}")
        setattr(self, f"_{name}", values)
    self._level = _finite_array([np.nan if v is None else v for v in noise["level"]], (len(noise["level"]),),
                                "noise.level", allow_nan=True)


def _restore_points(self: OnlineCalibrator, points: dict) -> None:
    n = self.settings.max_points
    self._pt_bias = _finite_array(points["bias_dps"], (n, 3), "points.bias_dps")
    self._pt_t = _finite_array(points["temperature_degc"], (n, self._lags), "points.temperature_degc",
                               bound=STATE_TEMPERATURE_MAX_DEGC)
    self._pt_accel = _finite_array(points["accel_g"], (n, 3), "points.accel_g")
    self._pt_s = _finite_array(points["still_s"], (n,), "points.still_s")
    self._pt_clock = _finite_array(points["clock_s"], (n,), "points.clock_s")
    self._pt_session = _whole_array(points["session"], "points.session", 0, self._session)
    bins = int(2 * STATE_TEMPERATURE_MAX_DEGC / self.settings.bin_width_degc) + 1
    self._pt_bin = _whole_array(points["bin"], "points.bin", -bins, bins).reshape(n)
    if self._pt_session.shape != (n,):
        raise InputError(f"points.session: {n} session numbers in 0..{self._session}")


def _restore_model(self: OnlineCalibrator, model: dict) -> None:
    self._degree = int(model["degree"])
    if not -1 <= self._degree <= self.settings.degree:
        raise InputError(f"model.degree: {self._degree} outside -1..{self.settings.degree}")
    self._coef = _finite_array(model["coef"], (3, 3), "model.coef")
    self._g = _finite_array(model["g_dps_per_g"], (3, 3), "model.g_dps_per_g")
    self._tilted = np.array([bool(v) for v in model["tilted"]], dtype=bool).reshape(3)
    self._sessions = _whole_array(model["sessions"], "model.sessions", 0, self._session).reshape(-1)
    constants = model["constants_dps"]
    self._constants = _finite_array(constants if constants else np.zeros((0, 3)), (self._sessions.size, 3),
                                    "model.constants_dps")
    self._rms = _finite_array(model["rms_dps"], (3,), "model.rms_dps")
    self._t_range = tuple(_finite_array(model["t_range_degc"], (2,), "model.t_range_degc",
                                        bound=STATE_TEMPERATURE_MAX_DEGC))
    self._should_save = bool(model["should_save"])
    self._lag_index = int(model["lag_index"])
    self._dof = int(model["dof"])
    self._piece_var = _finite_array([np.nan if v is None else v for v in model["piece_var"]], (3,), "model.piece_var",
                                    allow_nan=True)
    if not 0 <= self._lag_index < self._lags:
        raise InputError(f"model.lag_index: {self._lag_index} outside 0..{self._lags - 1}")
    p = 0 if self._degree < 0 else self._degree + int(self._tilted.sum()) + self._sessions.size
    self._lower = _finite_array(model["lower"], (p, p), "model.lower") if p else np.zeros((0, 0))
    self._scale2 = _finite_array(model["scale2"], (3,), "model.scale2")
    saved = model["saved"]
    self._saved = None if saved is None else {
        "degree": int(saved["degree"]), "coef": _finite_array(saved["coef"], (3, 3), "model.saved.coef"),
        "t_range": tuple(float(v) for v in saved["t_range"]),
        "constant": _finite_array(saved["constant"], (3,), "model.saved.constant")}


__all__ = ["GYRO_AXES", "LEARNER_FORMAT", "LEARNER_SCHEMA_VERSION", "LearnerSettings", "LearnerStatus",
           "LogContribution",
           "OnlineCalibrator", "block_statistics", "chi2_quantile", "replay"]
