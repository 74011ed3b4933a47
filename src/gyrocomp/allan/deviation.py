"""Allan deviation of gyro (rate) or angle (phase) data, with confidence intervals and noise types.

The estimators (OADEV, ADEV, MDEV, TDEV, HDEV, OHDEV, TOTDEV; IEEE Std 952-1997 Annex C, NIST SP 1065)
live in :mod:`.estimators`, the power-law noise identification (lag-1 autocorrelation, B1 ratio and R(n),
as Stable32) in :mod:`.noise_id`, the equivalent degrees of freedom and chi-squared intervals (Greenhall and
Riley 2003) in :mod:`.intervals`, and the IEEE Std 952 noise terms read from a curve in :mod:`.terms`.
This module joins them: :func:`allan_deviation` and :func:`allan_deviation_segments`.

``phase_out`` lets the phase itself live in a memory-mapped file for data larger than memory.
"""

from __future__ import annotations

import math
from typing import Iterable, get_args

import numpy as np

from ..threads import single_threaded_blas
from ..errors import InputError
from .estimators import (
    DEFAULT_STOP_RATIO,
    KINDS,
    AllanKind,
    DataType,
    TauGrid,
    ONE_SIGMA,
    STOP_RATIO,
    AllanMinimum,
    AllanResult,
    deviations_from_sums,
    variance_sums,
    averaging_factors,
    phase_from_chunks,
    term_count,
    to_phase,
)
from .streaming import PhaseAccumulator
from .intervals import confidence_interval, degrees_of_freedom, edf_greenhall, edf_totdev
from .noise_id import (
    NOISE_ID_MAX_POINTS,
    NOISE_ID_MIN_POINTS,
    NoiseIdentification,
    b1_expected,
    identify_noise,
    identify_noise_b1,
    noise_types,
    rn_expected,
)
from .terms import (
    BIAS_INSTABILITY_FACTOR,
    MODEL_UNCERTAINTY,
    READOFF_SLOPE_TOLERANCE,
    AccelNoise,
    GyroNoise,
    NoiseTerms,
    noise_parameters,
    noise_terms,
)

__all__ = [
    "AccelNoise",
    "AllanKind",
    "AllanMinimum",
    "AllanResult",
    "DataType",
    "TauGrid",
    "BIAS_INSTABILITY_FACTOR",
    "DEFAULT_STOP_RATIO",
    "GyroNoise",
    "KINDS",
    "MODEL_UNCERTAINTY",
    "NOISE_ID_MAX_POINTS",
    "NOISE_ID_MIN_POINTS",
    "NoiseIdentification",
    "NoiseTerms",
    "ONE_SIGMA",
    "PhaseAccumulator",
    "READOFF_SLOPE_TOLERANCE",
    "STOP_RATIO",
    "allan_deviation",
    "allan_deviation_segments",
    "averaging_factors",
    "b1_expected",
    "confidence_interval",
    "degrees_of_freedom",
    "edf_greenhall",
    "edf_totdev",
    "identify_noise",
    "identify_noise_b1",
    "noise_parameters",
    "noise_terms",
    "noise_types",
    "phase_from_chunks",
    "rn_expected",
    "term_count",
    "to_phase",
]


def _check(kind: str, rate_hz: float, data_type: str) -> None:
    if kind not in KINDS:
        raise InputError(f"kind: unknown Allan estimator {kind!r}; use one of {', '.join(KINDS)}")
    if not rate_hz > 0:
        raise InputError(f"rate_hz: must be positive, got {rate_hz}")
    if data_type not in get_args(DataType):
        raise InputError(f"data_type: {data_type!r}; use 'rate' or 'phase'")


