"""Allan deviation of gyro (rate) or angle (phase) data, with confidence intervals and noise types: the estimators
(:mod:`.estimators`), the noise identification (:mod:`.noise_id`), the intervals (:mod:`.intervals`), the IEEE Std
952 terms (:mod:`.terms`), joined in :mod:`.deviation`."""

from __future__ import annotations

from .deviation import (
    AccelNoise, allan_deviation, allan_deviation_segments, AllanKind, AllanMinimum, AllanResult, averaging_factors,
    b1_expected, BIAS_INSTABILITY_FACTOR, confidence_interval, DataType, DEFAULT_STOP_RATIO, degrees_of_freedom,
    edf_greenhall, edf_totdev, GyroNoise, identify_noise, identify_noise_b1, KINDS, MODEL_UNCERTAINTY,
    NOISE_ID_MAX_POINTS, NOISE_ID_MIN_POINTS, noise_parameters, noise_terms, noise_types, NoiseIdentification,
    NoiseTerms, ONE_SIGMA, phase_from_chunks, PhaseAccumulator, READOFF_SLOPE_TOLERANCE, rn_expected, STOP_RATIO,
    TauGrid, term_count, to_phase
)

__all__ = [
    "AccelNoise", "AllanKind", "AllanMinimum", "AllanResult", "BIAS_INSTABILITY_FACTOR", "DEFAULT_STOP_RATIO",
    "DataType", "GyroNoise", "KINDS", "MODEL_UNCERTAINTY", "NOISE_ID_MAX_POINTS", "NOISE_ID_MIN_POINTS",
    "NoiseIdentification", "NoiseTerms", "ONE_SIGMA", "PhaseAccumulator", "READOFF_SLOPE_TOLERANCE",
    "STOP_RATIO", "TauGrid", "allan_deviation", "allan_deviation_segments", "averaging_factors", "b1_expected",
    "confidence_interval", "degrees_of_freedom", "edf_greenhall", "edf_totdev", "identify_noise",
    "identify_noise_b1", "noise_parameters", "noise_terms", "noise_types", "phase_from_chunks", "rn_expected",
    "term_count", "to_phase"
]
