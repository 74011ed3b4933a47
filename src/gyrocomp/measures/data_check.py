"""The data check before a fit: is each run fit to calibrate from, and if only partly, what does it cost?

Each check has a name, a documented threshold and a severity. A **refusal** is a run (or a set of runs) that cannot
give a valid fit of what is asked: a run given twice (samples another run holds too), no temperature, time that goes
back (two logs appended, a clock reset), no reversal where turning-point hysteresis is asked, and, when a
temperature curve is asked by name (``poly:3``, ``table``, ``mlp``), a constant temperature, too little span, or
fewer samples or temperature levels than the curve has parameters (fewer than ten samples and two levels per
parameter is a warning). Under the default automatic choice those are warnings: the choice then fits no curve (a
constant bias, and whatever else the runs identify, such as g-sensitivity from positions at one temperature), which
is a valid fit of what the data hold.
A **warning** is what only degrades a fit, said with its expected cost: temperature quantized in coarse steps,
gaps, a rail (saturated samples), motion, a unit probably read wrongly, time stamps reordered or repeated by a
logger. Any check is accepted knowingly by its name (``accept``; ``accept=NAME``): it is
then reported as accepted, never as a refusal.

The thresholds (module constants, each documented where it is defined) are physical or stated by the data
sheets, not tuned on a corpus: MEMS gyro white-noise densities lie between about 0.001 and 0.1 deg/s/sqrt(Hz)
(the best tactical MEMS parts at the low end, consumer parts at the high end), so a density 57.3 times outside
that range is a unit mistake; a temperature model needs a span larger than the sensor's own noise and steps.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from ..effects import moving_average
from ..errors import TimeOrderWarning
from ..recording import Recording
from ..spilled_series import parts, streamed_median
from .plausibility import time_bursts_concern, turned_between_poses
from .sample_check import TEMPERATURE_SPIKE_DEGC, SampleCheck, SampleFacts

Severity = Literal["refuse", "warn"]
#: every check, in the order a verdict line lists them
DATA_CHECKS = (
    "repeated",
    "gyro-constant",
    "axes-identical",
    "time",
    "temperature-missing",
    "temperature-constant",
    "temperature-span",
    "too-short",
    "reversal",
    "temperature-quantized",
    "temperature-spikes",
    "gaps",
    "rail",
    "motion",
    "unit",
    "counts",
)

#: a temperature that varies less than this over a run is constant (a stuck or absent sensor) [degC]
CONSTANT_SPAN_DEGC = 0.01
#: a set of runs spanning less than this cannot identify a temperature curve [degC] (the plausibility check's)
MIN_SPAN_DEGC = 1.0
#: gyro samples that are whole numbers, on every axis, spread over at least this many of them: raw counts of the
#: sensor's converter read as deg/s (a MEMS gyro's rate in deg/s is never whole in every sample)
COUNTS_MIN_LEVELS = 8
#: temperature steps at least this coarse are said (whole or half degrees); finer LSBs are no concern [degC]
QUANTIZED_STEP_DEGC = 0.25
#: time that goes back by more than this many sample periods, and at least TIME_BACK_MIN_S, is two logs or a
#: clock reset, refused; less is a logger's reordering, sorted and said
TIME_BACK_PERIODS, TIME_BACK_MIN_S = 10, 1.0
#: gaps are said when the longest is at least this many sample periods and GAP_MIN_S long, or when this
#: fraction of the run is missing
GAP_PERIODS, GAP_MIN_S, GAP_MISSING_FRACTION = 10, 1.0, 0.01
#: a rail: an axis's extreme value held for at least this many consecutive samples, and this many robust
#: standard deviations from the axis's median
RAIL_RUN_SAMPLES, RAIL_SIGMAS = 3, 20.0
#: motion: consecutive 10 s means of an axis differ by more than this [deg/s] (the bias moves by hundredths of a
#: deg/s in 10 s, even on a chamber ramp of 10 degC/min; a turning unit by degrees per second)
MOTION_WINDOW_S, MOTION_DPS = 10.0, 1.0
#: the white-noise density of MEMS gyros [deg/s/sqrt(Hz)]: outside this, the data's unit is probably wrong
NOISE_DENSITY_RANGE = (1e-3, 0.2)
#: the noise density is read in windows of this many differences, at this percentile of their spread (the quiet
#: windows: a hand-turned session's poses, a chamber run's any)
UNIT_WINDOW_SAMPLES, UNIT_QUIET_PERCENTILE, UNIT_MAX_WINDOWS = 20, 10.0, 20_000
#: that percentile of the spread of 20 differences of white noise, over sqrt(2) sigma (by simulation of 1e5
#: windows; its own error below 1 %): the estimate is divided by it
UNIT_QUIET_FACTOR = 0.7455
#: two runs holding this many of the same samples or more are one run given twice, in whole or in part (one shared
#: sample is a boundary: a window cut by hand at an inclusive end, as MATLAB's ``data(1:1000)``, ``data(1000:2000)``)
MIN_SHARED_ROWS = 2
#: samples per parameter of the temperature curve below which a run set is too short, and distinct temperature
#: levels (at 0.1 degC) per parameter
SAMPLES_PER_PARAMETER, LEVELS_PER_PARAMETER = 10, 2


@dataclass(frozen=True)
class Ask:
    """What the fit asks of the data.

    Parameters
    ----------
    temperature : {"auto", "asked", "none"}
        The temperature curve: chosen automatically (the default), asked by name, or none.
    hysteresis : bool
        Turning-point hysteresis is asked explicitly (the runs must heat and cool).
    parameters : int
        Parameters of the temperature curve (a cubic: 4; a 1-3-1 network: 10).
    """

    temperature: Literal["auto", "asked", "none"] = "auto"
    hysteresis: bool = False
    parameters: int = 4


@dataclass(frozen=True)
class Finding:
    """One check's finding: its name, refusal or warning, the message (starting with the run) and, for a warning,
    its expected cost."""

    check: str
    severity: Severity
    message: str
    cost: str = ""

    def text(self) -> str:
        return self.message + (f"; expected cost: {self.cost}" if self.cost else "")


@dataclass(frozen=True)
class RunCheck:
    """The data check of one run: its findings, and those accepted by name (reported, never refusing)."""

    source: str
    findings: tuple[Finding, ...] = ()
    accepted: tuple[Finding, ...] = ()

    @property
    def verdict(self) -> Literal["refused", "warning", "ok"]:
        if any(f.severity == "refuse" for f in self.findings):
            return "refused"
        return "warning" if self.findings else "ok"

    @property
    def reasons(self) -> tuple[str, ...]:
        """The names of the checks that found something (not those accepted)."""
        return tuple(dict.fromkeys(f.check for f in self.findings))

    def line(self) -> str:
        """One verdict line: ``SOURCE: refused (checks): first message`` (``ok`` when nothing was found)."""
        if not self.findings:
            extra = f" (accepted: {', '.join(f.check for f in self.accepted)})" if self.accepted else ""
            return f"{self.source}: ok{extra}"
        first = (
            next(f for f in self.findings if f.severity == "refuse") if self.verdict == "refused" else self.findings[0]
        )
        text = first.text()
        text = text[len(self.source) + 2 :] if text.startswith(self.source + ": ") else text
        return f"{self.source}: {self.verdict} ({', '.join(self.reasons)}): {text}"

    def to_dict(self) -> dict:
        return {
            "source": self.source,
            "verdict": self.verdict,
            "findings": [_finding_dict(f) for f in self.findings],
            "accepted": [_finding_dict(f) for f in self.accepted],
        }


def _finding_dict(f: Finding) -> dict:
    return {"check": f.check, "severity": f.severity, "message": f.message, "cost": f.cost}


# -- the checks of one run ------------------------------------------------------------------------------------
def _temperature(recording: Recording) -> np.ndarray | None:
    """The run's temperature [degC] (the mean of several sensors), finite samples only; None when absent."""
    t = recording.temperature_degc
    if t is None:
        return None
    t = np.asarray(t, dtype=float)
    t = t.mean(axis=1) if t.ndim == 2 else t
    if not np.isfinite(t).all():  # a recording's values are finite; a copy only for one that is not
        t = t[np.isfinite(t)]
    return t if t.size else None