def _as_phase(data, rate_hz: float, data_type: str, phase_out) -> tuple[np.ndarray, float]:
    """The phase and the factor it carries: rate data is summed without the division by rate_hz (one
    pass fewer over the data; the deviations do not depend on it), so its phase is in [unit*samples]."""
    if data_type == "rate":
        if np.ndim(data) != 1:
            raise InputError("data: need a one-dimensional series")
        phase, scale = to_phase(data, 1.0, out=phase_out), rate_hz
    else:
        phase, scale = (data if isinstance(data, np.ndarray) else np.asarray(data, dtype=float)), 1.0
    if phase.ndim != 1 or phase.size < 3:
        raise InputError("data: need a one-dimensional series of at least 3 phase points")
    return phase, scale


@single_threaded_blas
def allan_deviation(
    data,
    rate_hz: float,
    *,
    kind: AllanKind = "oadev",
    taus: TauGrid | np.ndarray = "octave",
    data_type: DataType = "rate",
    confidence: float | None = ONE_SIGMA,
    phase_out: np.ndarray | None = None,
    noise_alpha=None,
) -> AllanResult:
    """Allan deviation of ``data`` sampled at ``rate_hz``, with confidence intervals.

    Parameters
    ----------
    data : array (n,)
        Rate samples (e.g. [deg/s]) or, with ``data_type="phase"``, integrated angle samples (e.g. [deg]).
        A ``np.memmap`` is read in blocks.
    rate_hz : float
        Sample rate [Hz].
    kind : {"oadev", "adev", "mdev", "tdev", "hdev", "ohdev", "totdev"}
        Estimator: overlapping Allan (default), Allan, modified Allan, time deviation (tau/sqrt(3) MDEV,
        in [unit*s]), Hadamard, overlapping Hadamard, total deviation (NIST SP 1065, section 5.2).
    taus : {"octave", "decade", "all"} or array
        Averaging times: m = 1, 2, 4, ...; m = 1, 2, 4, 10, 20, 40, ...; every m; or taus [s].
    data_type : {"rate", "phase"}
    confidence : float or None
        Two-sided confidence of ``ci_low``/``ci_high`` (default one sigma, 0.683). None skips the noise
        identification and the intervals (``ci_low``, ``ci_high``, ``alpha``, ``edf`` are NaN).
    phase_out : array (n+1,), optional
        Where to put the integrated rate data, e.g. a memory-mapped file for data larger than memory; by
        default a new array. It receives the running sum of the rate minus its mean [unit*samples], i.e.
        the phase times ``rate_hz``.
    noise_alpha : int or sequence of int, optional
        The power-law noise type of the intervals (alpha of S_y(f) ~ f^alpha: 2 white PM, 1 flicker PM, 0 white
        FM, -1 flicker FM, -2 random walk FM), one for every tau or one per tau, instead of identifying it from
        the data (lag-1 autocorrelation, B1 ratio and R(n)); as Stable32 lets its user choose the noise type.
    """
    _check(kind, rate_hz, data_type)
    phase, scale = _as_phase(data, rate_hz, data_type, phase_out)
    ms = averaging_factors(phase.size, taus, rate_hz, kind)
    forced = _noise_alpha(noise_alpha, len(ms))
    tau = ms / rate_hz
    counts = term_count(kind, phase.size, ms)
    deviation = deviations_from_sums(kind, variance_sums(kind, phase, ms, counts), ms, tau, counts, scale)
    alphas, methods, edf = _noise_and_edf(kind, phase, ms, confidence, forced)
    return _result(kind, tau, deviation, counts, alphas, edf, methods, confidence)


def _result(kind: str, tau, deviation, counts, alphas, edf, methods: tuple, confidence: float | None) -> AllanResult:
    """The :class:`AllanResult` of the deviations [u] at ``tau`` [s], with their intervals at ``confidence`` (the
    interval arrays of one sigma, and a NaN confidence, where it is None)."""
    low, high = confidence_interval(deviation, edf, ONE_SIGMA if confidence is None else confidence)
    return AllanResult(
        tau=tau,
        deviation=deviation,
        n=counts,
        ci_low=low,
        ci_high=high,
        alpha=alphas,
        edf=edf,
        kind=kind,
        confidence=math.nan if confidence is None else confidence,
        noise_method=methods,
    )


