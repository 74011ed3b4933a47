"""The online learner's state file: every field written, and read back checked against bounds, so that a forged
or damaged state is refused naming the field."""

from __future__ import annotations

import json
import os
import re
from pathlib import Path
from typing import Any


import numpy as np

from ...errors import InputError
from ...measures.plausibility import TEMPERATURE_RANGE_DEGC
from .settings import LEARNER_FORMAT, LINEAGE_KEPT, POOL_PIECES, LearnerSettings


def check_state_target(path: str | os.PathLike, lineage: tuple[str, ...]) -> None:
    """Refuse to save a learner whose lineage (the ids of the saved states it goes on from, its own last) is
    ``lineage`` over ``path`` when that file holds a learner state not among them: another learner resumed the same
    state and saved there first, or it was started afresh; replacing it would lose what that learner learned. A
    file that is no learner state, or one the learner descends from, may be replaced. Call it under
    :func:`gyrocomp.io.atomic.folder_lock` with the write, so that no other learner saves between the check and the
    write."""
    try:
        other = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError):  # missing, unreadable or no JSON: an ordinary output
        return
    if not isinstance(other, dict) or other.get("format") != LEARNER_FORMAT:
        return
    theirs = other.get("lineage")
    theirs = theirs[-1] if isinstance(theirs, list) and theirs and isinstance(theirs[-1], str) else None
    if theirs is None or theirs not in lineage:
        raise InputError(
            f"{path}: holds another learner's state, one this learner does not go on from (another "
            "learner resumed the same state and saved here first, or it started afresh); nothing "
            "written, so that neither loses what it learned: resume from that state, or save to "
            "another file"
        )


def record_to_dict(record: dict) -> dict:
    """A learner's per-block record as JSON values (flags as booleans, mean and temperature as lists)."""
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


def _finite_array(
    values, shape: tuple | None, name: str, *, allow_nan: bool = False, bound: float = STATE_MAGNITUDE_MAX
) -> np.ndarray:
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
        raise InputError(
            f"{name}: holds {float(finite[np.argmax(np.abs(finite))]):.3g}, beyond the {bound:g} a learner state holds"
        )
    return out


def _whole_array(values, name: str, lo: int, hi: int) -> np.ndarray:
    """Whole numbers in lo..hi, checked before numpy sees them (a 30-digit integer overflows its int64)."""
    flat = values if isinstance(values, list) else [values]
    if any(isinstance(v, bool) or not isinstance(v, int) or not lo <= v <= hi for v in flat):
        raise InputError(f"{name}: whole numbers in {lo}..{hi} expected")
    return np.array(flat, dtype=np.int64)


def _scalar(value, name: str, bound: float = STATE_MAGNITUDE_MAX) -> float:
    return float(_finite_array(value, (), name, bound=bound))


def restore_learner(cls, d: dict) -> Any:
    """A learner of class ``cls`` (an :class:`~gyrocomp.fitting.online.OnlineCalibrator`: not imported here, it
    imports this module) from a checked state dict, every field bounded."""
    self = cls(LearnerSettings(**d["settings"]))
    _restore_stream(self, d["stream"], d["piece"])
    _restore_noise(self, d["noise"])
    _restore_points(self, d["points"])
    _restore_model(self, d["model"])
    counts = d["counts"]
    self._counts = {
        "still_s": float(counts["still_s"]),
        **{k: int(counts[k]) for k in ("rejected_bound", "rejected_outliers", "stale_dropped")},
    }
    lineage = d.get("lineage", [])  # absent in states written before 0.2: no ancestors known
    if (
        not isinstance(lineage, list)
        or len(lineage) > LINEAGE_KEPT
        or not all(isinstance(i, str) and re.fullmatch(r"[0-9a-f]{32}", i) for i in lineage)
    ):
        raise InputError(f"lineage: up to {LINEAGE_KEPT} state ids (32 hexadecimal digits) expected")
    self._lineage = tuple(lineage)
    return self


def _restore_stream(self, stream: dict, piece: dict) -> None:
    w = self._w
    self._session = int(_whole_array(stream["session"], "stream.session", 0, 10**9)[0])
    self._accel = None if stream["accel"] is None else bool(stream["accel"])
    buffer = _finite_array(stream["buffer"], None, "stream.buffer", allow_nan=True)
    if buffer.size % (6 + self._lags):
        raise InputError(f"stream.buffer: rows of {6 + self._lags} numbers expected")
    buffer = buffer.reshape(-1, 6 + self._lags)
    if buffer.shape[0] >= w:
        raise InputError(f"stream.buffer: {buffer.shape[0]} samples; a block holds {w}")
    self._fill = buffer.shape[0]
    self._buffer[: self._fill] = buffer
    self._last_t = None if stream["last_t"] is None else _scalar(stream["last_t"], "stream.last_t")
    self._t0, self._base_clock, self._clock = (_scalar(stream[k], f"stream.{k}") for k in ("t0", "base_clock", "clock"))
    self._broken = bool(stream["broken"])
    self._lag_state = _finite_array(
        stream["lag_state_degc"], (self._lags,), "stream.lag_state_degc", bound=STATE_TEMPERATURE_MAX_DEGC
    )
    self._lag_t = None if stream["lag_t"] is None else _scalar(stream["lag_t"], "stream.lag_t")
    dq = stream["dequantizer"]
    self._dq = {
        "previous": None if dq["previous"] is None else _scalar(dq["previous"], "stream.dequantizer"),
        "crossing": None if dq["crossing"] is None else _scalar(dq["crossing"], "stream.dequantizer"),
        **{k: _scalar(dq[k], "stream.dequantizer") for k in ("time", "rate", "half")},
    }
    self._recent = []
    for rec in stream["recent"][-3:]:
        restored = {k: bool(rec[k]) for k in ("still", "linked")}
        if "mean" in rec:
            restored.update(
                mean=_finite_array(rec["mean"], (6,), "stream.recent.mean"),
                temperature=_finite_array(
                    rec["temperature"], (self._lags,), "stream.recent.temperature", bound=STATE_TEMPERATURE_MAX_DEGC
                ),
                quiet=bool(rec["quiet"]),
                agree=bool(rec["agree"]),
            )
        self._recent.append(restored)
    self._run_s = _scalar(piece["run_s"], "piece.run_s")
    self._piece = _finite_array(piece["sums"], (7 + self._lags,), "piece.sums")
    bins = int(2 * STATE_TEMPERATURE_MAX_DEGC / self.settings.bin_width_degc) + 1
    self._piece_bin = int(_whole_array(piece["bin"], "piece.bin", -bins, bins)[0])
    self._pool = [
        (
            int(_whole_array(p["bin"], "piece.pool.bin", -bins, bins)[0]),
            _finite_array(p["bias_dps"], (3,), "piece.pool.bias_dps"),
            _finite_array(p["accel_g"], (3,), "piece.pool.accel_g"),
            _finite_array(
                p["temperature_degc"], (self._lags,), "piece.pool.temperature_degc", bound=STATE_TEMPERATURE_MAX_DEGC
            ),
            _scalar(p["still_s"], "piece.pool.still_s"),
        )
        for p in piece["pool"][-POOL_PIECES:]
    ]


