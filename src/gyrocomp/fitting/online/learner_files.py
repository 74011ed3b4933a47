"""The online learner as files: its whole state as JSON (written and read back checked, with its lineage) and its
learned model as a model file (:class:`~gyrocomp.calibration.Calibration`); a part of
:class:`~gyrocomp.fitting.online.calibrator.OnlineCalibrator`, which reads the learner's arrays kept here."""

from __future__ import annotations

import json
import math
import os
import uuid
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from ...calibration import AxisCalibration, Calibration
from ... import jsontext
from ...errors import InputError, NotFittedError
from ...io.atomic import folder_lock, write_text_atomic
from ..provenance import provenance
from ...curves.polynomial import PolynomialCurve
from .state import record_to_dict, restore_learner, check_state_target
from .settings import (
    GYRO_AXES,
    LEARNER_FORMAT,
    LEARNER_SCHEMA_VERSION,
    LINEAGE_KEPT,
    ReplayedLog,
    T_REF_DEGC,
    T_SCALE_DEGC,
)


class LearnerFiles:
    """The learner's model file and state file (:meth:`to_calibration`, :meth:`to_dict`, :meth:`from_dict`,
    :meth:`save`, :meth:`load`); :class:`~gyrocomp.fitting.online.calibrator.OnlineCalibrator` is one."""

    def to_calibration(
        self,
        *,
        model: str = "online",
        require_curve: bool = True,
        axes: Iterable[str] = GYRO_AXES,
        contributions: Iterable[ReplayedLog] = (),
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
            raise NotFittedError(
                "the learner has no model yet: it has seen no still piece long enough "
                f"({self.settings.min_still_s:g} s) in {self._session} log(s)"
            )
        if require_curve and self._degree == 0:
            used = self._pt_session > 0
            low, high = float(self._pt_t[used, 0].min()), float(self._pt_t[used, 0].max())
            raise InputError(
                f"the still data of {self._session} log(s) cover {low:.1f}..{high:.1f} degC; a "
                f"temperature model needs at least {self.settings.min_span_degc:g} degC of them (the learner's "
                "min_span_degc): learn from logs whose still moments cover a wider temperature range"
            )
        out = {name: self._axis_calibration(j) for j, name in enumerate(GYRO_AXES) if name in axes}
        status = self.status
        report = {
            "method": "online learner",
            "sessions": status.sessions,
            "points": status.points,
            "still_s": status.still_s,
            "degree": self._degree,
            "rejected": status.rejected_bound + status.rejected_outliers,
            "settings": self.settings.to_dict(),
        }
        origin = provenance([])
        origin["inputs"] = [
            {
                "file": Path(c.source).name,
                "duration_s": c.duration_s,
                "still_s": c.still_s,
                "rejected_pieces": c.rejected,
            }
            for c in contributions
        ]
        return Calibration(axes=out, model=model, provenance=origin, fit_report=report)

    def _axis_calibration(self, j: int) -> AxisCalibration:
        """Gyro axis ``j``'s learned model: its curve (continued along its tangent past the range seen), lag,
        g-sensitivity [deg/s/g] and the sessions' constants [deg/s]."""
        curve = None
        if self._degree > 0:
            low, high = self._t_range
            coefficients = tuple(float(c) for c in self._coef[j, : self._degree])
            curve = PolynomialCurve(coefficients, T_REF_DEGC, T_SCALE_DEGC, low, high, extrapolation="linear")
        g = tuple(float(v) for v in self._g[j]) if self._tilted.any() else None
        return AxisCalibration(
            temperature=curve,
            g_sensitivity_dps_per_g=g,
            lag_time_constant_s=self.lag_time_constant_s,
            turn_on_biases=tuple(float(c) for c in self._constants[:, j]),
        )

    # ---------------------------------------------------------------- state as JSON
    def to_dict(self) -> dict[str, Any]:
        """The whole state (a learner loaded from it continues exactly where this one is)."""
        return {
            "format": LEARNER_FORMAT,
            "schema_version": LEARNER_SCHEMA_VERSION,
            "settings": self.settings.to_dict(),
            "stream": self._stream_state(),
            "noise": {
                "var_ring": self._var_ring.tolist(),
                "var_count": self._var_count.tolist(),
                "ring_pos": self._ring_pos.tolist(),
                "step_ring": self._step_ring.tolist(),
                "step_count": self._step_count.tolist(),
                "step_pos": self._step_pos.tolist(),
                "level": [None if math.isnan(v) else float(v) for v in self._level],
            },
            "piece": {
                "run_s": self._run_s,
                "sums": self._piece.tolist(),
                "bin": self._piece_bin,
                "pool": [
                    {
                        "bin": b,
                        "bias_dps": list(map(float, bias)),
                        "accel_g": list(map(float, accel)),
                        "temperature_degc": list(map(float, temps)),
                        "still_s": float(sec),
                    }
                    for b, bias, accel, temps, sec in self._pool
                ],
            },
            "points": {
                "bias_dps": self._pt_bias.tolist(),
                "temperature_degc": self._pt_t.tolist(),
                "accel_g": self._pt_accel.tolist(),
                "still_s": self._pt_s.tolist(),
                "clock_s": self._pt_clock.tolist(),
                "session": self._pt_session.tolist(),
                "bin": self._pt_bin.tolist(),
            },
            "model": self._model_state(),
            "counts": dict(self._counts),
            "lineage": list(self._lineage),
        }

    @classmethod
    def from_dict(cls, d: Any, source: str = "<dict>") -> "LearnerFiles":
        """A learner from :meth:`to_dict`'s output, every field checked."""
        if not isinstance(d, dict) or d.get("format") != LEARNER_FORMAT:
            raise InputError(f'{source}: not a gyrocomp learner state (no "format": "{LEARNER_FORMAT}")')
        if d.get("schema_version") != LEARNER_SCHEMA_VERSION:
            raise InputError(
                f"{source}: learner state schema {d.get('schema_version')!r}; this gyrocomp reads "
                f"{LEARNER_SCHEMA_VERSION}"
            )
        try:
            return restore_learner(cls, d)
        except InputError as exc:
            raise InputError(f"{source}: {exc}") from None
        except (KeyError, TypeError, ValueError, IndexError) as exc:
            raise InputError(f"{source}: malformed learner state ({type(exc).__name__}: {exc})") from None

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), allow_nan=False) + "\n"

    @property
    def state_id(self) -> str | None:
        """The id of the saved state this learner is (loaded from, or last saved as); None before any save."""
        return self._lineage[-1] if self._lineage else None

    def new_revision(self) -> str:
        """Give the state about to be saved an id of its own, the one it goes on from kept among its ancestors
        (the last :data:`LINEAGE_KEPT`); returns the new id."""
        self._lineage = (*self._lineage, uuid.uuid4().hex)[-LINEAGE_KEPT:]
        return self._lineage[-1]

    def check_state_target(self, path: str | os.PathLike) -> None:
        """Refuse to save over ``path`` when it holds a learner state this one does not go on from
        (:func:`~gyrocomp.fitting.online.state.check_state_target`); call it under
        :func:`gyrocomp.io.atomic.folder_lock` with the write."""
        check_state_target(path, self._lineage)

    def save(self, path: str | os.PathLike) -> None:
        """Write the state as JSON, atomically, as a new revision; refused (:meth:`check_state_target`) where
        ``path`` holds a state this one does not go on from."""
        with folder_lock(path):
            self.check_state_target(path)
            self.new_revision()
            write_text_atomic(path, self.to_json())

    @classmethod
    def load(cls, path: str | os.PathLike) -> "LearnerFiles":
        path = Path(path)
        try:
            text = path.read_text(encoding="utf-8")
        except FileNotFoundError:
            raise InputError(f"{path}: no such learner state file") from None
        except (OSError, UnicodeDecodeError) as exc:
            raise InputError(f"{path}: cannot read the learner state ({type(exc).__name__})") from None
        return cls.from_dict(jsontext.loads(text, str(path), "learner state"), str(path))

    def _stream_state(self) -> dict[str, Any]:
        """The stream part of the state: the session, the partial block, the lag and dequantizer states."""
        return {
            "session": self._session,
            "accel": self._accel,
            "buffer": self._buffer[: self._fill].tolist(),
            "last_t": self._last_t,
            "t0": self._t0,
            "base_clock": self._base_clock,
            "clock": self._clock,
            "broken": self._broken,
            "lag_state_degc": self._lag_state.tolist(),
            "lag_t": self._lag_t,
            "dequantizer": dict(self._dq),
            "recent": [record_to_dict(r) for r in self._recent],
        }

    def _model_state(self) -> dict[str, Any]:
        """The model part of the state: the fitted curve, g-sensitivity, constants and the last saved model."""
        return {
            "degree": self._degree,
            "coef": self._coef.tolist(),
            "g_dps_per_g": self._g.tolist(),
            "tilted": self._tilted.tolist(),
            "sessions": self._sessions.tolist(),
            "constants_dps": self._constants.tolist(),
            "rms_dps": self._rms.tolist(),
            "t_range_degc": list(self._t_range),
            "should_save": self._should_save,
            "lag_index": self._lag_index,
            "dof": self._dof,
            "lower": self._lower.tolist(),
            "piece_var": [None if math.isnan(v) else float(v) for v in self._piece_var],
            "scale2": self._scale2.tolist(),
            "saved": None
            if self._saved is None
            else {
                "degree": self._saved["degree"],
                "coef": self._saved["coef"].tolist(),
                "t_range": list(self._saved["t_range"]),
                "constant": self._saved["constant"].tolist(),
            },
        }


__all__ = ["LearnerFiles"]