def _quantization_step(t: np.ndarray) -> float:
    """The step of a temperature read on a grid [degC] (0 when it is not): the smallest change, when every value
    lies on multiples of it from the first. Read a part at a time (:func:`gyrocomp.spilled_series.parts`)."""
    smallest, changes = np.inf, 0
    for start, stop in parts(t.size, overlap=1):
        steps = np.abs(np.diff(t[start:stop]))
        steps = steps[steps > 1e-9]
        changes += steps.size
        smallest = min(smallest, float(np.min(steps))) if steps.size else smallest
    if changes < 3:
        return 0.0
    q, on_grid = smallest, 0
    for start, stop in parts(t.size):
        scaled = (t[start:stop] - t[0]) / q
        on_grid += int(np.count_nonzero(np.abs(scaled - np.round(scaled)) < 1e-3))
    return q if on_grid / t.size > 0.99 else 0.0


def _slope_dps_per_degc(recording: Recording, t: np.ndarray) -> float:
    """The largest least-squares slope of an axis on the temperature ``t`` [degC] (for costs) [deg/s/degC],
    summed a part at a time."""
    if np.ptp(t) <= 0 or t.size != recording.n_samples:
        return 0.0
    t_mean, g_mean = t.mean(), recording.gyro_dps.mean(axis=0)
    cross, power = np.zeros(recording.gyro_dps.shape[1]), 0.0
    for start, stop in parts(t.size):
        x = t[start:stop] - t_mean
        cross += x @ (recording.gyro_dps[start:stop] - g_mean)
        power += float(x @ x)
    return float(np.max(np.abs(cross / power)))


