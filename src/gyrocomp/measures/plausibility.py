"""Plausibility of a recording: what is probably a unit mistake or the wrong kind of data, said before a fit or a
compensation quietly produces a wrong result.

Each check is a pure function of the recording that returns the concerns it finds (empty when none); the
pipelines and ``apply`` turn them into :class:`gyrocomp.errors.PlausibilityWarning` (a
:class:`DataQualityWarning`) whose ``check`` names the check and whose message ends ``(check 'NAME')``. One
check is silenced with ``warnings.filterwarnings("ignore", message=silence_pattern("rotation"))``, all of them
with ``category=PlausibilityWarning``.

The limits are physical, not tuned: MEMS gyros measure at most a few thousand deg/s; a zero-rate offset is at
most tens of deg/s (the MPU-6050's tolerance is +-20 deg/s); a bias does not move by tens of deg/s within a run
at rest; temperatures of electronics in degC lie far below 150 (in kelvin they are above 200); sample rates of
logged IMUs lie between 1 mHz and 100 kHz.

One check compares the data with the model applied to it (``agreement``): on data at rest through a temperature
change, an axis's output follows the model's predicted error one to one; a slope far from 1 is a unit mistake
(0.0175 for rad/s read as deg/s), an axis mapped with the wrong sign (-1), or a model of another part. The slope
is taken over 60 s block means (:class:`BlockMeans`, the same for any chunking of a stream), and said only when it
lies beyond a factor of 2 either way by four standard errors, so motion, short logs and small temperature changes
(a wide interval) never raise it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import CHECKS, CheckName, InputError, PlausibilityWarning, silence_pattern
from ..effects import moving_average_range
from ..recording import GAP_FACTOR, Recording
from ..runs.prepared import PreparedRun
from ..units import STANDARD_GRAVITY_M_PER_S2

#: beyond any MEMS gyro's measurement range [deg/s]
MAX_RATE_DPS = 5000.0
#: the most any MEMS accelerometer measures [g]
MAX_ACCEL_G = 1000.0
#: beyond any zero-rate offset at rest [deg/s]
MAX_OFFSET_DPS = 50.0
#: a bias moves less than this within a run at rest; more is rotation [deg/s], judged on 10 s means
MAX_SWING_DPS = 25.0
SWING_WINDOW_S = 10.0
#: electronics read in degC stay below this; a median above it is probably kelvin [degC]
KELVIN_LOOKING_DEGC = 150.0
#: no MEMS sensor reports a temperature outside this (their ratings are -55..150 degC at most) [degC]
TEMPERATURE_RANGE_DEGC = (-100.0, 200.0)
#: a calibration run that varies less than this in temperature cannot identify a temperature curve [degC]
MIN_TEMPERATURE_SPAN_DEGC = 1.0
#: still poses of a hand-turned multi-position session: 1 s still, judged on 0.5 s windows, up to 10 times the
#: median variance (as gyrocomp.fitting.triad_fit.find_poses finds them)
POSE_WINDOW_S, POSE_MIN_S, POSE_FACTOR = 0.5, 1.0, 10.0
#: plausible sample rates of a logged IMU [Hz] (the fastest MEMS output data rates are 32 kHz)
RATE_RANGE_HZ = (1e-3, 4e4)
#: a recording this long at 1 Hz or slower is more likely a time column in ms read as s [s]
LONG_SLOW_S = 7 * 86400.0
#: time stamps in bursts: more than this share of the time steps are gaps (a dropout is a rare event) ...
BURST_GAP_SHARE = 0.05
#: ... and the samples' mean step is more than this many median steps (dropouts, even many, lengthen the mean
#: step a little; stamps taken when buffered samples arrive make the median step that of the transfer)
BURST_MEAN_STEPS = 2.0
#: the median norm of three accelerometer axes [g] that a unit mistake gives (gravity is 1 g, at rest and on
#: average in ordinary motion), and the mistake; said within 20 % of one
ACCEL_NORM_MISTAKES = (
    (STANDARD_GRAVITY_M_PER_S2, "m/s^2 read as g"),
    (1000.0, "mg read as g"),
    (1.0 / STANDARD_GRAVITY_M_PER_S2, "g read as m/s^2"),
)
#: the agreement check: block length [s], fewest complete blocks, the factor either way the data's slope on the
#: model's prediction may differ from 1 unsaid, and by how many standard errors it must lie beyond it
AGREEMENT_BLOCK_S, AGREEMENT_MIN_BLOCKS, AGREEMENT_FACTOR, AGREEMENT_SIGMAS = 60.0, 10, 2.0, 4.0
#: slopes that mean a known mistake, and the words for it (named when the slope is within 25 % of one)
KNOWN_SLOPES = (
    (math.pi / 180.0, "rad/s read as deg/s?"),
    (180.0 / math.pi, "deg/s data for a model fitted on rad/s?"),
    (1e-3, "a factor of 1/1000: the wrong unit prefix?"),
    (1e3, "a factor of 1000: the wrong unit prefix?"),
    (-1.0, "the opposite sign: an axis mapped with the wrong sign?"),
)


@dataclass(frozen=True)
class Concern:
    """One finding: the check that found it (``rate``, ``offset``, ``rotation``, ``kelvin``, ``time-unit``,
    ``time-bursts``, ``temperature-span``, ``agreement``, ``accel-unit``, ``temperature-range``) and the one-line
    message, which starts with the recording's source."""

    check: CheckName
    message: str

    def warning(self) -> PlausibilityWarning:
        """The warning to raise: the message ending with ``(check 'NAME')``, ``check`` set."""
        return PlausibilityWarning(f"{self.message} (check '{self.check}')", check=self.check)


