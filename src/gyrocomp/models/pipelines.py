"""From recordings to a :class:`Calibration`: the fit entry point every caller uses."""

from __future__ import annotations

import datetime as _dt
from pathlib import Path


from ..calibration import AxisCalibration, Calibration
from ..errors import InputError
from ..recording import Recording
from .temperature import PolynomialTemperatureModel


def _provenance(recordings: list[Recording]) -> dict:
    from .. import __version__
    from ..io import file_sha256

    inputs = []
    for rec in recordings:
        entry = {"file": Path(rec.source).name, "rows": rec.n_samples, "duration_s": rec.duration_s,
                 "rate_hz": rec.rate_hz}
        path = rec.metadata.get("path")
        if path and Path(path).is_file():
            entry["sha256"] = file_sha256(path)
        inputs.append(entry)
    return {
        "gyrocomp_version": __version__,
        "created_utc": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "inputs": inputs,
    }


def fit_calibration(recordings: list[Recording] | Recording, *, temperature: int | str | None = "auto",
                    bin_width_degc: float | None = None) -> Calibration:
    """Fit a compensation on calibration runs (each one power-on, the gyro at rest).

    Parameters
    ----------
    recordings : list of Recording
        Calibration runs; each gets its own turn-on constant, the temperature shape is shared.
    temperature : "auto", int or None
        Polynomial order of the temperature model: ``"auto"`` (cross-validated), 0..5, or None
        for no temperature model (each run's constant only).
    bin_width_degc : float, optional
        Temperature bin width for the fit [degC].
    """
    if isinstance(recordings, Recording):
        recordings = [recordings]
    recordings = list(recordings)
    if not recordings:
        raise InputError("fit: give at least one calibration run")
    if temperature is None:
        axes = {}
        for axis in recordings[0].gyro_axes:
            consts = tuple(float(rec.gyro(axis).mean()) for rec in recordings)
            axes[axis] = AxisCalibration(None, consts)
        return Calibration(axes=axes, model="none", provenance=_provenance(recordings),
                           fit_report={"temperature": None})
    for rec in recordings:
        if rec.temperature_degc is None:
            raise InputError(
                f"{rec.source}: no temperature column; a temperature model needs one "
                "(map it with --columns temperature=NAME, or fit with --temperature none)"
            )
    model = PolynomialTemperatureModel(order=temperature, bin_width_degc=bin_width_degc).fit(recordings)
    axes = {}
    report = {"temperature": "polynomial", "order_selection": model.selection_, "axes": {}}
    for axis, curve in model.curves_.items():
        axes[axis] = AxisCalibration(curve, tuple(float(c) for c in model.turn_on_biases_dps_[axis]),
                                     recordings[0].temperature_column_for(axis))
        report["axes"][axis] = {
            "order": curve.order,
            "scores": {str(p): float(s) for p, s in model.scores_[axis].items()},
            "fit_rms_dps": model.fit_rms_dps_[axis],
            "t_min_degc": curve.t_min_degc,
            "t_max_degc": curve.t_max_degc,
        }
    orders = sorted({c.order for c in model.curves_.values()})
    name = f"poly:{orders[0]}" if len(orders) == 1 else "poly:" + "/".join(map(str, orders))
    if temperature == "auto":
        name += " (auto)"
    return Calibration(axes=axes, model=name, provenance=_provenance(recordings), fit_report=report)


__all__ = ["fit_calibration"]