def temperature_findings(recording: Recording, ask: Ask) -> list[Finding]:
    """Missing and quantized temperature of one run (a constant one and the span are judged over the set of
    runs: a run at one temperature beside runs that span enough is fine)."""
    if ask.temperature == "none":
        return []
    src = recording.source
    t = _temperature(recording)
    if t is None:
        return [
            Finding(
                "temperature-missing",
                "refuse",
                f"{src}: no temperature column (or no finite sample in "
                "it): a temperature curve cannot be fitted (map one with columns={'temperature': 'NAME'}, "
                "or temperature=none fits a bias alone)",
            )
        ]
    q = _quantization_step(t) if np.ptp(t) >= CONSTANT_SPAN_DEGC else 0.0
    if q >= QUANTIZED_STEP_DEGC:
        slope = _slope_dps_per_degc(recording, t)
        return [
            Finding(
                "temperature-quantized",
                "warn",
                f"{src}: the temperature is read in steps of {q:.3g} degC",
                f"about {slope * q / math.sqrt(12):.2g} deg/s RMS of bias error (the slope "
                f"{slope:.2g} deg/s/degC times the step's {q / math.sqrt(12):.2g} degC RMS)",
            )
        ]
    return []


#: the cost of too little temperature under the automatic choice
_NO_CURVE = "no temperature curve: the automatic choice fits a constant bias"


def _curve_severity(ask: Ask) -> Severity:
    """A refusal when a curve is asked by name; a warning under the automatic choice (which then fits none)."""
    return "refuse" if ask.temperature == "asked" else "warn"


def gap_findings(recording: Recording) -> list[Finding]:
    """Gaps: the longest at least GAP_PERIODS sample periods and GAP_MIN_S, or GAP_MISSING_FRACTION missing."""
    if not recording.gaps:
        return []
    bursts = time_bursts_concern(recording)
    if bursts is not None:  # the steps are between bursts of stamps, no sample is missing
        return [
            Finding(
                "gaps",
                "warn",
                bursts.message,
                f"no sample missing; what uses the rate ({recording.rate_hz:.4g} Hz from the median step) is "
                f"{recording.rate_hz / recording.mean_rate_hz:.2g} times off",
            )
        ]
    period = 1.0 / recording.rate_hz
    longest = recording.gaps.longest()
    missing = float(np.sum(recording.gaps.durations_s - period))
    fraction = missing / max(recording.duration_s, period)
    if longest.duration_s < max(GAP_PERIODS * period, GAP_MIN_S) and fraction < GAP_MISSING_FRACTION:
        return []
    return [
        Finding(
            "gaps",
            "warn",
            f"{recording.source}: {len(recording.gaps)} gap(s), {missing:.4g} s in all "
            f"({100 * fraction:.2g} % of the run; longest {longest.duration_s:.4g} s after row "
            f"{longest.after_row})",
            f"{100 * fraction:.2g} % fewer samples; the drift over the gaps is not seen, nothing is interpolated",
        )
    ]


