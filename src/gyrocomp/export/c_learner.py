"""The online learner as dependency-free C99: ``gyrocomp_learn.h`` and ``gyrocomp_learn.c``.

Interface (the state ``gyrocomp_learner`` is defined in the header, so callers allocate it; its size is fixed by
the settings baked in; no dynamic memory)::

    void gyrocomp_learn_init(gyrocomp_learner *s, double rate_hz);
    void gyrocomp_learn_start_session(gyrocomp_learner *s);   /* a new power-on */
    void gyrocomp_learn_end_session(gyrocomp_learner *s);     /* a log ends */
    int  gyrocomp_learn_step(gyrocomp_learner *s, double t, const double gyro[3], const double accel[3],
                             double temperature);
    int  gyrocomp_learn_bias(const gyrocomp_learner *s, const double accel[3], double out[3]);
    void gyrocomp_learn_mark_saved(gyrocomp_learner *s);

Units: t [s], gyro [deg/s], accel [g] (NULL: none), temperature [degC]. ``gyrocomp_learn_step`` returns 1 when
the model was refitted, 0 otherwise, and -1 for a sample it refused (time not increasing, or accel given in some
steps of a session and not others); a sample with a non-finite value breaks the stream as in Python.
``gyrocomp_learn_bias`` writes the learned bias [deg/s] at the current (lagged) temperature and ``accel`` (NULL:
no g-sensitivity) with this session's constant (or the mean of the sessions' before the first piece of this one)
and returns 0, or -1 while there is no model. ``s->should_save`` says the model changed enough to be stored.

Scratch arrays are static (kept off a small firmware stack), so one learner steps at a time (not reentrant).
The code does what :class:`gyrocomp.fitting.online.OnlineCalibrator` does, in the same order of operations (the
tests feed both the same samples and compare the models to 1e-9).
"""

from __future__ import annotations

from importlib.resources import files

from ..c_literals import c_number
from ..fitting.online import (
    GAP_PERIODS,
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
)
from ..fitting.online.settings import MAD_TO_SIGMA, RIDGE
from ..motion.stillness import MAX_ACCEL_NOISE_DENSITY, MAX_GYRO_NOISE_DENSITY, MIN_BLOCK_SAMPLES


#: the learner's C, with @NAME@ where a setting or a constant goes (real C files beside this module)
TEMPLATES = files(__package__) / "templates"


def template_values(settings: LearnerSettings | None = None) -> dict[str, str]:
    """What goes where the templates say ``@NAME@``: the settings (the defaults at 100 Hz when None) and the
    Python learner's own constants, so that the two learners share one set of numbers (a test checks that the
    templates ask for exactly these names)."""
    s = settings or LearnerSettings(rate_hz=100.0)
    z = s.z_values()
    return {
        "LAGS": str(len(s.lag_candidates_s)),
        "HISTORY": str(s.history_blocks),
        "POINTS": str(s.max_points),
        "SESSIONS": str(s.max_sessions),
        "POOL": str(POOL_PIECES),
        "LAG_VALUES": "{" + ", ".join(c_number(v) for v in s.lag_candidates_s) + "}",
        "BLOCK_S": c_number(s.block_s),
        "MIN_STILL_S": c_number(s.min_still_s),
        "PIECE_S": c_number(s.piece_s),
        "NOISE_QUANTILE": c_number(s.noise_quantile),
        "Z_NOISE": c_number(z["noise"]),
        "Z_VAR3": c_number(z["variance3"]),
        "Z_VAR6": c_number(z["variance6"]),
        "Z_STEP3": c_number(z["step3"]),
        "Z_STEP6": c_number(z["step6"]),
        "BIN_WIDTH": c_number(s.bin_width_degc),
        "T_LOW": c_number(s.t_low_degc),
        "BINS": str(s.bins),
        "DEGREE": str(s.degree),
        "MIN_BLOCK": str(MIN_BLOCK_SAMPLES),
        "MIN_STEPS": str(MIN_STEPS),
        "PER_TILT": str(POINTS_PER_TILT),
        "MIN_DOF": str(MIN_OUTLIER_DOF),
        "MIN_POINTS": str(MIN_SESSION_POINTS),
        "CUBIC_SPAN": c_number(s.cubic_span_degc),
        "MIN_SPAN": c_number(s.min_span_degc),
        "HALF_LIFE_H": c_number(s.half_life_h),
        "STALE_H": c_number(s.stale_h),
        "MAX_BIAS": c_number(s.max_bias_dps),
        "OUTLIER_DPS": c_number(s.outlier_dps),
        "OUTLIER_SIGMAS": c_number(s.outlier_sigmas),
        "MAX_TEMPCO": c_number(s.max_tempco_dps_per_degc),
        "SAVE_CHANGE": c_number(s.save_change_dps),
        "GAP_PERIODS": c_number(GAP_PERIODS),
        "LEVEL_GROWTH": c_number(LEVEL_GROWTH),
        "MAD": c_number(MAD_TO_SIGMA),
        "MIN_TILT": c_number(MIN_TILT_G),
        "PIECE_WEIGHT": c_number(PIECE_SPREAD_WEIGHT),
        "RIDGE": c_number(RIDGE),
        "T_REF": c_number(T_REF_DEGC),
        "T_SCALE": c_number(T_SCALE_DEGC),
        "CEILING": "{"
        + ", ".join([c_number(MAX_GYRO_NOISE_DENSITY**2)] * 3 + [c_number(MAX_ACCEL_NOISE_DENSITY**2)] * 3)
        + "}",
    }


def learner_c_sources(settings: LearnerSettings | None = None) -> dict[str, str]:
    """``{"gyrocomp_learn.h": ..., "gyrocomp_learn.c": ...}``: the online learner with ``settings`` baked in (their
    ``rate_hz`` is not: ``gyrocomp_learn_init`` takes the rate)."""
    values = template_values(settings)
    header = (TEMPLATES / "gyrocomp_learn.h.in").read_text(encoding="utf-8")
    source = (TEMPLATES / "gyrocomp_learn.c.in").read_text(encoding="utf-8")
    for key, value in values.items():
        header = header.replace(f"@{key}@", value)
        source = source.replace(f"@{key}@", value)
    return {"gyrocomp_learn.h": header, "gyrocomp_learn.c": source}


__all__ = ["TEMPLATES", "learner_c_sources", "template_values"]