def _restore_noise(self, noise: dict) -> None:
    r = self.settings.history_blocks
    self._var_ring = _finite_array(noise["var_ring"], (r, 6), "noise.var_ring")
    self._step_ring = _finite_array(noise["step_ring"], (r, 6), "noise.step_ring")
    for name in ("var_count", "ring_pos", "step_count", "step_pos"):
        values = _whole_array(noise[name], f"noise.{name}", 0, r)
        if values.shape != (6,):
            raise InputError(f"noise.{name}: six whole numbers in 0..{r}")
        setattr(self, f"_{name}", values)
    self._level = _finite_array(
        [np.nan if v is None else v for v in noise["level"]], (len(noise["level"]),), "noise.level", allow_nan=True
    )


def _restore_points(self, points: dict) -> None:
    n = self.settings.max_points
    self._pt_bias = _finite_array(points["bias_dps"], (n, 3), "points.bias_dps")
    self._pt_t = _finite_array(
        points["temperature_degc"], (n, self._lags), "points.temperature_degc", bound=STATE_TEMPERATURE_MAX_DEGC
    )
    self._pt_accel = _finite_array(points["accel_g"], (n, 3), "points.accel_g")
    self._pt_s = _finite_array(points["still_s"], (n,), "points.still_s")
    self._pt_clock = _finite_array(points["clock_s"], (n,), "points.clock_s")
    self._pt_session = _whole_array(points["session"], "points.session", 0, self._session)
    bins = int(2 * STATE_TEMPERATURE_MAX_DEGC / self.settings.bin_width_degc) + 1
    self._pt_bin = _whole_array(points["bin"], "points.bin", -bins, bins).reshape(n)
    if self._pt_session.shape != (n,):
        raise InputError(f"points.session: {n} session numbers in 0..{self._session}")


def _restore_model(self, model: dict) -> None:
    self._degree = int(model["degree"])
    if not -1 <= self._degree <= self.settings.degree:
        raise InputError(f"model.degree: {self._degree} outside -1..{self.settings.degree}")
    self._coef = _finite_array(model["coef"], (3, 3), "model.coef")
    self._g = _finite_array(model["g_dps_per_g"], (3, 3), "model.g_dps_per_g")
    self._tilted = np.array([bool(v) for v in model["tilted"]], dtype=bool).reshape(3)
    self._sessions = _whole_array(model["sessions"], "model.sessions", 0, self._session).reshape(-1)
    constants = model["constants_dps"]
    self._constants = _finite_array(
        constants if constants else np.zeros((0, 3)), (self._sessions.size, 3), "model.constants_dps"
    )
    self._rms = _finite_array(model["rms_dps"], (3,), "model.rms_dps")
    self._t_range = tuple(
        _finite_array(model["t_range_degc"], (2,), "model.t_range_degc", bound=STATE_TEMPERATURE_MAX_DEGC)
    )
    self._should_save = bool(model["should_save"])
    self._lag_index = int(model["lag_index"])
    self._dof = int(model["dof"])
    self._piece_var = _finite_array(
        [np.nan if v is None else v for v in model["piece_var"]], (3,), "model.piece_var", allow_nan=True
    )
    if not 0 <= self._lag_index < self._lags:
        raise InputError(f"model.lag_index: {self._lag_index} outside 0..{self._lags - 1}")
    p = 0 if self._degree < 0 else self._degree + int(self._tilted.sum()) + self._sessions.size
    self._lower = _finite_array(model["lower"], (p, p), "model.lower") if p else np.zeros((0, 0))
    self._scale2 = _finite_array(model["scale2"], (3,), "model.scale2")
    saved = model["saved"]
    self._saved = (
        None
        if saved is None
        else {
            "degree": int(saved["degree"]),
            "coef": _finite_array(saved["coef"], (3, 3), "model.saved.coef"),
            "t_range": tuple(float(v) for v in saved["t_range"]),
            "constant": _finite_array(saved["constant"], (3,), "model.saved.constant"),
        }
    )


__all__ = [
    "STATE_MAGNITUDE_MAX",
    "STATE_TEMPERATURE_MAX_DEGC",
    "check_state_target",
    "record_to_dict",
    "restore_learner",
]