def sample_findings(facts: SampleFacts, source: str) -> list[Finding]:
    """The findings of the sample checks (:class:`gyrocomp.measures.sample_check.SampleFacts` of the run
    ``source``): a gyro that says nothing, temperature spikes and raw counts."""
    return gyro_findings(facts, source) + temperature_spike_findings(facts, source) + counts_findings(facts, source)


def gyro_findings(facts: SampleFacts, source: str) -> list[Finding]:
    """A gyro that says nothing: an axis whose every sample is the same value (a dead or absent axis; every axis:
    refused, one of several: a warning), and two axes that hold the same samples (one column mapped twice: a
    warning)."""
    out = []
    axes = facts.gyro_axes
    if facts.constant_dps:
        every = len(facts.constant_dps) == len(axes)
        named = ", ".join(f"{axes[j]} ({v:.6g} deg/s)" for j, v in facts.constant_dps.items())
        out.append(
            Finding(
                "gyro-constant",
                "refuse" if every else "warn",
                f"{source}: {named}: every sample the same value: a dead, absent or unconnected "
                + ("gyro, or the wrong columns mapped; nothing to calibrate" if every else "axis"),
                "" if every else "that axis is fitted as the constant it holds",
            )
        )
    for j, k in facts.identical:
        out.append(
            Finding(
                "axes-identical",
                "warn",
                f"{source}: {axes[j]} and {axes[k]} hold the same samples in every row: one "
                "column mapped to two axes? (map each axis to its own column)",
                "the two axes are fitted as one: if they are two sensors' axes, one of them is wrong",
            )
        )
    return out


def temperature_spike_findings(facts: SampleFacts, source: str) -> list[Finding]:
    """Temperature spikes: samples TEMPERATURE_SPIKE_DEGC or more from the median of the TEMPERATURE_SPIKE_SAMPLES
    around them (a sensor's read errors, -40 degC or a bit flip), said with their count and first rows."""
    if not facts.spikes:
        return []
    first = ", ".join(str(r) for r in facts.spike_rows)
    return [
        Finding(
            "temperature-spikes",
            "warn",
            f"{source}: {facts.spikes} temperature sample(s) jump {TEMPERATURE_SPIKE_DEGC:g} degC or more "
            f"from their neighbours and back (rows {first}{', ...' if facts.spikes > len(facts.spike_rows) else ''}; "
            f"up to {facts.spike_worst_degc:.3g} degC from their neighbours' median): read errors of the sensor",
            f"{100 * facts.spikes / facts.temperature_samples:.2g} % of the samples at temperatures the die never "
            "had: a fit bends the curve toward them, a compensation applies the curve there; cut or mend those rows",
        )
    ]


def counts_findings(facts: SampleFacts, source: str) -> list[Finding]:
    """Raw counts: every gyro sample a whole number, on every axis, over COUNTS_MIN_LEVELS values or more (a
    converter's output read as deg/s)."""
    if facts.n_samples < COUNTS_MIN_LEVELS or not facts.whole_numbers or facts.spread_dps < COUNTS_MIN_LEVELS:
        return []
    return [
        Finding(
            "counts",
            "warn",
            f"{source}: every gyro sample is a whole number (spread over {facts.spread_dps:.0f} of them): raw "
            "counts of the sensor's converter read as deg/s? give their scale as the gyro's unit (gyro_unit="
            "'1/131 deg/s' for 131 counts per deg/s, as its data sheet states)",
            "a model in counts, wrong by the sensor's scale factor wherever deg/s are expected",
        )
    ]


