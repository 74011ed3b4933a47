"""The online learner: a temperature model of the gyro bias learned from the still moments of a live stream.

:class:`OnlineCalibrator` takes samples as they arrive (any chunk size, one sample included) and does, with fixed
memory, what Android's over-temperature calibration (AOSP ``over_temp_cal``), ArduPilot's onboard learning
(``INS_TCALn_ENABLE=2``) and SlimeVR's tracker calibration do, in the way gyrocomp's batch stillness detector
(:mod:`gyrocomp.motion.stillness`) decides what is still:

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
   and the noise levels below the physical ceilings of :mod:`gyrocomp.motion.stillness`), and its means agree with both
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

from .blocks import block_statistics
from .calibrator import OnlineCalibrator
from .replay import RATE_TOLERANCE, replay
from .settings import (
    GAP_PERIODS,
    GYRO_AXES,
    LEARNER_FORMAT,
    LEARNER_SCHEMA_VERSION,
    LEVEL_GROWTH,
    MIN_OUTLIER_DOF,
    MIN_SESSION_POINTS,
    MIN_STEPS,
    MIN_TILT_G,
    PIECE_SPREAD_WEIGHT,
    POINTS_PER_TILT,
    POOL_PIECES,
    T_REF_DEGC,
    T_SCALE_DEGC,
    LearnerSettings,
    LearnerStatus,
    ReplayedLog,
    chi2_quantile,
)

__all__ = [
    "GAP_PERIODS",
    "GYRO_AXES",
    "LEARNER_FORMAT",
    "LEARNER_SCHEMA_VERSION",
    "LEVEL_GROWTH",
    "MIN_OUTLIER_DOF",
    "MIN_SESSION_POINTS",
    "MIN_STEPS",
    "MIN_TILT_G",
    "PIECE_SPREAD_WEIGHT",
    "POINTS_PER_TILT",
    "POOL_PIECES",
    "RATE_TOLERANCE",
    "T_REF_DEGC",
    "T_SCALE_DEGC",
    "LearnerSettings",
    "LearnerStatus",
    "ReplayedLog",
    "OnlineCalibrator",
    "block_statistics",
    "chi2_quantile",
    "replay",
]