def _noise_and_edf(kind: str, phase: np.ndarray, ms: np.ndarray, confidence: float | None, forced) -> tuple:
    """Per averaging factor: the noise type's alpha (``forced``, or identified from ``phase``), how it was found,
    and the equivalent degrees of freedom (NaN and empty without ``confidence``)."""
    if confidence is None:
        return np.full(len(ms), np.nan), ("",) * len(ms), np.full(len(ms), np.nan)
    if forced is None:
        found = noise_types(kind, phase, ms)
        alphas, methods = found.alpha, found.method
    else:
        alphas, methods = forced, ("given",) * len(ms)
    return alphas, methods, degrees_of_freedom(kind, alphas, ms, phase.size)


def _noise_alpha(value, count: int) -> np.ndarray | None:
    """``noise_alpha`` as one alpha per tau (None: identify from the data)."""
    if value is None:
        return None
    try:
        values = np.atleast_1d(np.asarray(value, dtype=float))
    except (TypeError, ValueError):
        raise InputError(f"noise_alpha: whole numbers from -2 to 2, got {value!r}") from None
    if values.ndim != 1 or values.size not in (1, count):
        raise InputError(f"noise_alpha: one alpha, or one per tau ({count}), got {values.size}")
    if not np.all(np.isin(values, (-2, -1, 0, 1, 2))):
        raise InputError(
            f"noise_alpha: each one of 2, 1, 0, -1, -2 (white PM .. random walk FM), got {values.tolist()}"
        )
    return np.broadcast_to(values, (count,)).astype(float)


@single_threaded_blas
def allan_deviation_segments(
    segments: Iterable,
    rate_hz: float,
    *,
    kind: AllanKind = "oadev",
    taus: TauGrid | np.ndarray = "octave",
    data_type: DataType = "rate",
    confidence: float | None = ONE_SIGMA,
) -> AllanResult:
    """One deviation curve from several contiguous stretches of data separated by gaps.

    The sums of squared differences and their term counts are pooled over the stretches, so no term
    spans a gap; the degrees of freedom add. The noise type comes from the longest stretch. The named
    tau grids follow the longest stretch. TOTDEV's reflected series has no pooled form. ``confidence``
    None skips the noise identification and the intervals, as in :func:`allan_deviation`.
    """
    _check(kind, rate_hz, data_type)
    if kind == "totdev":
        raise InputError("kind: totdev cannot pool stretches separated by gaps; use oadev, or one stretch")
    shortest = 3 if data_type == "phase" else 2
    integrated = [_as_phase(s, rate_hz, data_type, None) for s in segments if len(s) >= shortest]
    if not integrated:
        raise InputError("data: no stretch has enough samples")
    phases, scale = [phase for phase, _ in integrated], integrated[0][1]
    longest = max(phases, key=len)
    ms = averaging_factors(longest.size, taus, rate_hz, kind)
    tau = ms / rate_hz
    sums, counts, edf = np.zeros(len(ms)), np.zeros(len(ms), dtype=np.int64), np.zeros(len(ms))
    found = noise_types(kind, longest, ms) if confidence is not None else None
    alphas = found.alpha if found is not None else np.full(len(ms), np.nan)
    for phase in phases:
        own = np.maximum(term_count(kind, phase.size, ms), 0)
        sums += variance_sums(kind, phase, ms, own)
        counts += own
        if confidence is not None:
            own_edf = degrees_of_freedom(kind, alphas, ms, phase.size)
            edf += np.where((own > 0) & np.isfinite(own_edf), own_edf, 0.0)
    edf = np.where(np.isnan(alphas), np.nan, edf)
    deviation = deviations_from_sums(kind, sums, ms, tau, counts, scale)
    methods = found.method if found is not None else ("",) * len(ms)
    return _result(kind, tau, deviation, counts, alphas, edf, methods, confidence)