def rail_findings(recording: Recording) -> list[Finding]:
    """A rail: an axis's extreme value held RAIL_RUN_SAMPLES times in a row, RAIL_SIGMAS from its median (the
    medians exact, a part at a time: :func:`gyrocomp.spilled_series.streamed_median`)."""
    out = []
    for j, axis in enumerate(recording.gyro_axes):
        x = recording.gyro_dps[:, j]
        median = streamed_median(x[a:b] for a, b in parts(x.size))
        sigma = 1.4826 * streamed_median(np.abs(x[a:b] - median) for a, b in parts(x.size)) or 1e-12
        for edge in (float(np.max(x)), float(np.min(x))):
            at = np.flatnonzero(x == edge)
            held = np.flatnonzero(np.diff(at) == 1)
            if at.size < RAIL_RUN_SAMPLES or _longest_run(held) + 1 < RAIL_RUN_SAMPLES - 1:
                continue
            centre, spread = median, sigma
            if x.size // 10 < at.size < x.size:  # plateaus hold much of the run: judged against the rest
                rest = [x[a:b][x[a:b] != edge] for a, b in parts(x.size)]
                centre = streamed_median(rest)
                spread = 1.4826 * streamed_median(np.abs(r - centre) for r in rest) or 1e-12
            if abs(edge - centre) < RAIL_SIGMAS * spread:
                continue
            out.append(
                Finding(
                    "rail",
                    "warn",
                    f"{recording.source}: {axis} sits at {edge:.5g} deg/s for {at.size} "
                    f"sample(s) (first at row {int(recording.row_numbers[at[0]])}): the sensor's range "
                    "was exceeded",
                    f"{at.size} sample(s) ({100 * at.size / x.size:.2g} %) wrong by an "
                    "unknown amount; the unit moved, so the run is no rest either",
                )
            )
    return out


def _longest_run(held: np.ndarray) -> int:
    """The longest stretch of consecutive indices in ``held``."""
    if not held.size:
        return 0
    breaks = np.flatnonzero(np.diff(held) != 1)
    lengths = np.diff(np.concatenate(([0], breaks + 1, [held.size])))
    return int(lengths.max())


def motion_findings(recording: Recording) -> list[Finding]:
    """Motion: consecutive 10 s means of an axis that differ by more than MOTION_DPS (the bias drifts by hundredths
    of a deg/s in 10 s, even on a fast chamber ramp; a turning unit by degrees per second); a multi-position
    session (still poses that turn every accelerometer axis up and down) turns on purpose and is not said."""
    w = max(1, int(round(MOTION_WINDOW_S * recording.rate_hz)))
    n_blocks = recording.gyro_dps.shape[0] // w
    if n_blocks < 2:
        return []
    blocks = recording.gyro_dps[: n_blocks * w].reshape(n_blocks, w, -1).mean(axis=1)
    steps = np.abs(np.diff(blocks, axis=0))
    jump = np.any(steps > MOTION_DPS, axis=1)
    if not jump.any() or turned_between_poses(recording):
        return []
    moving = np.zeros(n_blocks, dtype=bool)
    moving[:-1] |= jump
    moving[1:] |= jump
    fraction, worst = float(moving.mean()), float(steps.max())
    return [
        Finding(
            "motion",
            "warn",
            f"{recording.source}: the unit moves in {int(moving.sum())} of {n_blocks} "
            f"10 s windows (their means jump by up to {worst:.3g} deg/s)",
            f"up to {worst * fraction:.2g} "
            f"deg/s of bias error where the moving {100 * fraction:.2g} % of the run lies, unless cut out",
        )
    ]


