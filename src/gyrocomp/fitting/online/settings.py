"""The online learner's settings, its constants and its status (see :mod:`gyrocomp.fitting.online`)."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields
from typing import Any, Literal

from ...errors import InputError
from ...motion.stillness import MIN_BLOCK_SAMPLES

LEARNER_FORMAT = "gyrocomp-learner"
LEARNER_SCHEMA_VERSION = 1
#: the saved states' ids a learner state keeps (its ancestors, its own last): a save may replace a state file only
#: when that file's id is among them (``OnlineCalibrator.check_state_target``)
LINEAGE_KEPT = 64
#: the curve's variable u = (T - T_REF_DEGC) / T_SCALE_DEGC
T_REF_DEGC = 25.0
T_SCALE_DEGC = 25.0
#: the held noise level may grow by this factor per block
LEVEL_GROWTH = 1.001
#: robust step spread once this many steps are known
MIN_STEPS = 10
#: a step between samples beyond this many nominal periods breaks the stream
GAP_PERIODS = 1.5
#: median absolute deviation of a unit normal (a MAD over this is a standard deviation)
MAD_TO_SIGMA = 0.6745
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
RIDGE = 1e-12
GYRO_AXES = ("gyro_x", "gyro_y", "gyro_z")


def chi2_quantile(z: float, dof: float) -> float:
    """The chi-square quantile of ``dof`` degrees of freedom at the normal quantile ``z`` (Wilson-Hilferty)."""
    h = 2.0 / (9.0 * dof)
    return dof * (1.0 - h + z * math.sqrt(h)) ** 3


#: settings that must be positive
_POSITIVE = (
    "rate_hz",
    "block_s",
    "min_still_s",
    "piece_s",
    "bin_width_degc",
    "half_life_h",
    "stale_h",
    "max_bias_dps",
    "outlier_dps",
    "outlier_sigmas",
    "max_tempco_dps_per_degc",
    "save_change_dps",
)
#: what the learner holds in memory grows with these: bounded, so a state file cannot ask for gigabytes
_MEMORY_BOUNDS = (
    ("rate_hz", 4e4),
    ("block_s", 60.0),
    ("min_still_s", 3600.0),
    ("piece_s", 3600.0),
    ("bin_width_degc", 50.0),
)


def _checked_lags(lags) -> tuple[float, ...]:
    """``lag_candidates_s`` checked: 1 to 8 time constants [s], the first 0 and the rest positive."""
    if isinstance(lags, (str, bytes)) or not hasattr(lags, "__len__"):
        raise InputError(f"lag_candidates_s: expected a list of time constants [s], got {lags!r}")
    lags = tuple(lags)
    if (
        not 1 <= len(lags) <= 8
        or any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in lags)
        or lags[0] != 0
        or any(not (math.isfinite(v) and v > 0) for v in lags[1:])
    ):
        raise InputError(
            f"lag_candidates_s: 1 to 8 time constants [s], the first 0 and the rest positive, got {list(lags)!r}"
        )
    return tuple(float(v) for v in lags)


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
        object.__setattr__(self, "lag_candidates_s", _checked_lags(self.lag_candidates_s))
        for f in fields(self):
            if f.name == "lag_candidates_s":
                continue
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise InputError(f"{f.name}: expected a finite number, got {value!r}")
        for name in _POSITIVE:
            if not getattr(self, name) > 0:
                raise InputError(f"{name}: must be positive, got {getattr(self, name):.6g}")
        for name, high in _MEMORY_BOUNDS:
            if getattr(self, name) > high:
                raise InputError(f"{name}: at most {high:g}, got {getattr(self, name):.6g}")
        if self.rate_hz * self.block_s > 1e6:
            raise InputError(
                f"block_s: {self.block_s:.6g} s at rate_hz={self.rate_hz:.6g} is "
                f"{self.rate_hz * self.block_s:.3g} samples a block; at most 1e6"
            )
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
            raise InputError(
                "cubic_span_degc and min_span_degc: need cubic_span_degc >= min_span_degc >= 0, got "
                f"{self.cubic_span_degc} and {self.min_span_degc}"
            )

    @property
    def block_samples(self) -> int:
        return max(MIN_BLOCK_SAMPLES, int(math.floor(self.block_s * self.rate_hz + 0.5)))

    @property
    def bins(self) -> int:
        return int(math.ceil((self.t_high_degc - self.t_low_degc) / self.bin_width_degc))

    def z_values(self) -> dict[str, float]:
        """The normal quantiles of the tests: the noise quantile's, and the variance and step tests' with three
        channels (gyro only) and six (gyro and accelerometer)."""
        from scipy.special import ndtri  # scipy.special takes 0.1 s to import: not at every command's start

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


@dataclass(frozen=True)
class ReplayedLog:
    """What one replayed log gave the learner: its gyro axes, its length [s], the still time accepted [s], the
    pieces rejected (beyond the bound or as outliers) and the temperature range of the log [degC]."""

    source: str
    gyro_axes: tuple[str, ...]
    duration_s: float
    still_s: float
    rejected: int
    temperature_min_degc: float
    temperature_max_degc: float


__all__ = [
    "GAP_PERIODS",
    "GYRO_AXES",
    "LEARNER_FORMAT",
    "LEARNER_SCHEMA_VERSION",
    "LEVEL_GROWTH",
    "LearnerSettings",
    "LearnerStatus",
    "ReplayedLog",
    "MIN_OUTLIER_DOF",
    "MIN_SESSION_POINTS",
    "MIN_STEPS",
    "MIN_TILT_G",
    "PIECE_SPREAD_WEIGHT",
    "POINTS_PER_TILT",
    "POOL_PIECES",
    "T_REF_DEGC",
    "T_SCALE_DEGC",
    "chi2_quantile",
    "MAD_TO_SIGMA",
    "RIDGE",
]