#: the unit checks judge a median; past this many samples they take it of an evenly spaced subsample (a unit
#: mistake moves every sample, and the exact median of a day at 100 Hz costs a tenth of a second per check)
MEDIAN_SAMPLES = 100_000


def _stride(n: int) -> int:
    return max(1, n // MEDIAN_SAMPLES)


def _median(values: np.ndarray) -> float:
    """The median of ``values`` (all of them, or every k-th past MEDIAN_SAMPLES)."""
    return float(np.median(values[:: _stride(len(values))]))


def recording_concerns(recording: Recording) -> list[Concern]:
    """Unit mistakes any use of ``recording`` suffers from: values beyond any MEMS range, kelvin-looking
    temperatures, a temperature no sensor reaches (named with its row), an implausible sample rate (a time column
    in ms read as s, or the reverse)."""
    out = []
    src = recording.source
    gyro = recording.gyro_dps  # its largest magnitude from its extremes: no copy of the samples
    peak = max(float(np.max(gyro)), -float(np.min(gyro))) if gyro.size else 0.0
    if peak > MAX_RATE_DPS:
        out.append(
            Concern(
                "rate",
                f"{src}: gyro values up to {peak:.4g} deg/s, beyond any MEMS gyro's range "
                f"({MAX_RATE_DPS:g} deg/s): a unit mistake or a corrupt file?",
            )
        )
    if recording.temperature_degc is not None:
        median = _median(recording.temperature_degc)
        if median > KELVIN_LOOKING_DEGC:
            out.append(
                Concern(
                    "kelvin",
                    f"{src}: median temperature {median:.4g} degC looks like kelvin; "
                    "gyrocomp reads degC (subtract 273.15)",
                )
            )
        else:
            out += temperature_range_concerns(recording)
    concern = accel_unit_concern(recording)
    if concern is not None:
        out.append(concern)
    concern = time_unit_concern(src, recording.rate_hz, recording.duration_s)
    if concern is not None:
        out.append(concern)
    concern = time_bursts_concern(recording)
    if concern is not None:
        out.append(concern)
    return out


def time_bursts_concern(recording: Recording) -> Concern | None:
    """Time stamps that came in bursts: more than :data:`BURST_GAP_SHARE` of the time steps are gaps (longer than
    :data:`gyrocomp.recording.GAP_FACTOR` median steps) and the mean step is over :data:`BURST_MEAN_STEPS` median
    steps. Stamps taken when a buffer of samples arrives (a serial or USB link, a phone's sensor events) look so:
    the rate read from them (the median step's) is that of the transfer, not the sensor's, and figures that use
    it (Allan deviation, noise densities) are off by the ratio of the two."""
    steps = recording.n_samples - 1
    if steps < 2 or len(recording.gaps) <= BURST_GAP_SHARE * steps:
        return None
    mean_rate_hz = recording.mean_rate_hz
    if recording.rate_hz <= BURST_MEAN_STEPS * mean_rate_hz:
        return None
    return Concern(
        "time-bursts",
        f"{recording.source}: the time stamps come in bursts: {len(recording.gaps)} of {steps} steps "
        f"({len(recording.gaps) / steps:.0%}) are gaps over {GAP_FACTOR:g} times the median step "
        f"({1e3 / recording.rate_hz:.3g} ms, {recording.rate_hz:.4g} Hz), and the samples average "
        f"{mean_rate_hz:.4g} Hz: the stamps look like when buffered samples arrived, not when they were taken, "
        f"and what uses the rate (Allan deviation, noise densities) would be {recording.rate_hz / mean_rate_hz:.2g} "
        f"times off; if the sensor samples evenly, read the samples at that rate, their stamps left unread "
        f"(columns={{'time': ''}} and rate_hz={mean_rate_hz:.4g})",
    )


def time_unit_concern(source: str, rate_hz: float, duration_s: float) -> Concern | None:
    """A sample rate [Hz] or a length [s] that says the time column was read in the wrong unit (nanoseconds or
    milliseconds read as seconds, or the reverse)."""
    lo, hi = RATE_RANGE_HZ
    if not lo <= rate_hz <= hi:
        return Concern(
            "time-unit",
            f"{source}: {rate_hz:.3g} Hz is no IMU's sample rate: is the time column in "
            "another unit than the one given?",
        )
    if duration_s > LONG_SLOW_S and rate_hz <= 1.0:
        return Concern(
            "time-unit",
            f"{source}: {duration_s / 86400:.3g} days at {rate_hz:.3g} Hz: is the time column in ms read as s?",
        )
    return None


def temperature_range_concerns(recording: Recording) -> list[Concern]:
    """Samples whose temperature no sensor reaches (``TEMPERATURE_RANGE_DEGC``), named with the first one's row:
    one corrupt sample at 1e6 degC stretches a temperature model's range and its bins over nothing."""
    t = np.asarray(recording.temperature_degc, dtype=float)
    lo, hi = TEMPERATURE_RANGE_DEGC
    bad = np.flatnonzero(np.any((t < lo) | (t > hi), axis=1) if t.ndim == 2 else (t < lo) | (t > hi))
    if not bad.size:
        return []
    first = int(bad[0])
    value = float(np.ravel(t[first])[np.argmax(np.abs(np.ravel(t[first]) - 25.0))])
    return [
        Concern(
            "temperature-range",
            f"{recording.source}: row {int(recording.row_numbers[first])}: temperature "
            f"{value:.4g} degC, beyond any sensor's range ({lo:g}..{hi:g} degC)"
            + (f", and {bad.size - 1} row(s) more" if bad.size > 1 else "")
            + ": a corrupt sample, or another unit?",
        )
    ]


def accel_unit_concern(recording: Recording) -> Concern | None:
    """The accelerometer read in the wrong unit: the median norm of its three axes [g] is gravity's 1 g at rest
    and, on average, in a vehicle's ordinary motion; a median near 9.81, 1000 or 0.102 is m/s^2, mg, or g data
    read as m/s^2 (``ACCEL_NORM_MISTAKES``)."""
    if recording.accel_g is None or recording.accel_g.shape[1] != 3 or not recording.accel_g.size:
        return None
    accel = recording.accel_g[:: _stride(len(recording.accel_g))]
    norm = _median(np.sqrt(np.einsum("ij,ij->i", accel, accel)))
    for value, words in ACCEL_NORM_MISTAKES:
        if abs(norm / value - 1.0) < 0.2:
            return Concern(
                "accel-unit",
                f"{recording.source}: the accelerometer's median norm is {norm:.3g} g where "
                f"gravity is 1 g: {words}? (give its unit with accel_unit=)",
            )
    return None


def calibration_concerns(recording: Recording) -> list[Concern]:
    """What makes ``recording`` a poor calibration run besides :func:`recording_concerns`: a zero-rate offset
    no MEMS part has, or a swing of the 10 s means that only rotation makes (a 10 s mean is the angle turned
    over 10 s: turning a unit between positions, 90 or 180 degrees, stays below the limit, a rate table does
    not; a hand-turned multi-position session may exceed it and is recognized, :func:`turned_between_poses`)."""
    out = recording_concerns(recording)
    src = recording.source
    w = max(1, int(round(SWING_WINDOW_S * recording.rate_hz)))
    for j, axis in enumerate(recording.gyro_axes):
        x = recording.gyro_dps[:, j]
        median = _median(x)
        if abs(median) > MAX_OFFSET_DPS:
            out.append(
                Concern(
                    "offset",
                    f"{src}: {axis} reads {median:.3g} deg/s at the median, more than any "
                    "zero-rate offset: does the unit turn, or is the unit of the data wrong?",
                )
            )
        if x.size >= w:
            swing = moving_average_range(x, w)
            if swing > MAX_SWING_DPS and not turned_between_poses(recording):
                out.append(
                    Concern(
                        "rotation",
                        f"{src}: {axis} swings by {swing:.3g} deg/s over {SWING_WINDOW_S:g} s "
                        "means: the unit turns, and a calibration run must be at rest "
                        "(record still positions, or cut the run to them)",
                    )
                )
    return out


def turned_between_poses(recording: Recording) -> bool:
    """Whether the recording is a multi-position session: still poses (of at least 1 s) whose gravity directions
    turn every accelerometer axis within 60 deg of up and of down. Its turns are meant (the fits use its still
    stretches, and the scale-factor fit its turns), so its swing is no sign of a run that should have been at
    rest."""
    if recording.accel_g is None or recording.accel_g.shape[1] != 3:
        return False
    segments = PreparedRun.of(recording).static_segments(
        window_s=POSE_WINDOW_S, min_duration_s=POSE_MIN_S, factor=POSE_FACTOR
    )
    if len(segments) < 6:
        return False
    means = np.array([recording.accel_g[s.start : s.stop].mean(axis=0) for s in segments])
    units = means / np.maximum(np.linalg.norm(means, axis=1), 1e-12)[:, None]
    return bool(np.all(np.any(units > 0.5, axis=0)) and np.all(np.any(units < -0.5, axis=0)))


class BlockMeans:
    """Means of some columns over fixed time blocks counted from the first sample: the same blocks and, to
    rounding, the same means whatever the chunks they come in (:meth:`add` each chunk in time order).

    Parameters
    ----------
    columns : int
        How many columns each chunk has.
    block_s : float
        Block length [s].
    """

    def __init__(self, columns: int, block_s: float = AGREEMENT_BLOCK_S):
        self.block_s = float(block_s)
        self.columns = int(columns)
        self._t0: float | None = None
        self._blocks: dict[int, np.ndarray] = {}  # block number -> [count, sums of the columns]; only those with data

    def add(self, time_s: np.ndarray, values) -> None:
        """One chunk: time [s] (m,), values (m, columns), or a list of arrays (m, c_i) whose columns together are
        the chunk's (no copy of them is made)."""
        if not len(time_s):
            return
        if self._t0 is None:
            self._t0 = float(time_s[0])
        index = np.floor((np.asarray(time_s, dtype=float) - self._t0) / self.block_s)
        parts = values if isinstance(values, list) else [values]
        parts = [np.asarray(v, dtype=float).reshape(len(index), -1) for v in parts]
        if np.all(index[1:] >= index[:-1]):  # time in order (a stream's always is): one pass per part
            starts = np.flatnonzero(np.concatenate([[True], index[1:] != index[:-1]]))
            numbers = index[starts]
            counts = np.diff(np.append(starts, len(index))).astype(float)
            sums = np.column_stack([counts, *(np.add.reduceat(v, starts, axis=0) for v in parts)])
        else:
            numbers, which = np.unique(index, return_inverse=True)
            rows = np.column_stack([np.ones(len(index)), *parts])
            sums = np.stack(
                [np.bincount(which, weights=rows[:, j], minlength=numbers.size) for j in range(rows.shape[1])], axis=1
            )
        for number, row in zip(numbers.tolist(), sums):
            if number in self._blocks:
                self._blocks[number] += row
            else:
                self._blocks[number] = row

    def means(self) -> np.ndarray:
        """The means (b, columns) of the complete blocks in time order: those with at least half the fullest
        block's samples (the last, partial block and blocks at the edges of gaps left out)."""
        if not self._blocks:
            return np.zeros((0, self.columns))
        table = np.array([self._blocks[k] for k in sorted(self._blocks)])
        full = table[:, 0] >= 0.5 * table[:, 0].max()
        return table[full, 1:] / table[full, :1]


@dataclass(frozen=True)
class ScaleAgreement:
    """How an axis's output follows the error a model predicts for it: the least-squares slope of the block means
    of the output on those of the prediction (1 when the model describes the data), its standard error, and the
    number of blocks."""

    slope: float
    standard_error: float
    blocks: int
    #: with the direction of temperature change as a second regressor: the offset between heating and cooling
    #: blocks [deg/s] and its standard error, and the slope on the prediction then (NaN without a temperature)
    direction_offset: float = math.nan
    direction_standard_error: float = math.nan
    slope_with_direction: float = math.nan

    @property
    def follows_direction(self) -> bool:
        """Whether the output parts between heating and cooling blocks by ``AGREEMENT_SIGMAS`` standard errors
        beyond what the model predicts, and with that part taken out the slope is within ``AGREEMENT_FACTOR``
        either way of 1: a branch (hysteresis) or a lag the model does not carry, rather than a unit or a part."""
        return bool(
            abs(self.direction_offset) > AGREEMENT_SIGMAS * self.direction_standard_error
            and 1.0 / AGREEMENT_FACTOR <= self.slope_with_direction <= AGREEMENT_FACTOR
        )

    @property
    def disagrees(self) -> bool:
        """The slope lies beyond ``AGREEMENT_FACTOR`` either way of 1 by ``AGREEMENT_SIGMAS`` standard errors."""
        margin = AGREEMENT_SIGMAS * self.standard_error
        return self.slope + margin < 1.0 / AGREEMENT_FACTOR or self.slope - margin > AGREEMENT_FACTOR


def _direction_fit(x: np.ndarray, y: np.ndarray, temperature_means: np.ndarray | None) -> tuple[float, float, float]:
    """(offset, its standard error, slope): ``y`` on ``x`` and on the direction of temperature change of each block
    (+1 heating, -1 cooling, from the block-mean temperatures' differences; blocks that hold still are 0), each
    about its mean; NaN without a temperature or with blocks of one direction only."""
    nan = (math.nan, math.nan, math.nan)
    if temperature_means is None or not np.all(np.isfinite(temperature_means)):
        return nan
    step = np.gradient(np.asarray(temperature_means, dtype=float))
    still = np.abs(step) <= 0.05 * np.max(np.abs(step)) if np.any(step) else np.ones(step.size, dtype=bool)
    d = np.where(still, 0.0, np.sign(step))
    if not (np.any(d > 0) and np.any(d < 0)):
        return nan
    a = np.column_stack([x, d - d.mean()])
    coef, *_ = np.linalg.lstsq(a, y, rcond=None)
    residual = y - a @ coef
    cov = np.linalg.pinv(a.T @ a) * float(residual @ residual) / max(x.size - 3, 1)
    # heating and cooling blocks part by twice the coefficient of the sign
    return 2.0 * float(coef[1]), 2.0 * math.sqrt(max(float(cov[1, 1]), 0.0)), float(coef[0])


def scale_agreement(
    output_means: np.ndarray, predicted_means: np.ndarray, temperature_means: np.ndarray | None = None
) -> ScaleAgreement | None:
    """The slope of an axis's block-mean output on its predicted error's (both [deg/s]), with its standard error
    from the scatter about the line (each about its mean: the turn-on constant does not enter). With the blocks'
    mean temperatures [degC], also the fit with the direction of temperature change as a second regressor
    (:attr:`ScaleAgreement.follows_direction`).

    None with fewer than ``AGREEMENT_MIN_BLOCKS`` blocks, or when the prediction's variation rests on fewer than
    half that many blocks (its participation ratio (sum |x|)^2 / sum x^2 of the centred means: n for a step over
    n blocks, 3n/4 for a ramp, 1 for one block), e.g. a prediction held at the edge of its range but in one block;
    a prediction constant to rounding (1e-9 of its size) does not vary, and one that is not finite (a corrupt
    temperature sent it past any float) says nothing.
    """
    x = np.asarray(predicted_means, dtype=float)
    y = np.asarray(output_means, dtype=float)
    if x.size < AGREEMENT_MIN_BLOCKS or not (np.all(np.isfinite(x)) and np.all(np.isfinite(y))):
        return None
    scale = float(np.max(np.abs(x)))
    if not np.ptp(x) > 1e-9 * scale:
        return None
    y = y - y.mean()
    y_scale = float(np.max(np.abs(y))) or 1.0
    x, y = (x - x.mean()) / scale, y / y_scale  # each in units of its largest value: no square overflows
    sxx = float(x @ x)
    if float(np.sum(np.abs(x))) ** 2 / sxx < AGREEMENT_MIN_BLOCKS / 2:
        return None
    slope = float(x @ y) / sxx
    residual = y - slope * x
    # blocks whose residual is a slow drift (neighbours alike) are fewer independent ones: the standard error is
    # that of the effective number of blocks, n (1 - r) / (1 + r), r the residual's lag-1 correlation (a drift of
    # the part over a stretch where the prediction varies little is then not read as a slope, nor as a unit)
    r = _lag_one_correlation(residual)
    effective = max(x.size * (1.0 - r) / (1.0 + r), 3.0)
    standard_error = math.sqrt(float(residual @ residual) / (x.size - 2) / sxx * (x.size - 2) / (effective - 2))
    offset, offset_se, slope_d = _direction_fit(x, y, temperature_means)
    return ScaleAgreement(
        slope * y_scale / scale,
        standard_error * y_scale / scale,
        int(x.size),
        offset * y_scale,
        offset_se * y_scale,
        slope_d * y_scale / scale,
    )


def _lag_one_correlation(residual: np.ndarray) -> float:
    """The lag-1 autocorrelation of ``residual`` (about its mean), within [0, 0.95] (a negative one is taken as
    none: it would only shrink the standard error)."""
    e = residual - residual.mean()
    denominator = float(e @ e)
    if e.size < 3 or denominator <= 0:
        return 0.0
    return float(np.clip(float(e[1:] @ e[:-1]) / denominator, 0.0, 0.95))


def agreement_concern(source: str, axis: str, agreement: ScaleAgreement | None) -> Concern | None:
    """The ``agreement`` concern of an axis whose output does not follow the model (see the module), naming the
    known mistake its slope matches."""
    if agreement is None or not (agreement.disagrees or agreement.follows_direction):
        return None
    slope = agreement.slope
    known = next((words for ratio, words in KNOWN_SLOPES if abs(slope / ratio - 1.0) < 0.25), None)
    if known is None and agreement.follows_direction:
        said = (
            f" (and follows the error the model predicts with a slope of {slope:.3g} +- "
            f"{agreement.standard_error:.2g}, not 1)"
            if agreement.disagrees
            else ""
        )
        return Concern(
            "agreement",
            f"{source}: {axis}'s output differs between heating and cooling by "
            f"{agreement.direction_offset:.2g} deg/s more than the model predicts{said}; with that difference "
            f"taken out, its slope on the prediction is {agreement.slope_with_direction:.3g}: a hysteresis or "
            "a thermal lag the model does not carry, or one unlike the fit runs' (another ramp rate)?",
        )
    return Concern(
        "agreement",
        f"{source}: {axis} follows the error the model predicts for it with a slope of "
        f"{slope:.3g} +- {agreement.standard_error:.2g}, not 1: "
        + (known or "is the data in another unit than the model's, or the model of another part?"),
    )


def _largest_span_degc(recordings: list[Recording]) -> float | None:
    """The largest temperature span of any run [degC], or None when no run has a temperature."""
    spans = [float(np.ptp(r.temperature_degc)) for r in recordings if r.temperature_degc is not None]
    return max(spans) if spans else None


def require_temperature_span(recordings: list[Recording], what: str) -> None:
    """Refuse to compare temperature models on runs whose temperature does not vary at all: every such model
    is then undetermined (``what`` names the operation in the message)."""
    span = _largest_span_degc(recordings)
    if span is not None and span < MIN_TEMPERATURE_SPAN_DEGC:
        raise InputError(
            f"{recordings[0].source}: the temperature of every run spans at most {span:.3g} degC; "
            f"{what} compares temperature models, which need runs over a temperature range"
        )


def temperature_span_concern(recordings: list[Recording]) -> Concern | None:
    """A temperature curve asked for on runs that each stay at one temperature: with one constant per run, such
    runs say nothing about the curve (a multi-position run at room temperature is fine for G alone)."""
    span = _largest_span_degc(recordings)
    if span is None or span >= MIN_TEMPERATURE_SPAN_DEGC:
        return None
    return Concern(
        "temperature-span",
        f"{recordings[0].source}: the temperature of every run spans at most "
        f"{span:.3g} degC; a temperature curve needs runs over a temperature "
        "range (or fit with temperature=None)",
    )


__all__ = [
    "AGREEMENT_BLOCK_S",
    "BlockMeans",
    "CHECKS",
    "CheckName",
    "Concern",
    "ScaleAgreement",
    "accel_unit_concern",
    "agreement_concern",
    "temperature_range_concerns",
    "time_unit_concern",
    "calibration_concerns",
    "recording_concerns",
    "time_bursts_concern",
    "require_temperature_span",
    "scale_agreement",
    "silence_pattern",
    "temperature_span_concern",
    "turned_between_poses",
]