def white_noise_density(recording: Recording) -> float:
    """The gyro's white-noise density [deg/s/sqrt(Hz)] where the unit is stillest: the standard deviation of
    sample-to-sample differences over windows of UNIT_WINDOW_SAMPLES (at most UNIT_MAX_WINDOWS of them, evenly
    spread over the run), its UNIT_QUIET_PERCENTILE-th percentile (motion and steps leave the quiet windows alone)
    over UNIT_QUIET_FACTOR, divided by sqrt(2 rate); the median over the axes."""
    x = recording.gyro_dps
    span = UNIT_WINDOW_SAMPLES + 1
    if x.shape[0] < span:
        return float(np.median(np.std(np.diff(x, axis=0), axis=0))) / math.sqrt(2.0 * recording.rate_hz)
    starts = np.unique(np.linspace(0, x.shape[0] - span, min(UNIT_MAX_WINDOWS, x.shape[0] // span)).astype(int))
    windows = np.diff(x[starts[:, None] + np.arange(span)], axis=1).std(axis=1)  # (windows, axes)
    quiet = float(np.median(np.percentile(windows, UNIT_QUIET_PERCENTILE, axis=0))) / UNIT_QUIET_FACTOR
    return quiet / math.sqrt(2.0 * recording.rate_hz)


def unit_findings(recording: Recording) -> list[Finding]:
    """The gyro's unit: its white-noise density (:func:`white_noise_density`) outside NOISE_DENSITY_RANGE, by the
    factor of 57.3 a rad/s-deg/s mistake makes."""
    if recording.gyro_dps.shape[0] < 10:
        return []
    density = white_noise_density(recording)
    lo, hi = NOISE_DENSITY_RANGE
    if lo <= density <= hi or density == 0.0:
        return []
    words = (
        "rad/s read as deg/s? (give the gyro's unit: gyro_unit=rad/s)"
        if density < lo
        else "deg/s read as rad/s? (the gyro's unit given is wrong)"
    )
    return [
        Finding(
            "unit",
            "warn",
            f"{recording.source}: gyro white noise {density:.3g} deg/s/sqrt(Hz), outside any "
            f"MEMS gyro's {lo:g}..{hi:g}: {words}",
            "a model 57.3 times too small or too large",
        )
    ]


def time_findings(source: str, notes: Sequence[Warning], rate_hz: float) -> list[Finding]:
    """Time order from what the reader said (:class:`TimeOrderWarning`): going back far is refused, a logger's
    reordering or repeated stamps are said."""
    out = []
    for note in notes:
        if not isinstance(note, TimeOrderWarning):
            continue
        limit = max(TIME_BACK_PERIODS / rate_hz, TIME_BACK_MIN_S)
        if note.largest_back_s > limit:
            out.append(
                Finding(
                    "time",
                    "refuse",
                    f"{source}: the time goes back by {note.largest_back_s:.4g} s (more "
                    f"than {limit:.3g} s): two logs appended or a clock reset; split it into its parts",
                )
            )
        else:
            out.append(Finding("time", "warn", str(note), "none: the samples were put in order"))
    return out


#: the reader's refusals that are time order (tables refuse any backward or repeated time)
_TIME_REFUSAL = re.compile(r"time (repeats|goes backwards)")


def unreadable(source: str, message: str) -> RunCheck:
    """The check of a run the reader refused: ``time`` when its time repeats or goes back, else ``unreadable``."""
    check = "time" if _TIME_REFUSAL.search(message) else "unreadable"
    return RunCheck(source, (Finding(check, "refuse", message),))


# -- the checks of a set of runs ----------------------------------------------------------------------------------
def _levels(known: list) -> int:
    """How many distinct temperatures to 0.1 degC the runs' temperatures ``known`` [degC] hold, read
    a part at a time (as many values held as there are levels)."""
    levels = np.empty(0)
    for t in known:
        for start, stop in parts(t.size):
            levels = np.union1d(levels, np.round(t[start:stop], 1))
    return int(levels.size)


def _too_few_levels(recordings: Sequence[Recording], known: list, ask: Ask, out: dict) -> None:
    """Add to ``out`` (by run) the finding that the runs' temperatures ``known`` [degC] have fewer samples or
    levels than the curve asked needs."""
    samples = sum(t.size for t in known)
    levels = _levels(known)
    if samples >= SAMPLES_PER_PARAMETER * ask.parameters and levels >= LEVELS_PER_PARAMETER * ask.parameters:
        return
    # fewer samples or levels than parameters: the curve asked is not determined at all
    undetermined = ask.temperature == "asked" and min(samples, levels) < ask.parameters
    if ask.temperature == "auto":
        cost = _NO_CURVE
    else:
        cost = (
            ""
            if undetermined
            else "the curve's parameters poorly determined: its error between the levels is not known"
        )
    for i in range(len(recordings)):
        out.setdefault(i, []).append(
            Finding(
                "too-short",
                "refuse" if undetermined else "warn",
                f"{recordings[i].source}: {samples} "
                f"sample(s) at {levels} temperature level(s) for a curve of {ask.parameters} parameters (at "
                f"least {SAMPLES_PER_PARAMETER * ask.parameters} and {LEVELS_PER_PARAMETER * ask.parameters})",
                cost,
            )
        )


def _series(rec: Recording) -> list[np.ndarray]:
    return [rec.time_s, rec.gyro_dps] + ([] if rec.temperature_degc is None else [rec.temperature_degc])


def _shared_rows(a: Recording, b: Recording) -> tuple[int, int, int] | None:
    """Where ``b`` holds ``a``'s samples: (first row in a, first row in b, rows) when, over the time the two share,
    b's samples are a's at the same stamps, times, gyro and temperature equal (compared at the ends first, then a
    part at a time); None otherwise."""
    if min(a.n_samples, b.n_samples) == 0 or (a.temperature_degc is None) != (b.temperature_degc is None):
        return None
    lo, hi = max(a.time_s[0], b.time_s[0]), min(a.time_s[-1], b.time_s[-1])
    if lo > hi:
        return None
    first_b = int(np.searchsorted(b.time_s, lo))
    first_a = int(np.searchsorted(a.time_s, b.time_s[first_b]))
    if first_a >= a.n_samples or a.time_s[first_a] != b.time_s[first_b]:
        return None
    rows = min(a.n_samples - first_a, int(np.searchsorted(b.time_s, hi, side="right")) - first_b)
    if rows < MIN_SHARED_ROWS:
        return None
    pairs = list(zip(_series(a), _series(b)))
    ends = np.array([0, rows - 1])
    if not all(np.array_equal(x[first_a + ends], y[first_b + ends], equal_nan=True) for x, y in pairs):
        return None
    for start, stop in parts(rows):
        if not all(
            np.array_equal(x[first_a + start : first_a + stop], y[first_b + start : first_b + stop], equal_nan=True)
            for x, y in pairs
        ):
            return None
    return first_a, first_b, rows


def repeated_findings(recordings: Sequence[Recording]) -> dict[int, list[Finding]]:
    """Each run that holds samples an earlier run holds too, at the same time stamps with the same values (one file
    given twice, a glob that names it again, a copy, a run split from a log given beside the log): refused, since a
    run held out against itself would judge the model choice, and the drift it says to expect, on the data it was
    fitted to."""
    out: dict[int, list[Finding]] = {}
    for j, later in enumerate(recordings):
        for earlier in recordings[:j]:
            shared = _shared_rows(earlier, later)
            if shared is None:
                continue
            first_a, first_b, rows = shared
            if rows == earlier.n_samples == later.n_samples:
                what = f"the same samples as {earlier.source} (a run given twice)"
            else:
                what = (
                    f"its rows {first_b}..{first_b + rows - 1} are rows {first_a}..{first_a + rows - 1} of "
                    f"{earlier.source}, the same samples (a run given twice in part: a run split from a log given "
                    "beside the log)"
                )
            out[j] = [
                Finding(
                    "repeated",
                    "refuse",
                    f"{later.source}: {what}: held out against itself, it would judge the model and the drift to "
                    "expect on the data fitted; give each run once",
                )
            ]
            break
    return out


def set_findings(recordings: Sequence[Recording], ask: Ask) -> dict[int, list[Finding]]:
    """What only the runs together say, by run: a run repeated (:func:`repeated_findings`), a constant temperature
    in every run, too little span, too short for the curve, no reversal where hysteresis is asked (each said on
    every run it concerns)."""
    out: dict[int, list[Finding]] = repeated_findings(recordings)
    temps = [_temperature(r) for r in recordings]
    known = [t for t in temps if t is not None]
    if ask.temperature != "none" and known:
        _too_few_levels(recordings, known, ask, out)
    present = [t for t in temps if t is not None and np.ptp(t) >= CONSTANT_SPAN_DEGC]
    if ask.temperature != "none" and known and not present:  # every run at one temperature
        for i, t in enumerate(temps):
            if t is not None:
                out.setdefault(i, []).append(
                    Finding(
                        "temperature-constant",
                        _curve_severity(ask),
                        f"{recordings[i].source}: the temperature is "
                        f"constant ({t[0]:.4g} degC throughout), as in every run given: a stuck or absent sensor, or "
                        "runs that all stay at one set point",
                        _NO_CURVE if ask.temperature == "auto" else "",
                    )
                )
    if ask.temperature != "none" and present:
        span = float(max(t.max() for t in present) - min(t.min() for t in present))
        if span < MIN_SPAN_DEGC:
            for i, t in enumerate(temps):
                if t is not None:
                    out.setdefault(i, []).append(
                        Finding(
                            "temperature-span",
                            _curve_severity(ask),
                            f"{recordings[i].source}: the runs span {span:.3g} degC, "
                            f"less than {MIN_SPAN_DEGC:g} degC: no temperature curve "
                            "can be told from noise",
                            _NO_CURVE if ask.temperature == "auto" else "",
                        )
                    )
        if ask.hysteresis and not any(_reverses(t) for t in present):
            for i in range(len(recordings)):
                out.setdefault(i, []).append(
                    Finding(
                        "reversal",
                        "refuse",
                        f"{recordings[i].source}: the "
                        "temperature never turns back, and turning-point hysteresis "
                        "is asked: record heating and cooling",
                    )
                )
    return out


def _reverses(t: np.ndarray) -> bool:
    """Whether a temperature heats and cools by at least MIN_SPAN_DEGC each (judged on 1 % of its samples)."""
    s = moving_average(t, max(1, t.size // 100))
    rise = s - np.minimum.accumulate(s)
    fall = np.maximum.accumulate(s) - s
    return bool(
        rise.max() >= MIN_SPAN_DEGC
        and fall.max() >= MIN_SPAN_DEGC
        and (
            np.argmax(fall >= MIN_SPAN_DEGC) > np.argmax(rise >= MIN_SPAN_DEGC)
            or np.argmax(rise >= MIN_SPAN_DEGC) > np.argmax(fall >= MIN_SPAN_DEGC)
        )
    )


@dataclass(frozen=True)
class CheckedRun:
    """A run as read: its recording (None when the reader refused it) and what the reader said."""

    source: str
    recording: Recording | None
    notes: tuple[Warning, ...] = ()
    refusal: str | None = None


def check_runs(
    runs: Sequence[CheckedRun], ask: Ask | None = None, accept: Iterable[str] = (), still_only: Iterable[str] = ()
) -> list[RunCheck]:
    """The data check of each run (see the module), the checks named in ``accept`` reported as accepted.
    ``still_only``: the sources of field logs fitted on their still segments alone, whose motion is expected (it
    is not checked)."""
    ask = ask or Ask()
    accept, still_only = frozenset(accept), frozenset(still_only)
    readable = [i for i, r in enumerate(runs) if r.recording is not None]
    together = set_findings([runs[i].recording for i in readable], ask)
    position = {i: k for k, i in enumerate(readable)}
    out = []
    for i, run in enumerate(runs):
        if run.recording is None:
            out.append(_split(unreadable(run.source, run.refusal or "unreadable").findings, run.source, accept))
            continue
        rec = run.recording
        facts = SampleCheck().add(rec).facts()
        found = (
            time_findings(run.source, run.notes, rec.rate_hz)
            + temperature_findings(rec, ask)
            + together.get(position[i], [])
            + gyro_findings(facts, rec.source)
            + temperature_spike_findings(facts, rec.source)
            + gap_findings(rec)
            + rail_findings(rec)
            + (motion_findings(rec) if rec.source not in still_only else [])
            + unit_findings(rec)
            + counts_findings(facts, rec.source)
        )
        out.append(_split(found, run.source, accept))
    return out


def _split(found: Iterable[Finding], source: str, accept: frozenset[str]) -> RunCheck:
    found = sorted(found, key=lambda f: DATA_CHECKS.index(f.check) if f.check in DATA_CHECKS else -1)
    return RunCheck(
        source, tuple(f for f in found if f.check not in accept), tuple(f for f in found if f.check in accept)
    )


__all__ = [
    "Ask",
    "DATA_CHECKS",
    "CheckedRun",
    "Finding",
    "RunCheck",
    "check_runs",
    "repeated_findings",
    "sample_findings",
    "set_findings",
    "unreadable",
]
