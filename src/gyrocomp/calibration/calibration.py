"""The frozen, versioned, JSON-serializable result of a fit; :mod:`gyrocomp.calibration.compensate` applies it.

A model file is JSON with ``"format": "gyrocomp-calibration"`` and an integer ``schema_version``.
Loading checks both, upgrades files written with an older schema, and refuses newer ones.
Nothing is ever unpickled: loading a model file cannot run code.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .. import jsontext
from ..errors import InputError
from .fit_report import FitReport
from ..io.atomic import write_text_atomic
from ..io.digest import file_sha256
from ..curves.kinds import curve_from_dict
from ..curves.protocol import TemperatureCurve
from ..curves.network import NetworkCurve
from ..curves.hysteresis import BranchCurve, HysteresisCurve, memory_curve_from_dict
from ..curves.rate import TemperatureRateTerm
from ..recording import GYRO_AXES
from .triad import TriadCalibration
from .schema import UNITS, validate_model
from ..units import AxisUnit, check_axis_unit, in_unit, require_unit

FORMAT_NAME = "gyrocomp-calibration"
SCHEMA_VERSION = 7


def _refuse_later_fields(d: dict, version: int, top: tuple[str, ...] = (), per_axis: tuple[str, ...] = ()) -> None:
    """A file that says schema ``version`` but holds what a later schema added (its version edited by hand, or
    copied from another file) is refused: upgrading it would overwrite those values with the defaults."""
    found = [key for key in top if key in d]
    axes = d.get("axes") if isinstance(d.get("axes"), dict) else {}
    found += [
        f"axes.{name}.{key}" for name, ax in axes.items() if isinstance(ax, dict) for key in per_axis if key in ax
    ]
    if found:
        raise InputError(
            f"schema_version {version}: the file holds {found[0]}, which schema {version + 1} added; "
            "its schema_version was changed by hand? (write it again with gyrocomp fit)"
        )


def _upgrade_1_to_2(d: dict) -> dict:
    """Schema 2 adds thermal lag and hysteresis per axis; a schema-1 file has neither."""
    _refuse_later_fields(d, 1, (), ("lag_time_constant_s", "hysteresis"))
    d = dict(d)
    if isinstance(d.get("axes"), dict):
        d["axes"] = {
            name: {**ax, "lag_time_constant_s": 0.0, "hysteresis": None} if isinstance(ax, dict) else ax
            for name, ax in d["axes"].items()
        }
    d["schema_version"] = 2
    return d


def _upgrade_2_to_3(d: dict) -> dict:
    """Schema 3 adds the g-sensitivity per axis; a schema-2 file has none."""
    _refuse_later_fields(d, 2, (), ("g_sensitivity_dps_per_g", "g_squared_dps_per_g2"))
    d = dict(d)
    if isinstance(d.get("axes"), dict):
        d["axes"] = {
            name: {**ax, "g_sensitivity_dps_per_g": None, "g_squared_dps_per_g2": None} if isinstance(ax, dict) else ax
            for name, ax in d["axes"].items()
        }
    d["schema_version"] = 3
    return d


def _upgrade_3_to_4(d: dict) -> dict:
    """Schema 4 adds a network on the accelerations per axis (pipeline mlp>mlp-accel); schema 3 has none."""
    _refuse_later_fields(d, 3, (), ("acceleration_network",))
    d = dict(d)
    if isinstance(d.get("axes"), dict):
        d["axes"] = {
            name: {**ax, "acceleration_network": None} if isinstance(ax, dict) else ax for name, ax in d["axes"].items()
        }
    d["schema_version"] = 4
    return d


def _upgrade_4_to_5(d: dict) -> dict:
    """Schema 5 adds accelerometer temperature models; older files have none."""
    _refuse_later_fields(d, 4, ("accel_axes", "accel_reference_degc"), ())
    d = dict(d)
    d.setdefault("accel_axes", {})
    d.setdefault("accel_reference_degc", None)
    d["schema_version"] = 5
    return d


def _upgrade_5_to_6(d: dict) -> dict:
    """Schema 6 adds scale factor and misalignment of the gyro and accelerometer triads; older files have none."""
    _refuse_later_fields(d, 5, ("gyro_triad", "accel_triad"), ())
    d = dict(d)
    d.setdefault("gyro_triad", None)
    d.setdefault("accel_triad", None)
    d["schema_version"] = 6
    return d


def _upgrade_6_to_7(d: dict) -> dict:
    """Schema 7 adds a temperature-rate term per axis (:mod:`gyrocomp.curves.rate`); older files have none."""
    _refuse_later_fields(d, 6, (), ("temperature_rate",))
    d = dict(d)
    for key in ("axes", "accel_axes"):
        if isinstance(d.get(key), dict):
            d[key] = {
                name: {**ax, "temperature_rate": None} if isinstance(ax, dict) else ax for name, ax in d[key].items()
            }
    d["schema_version"] = 7
    return d


#: upgrade functions from schema version v to v + 1, applied in turn by ``load``
UPGRADES: dict[int, Callable[[dict], dict]] = {
    1: _upgrade_1_to_2,
    2: _upgrade_2_to_3,
    3: _upgrade_3_to_4,
    4: _upgrade_4_to_5,
    5: _upgrade_5_to_6,
    6: _upgrade_6_to_7,
}


def _require_finite(value: Any, where: str = "") -> None:
    """Every number under ``value`` finite (a NaN passes any bound a schema sets: it compares false), the error
    naming the field (``axes.gyro_z.temperature.coefficients_dps[0]``), in the fit report too (show formats it)."""
    if isinstance(value, dict):
        for key, item in value.items():
            _require_finite(item, f"{where}.{key}" if where else str(key))
    elif isinstance(value, list):
        for k, item in enumerate(value):
            _require_finite(item, f"{where}[{k}]")
    elif isinstance(value, float) and not math.isfinite(value):
        raise InputError(f"{where}: {value} is not a finite number")


def _check_ranges(d: dict) -> None:
    """What the schema cannot say: each curve's range in order (its minimum at or below its maximum)."""
    for section in ("axes", "accel_axes"):
        for name, ax in d[section].items():
            for key in ("temperature", "hysteresis", "acceleration_network"):
                curve = ax.get(key)
                if (
                    isinstance(curve, dict)
                    and isinstance(curve.get("t_min_degc"), (int, float))
                    and isinstance(curve.get("t_max_degc"), (int, float))
                    and curve["t_min_degc"] > curve["t_max_degc"]
                ):
                    raise InputError(
                        f"{section}.{name}.{key}: t_min_degc {curve['t_min_degc']:g} is above "
                        f"t_max_degc {curve['t_max_degc']:g}"
                    )


def _check_triads(triads: dict[str, TriadCalibration | None], axes: dict) -> None:
    gyro, accel = triads["gyro_triad"], triads["accel_triad"]
    if gyro is not None and (gyro.unit != "deg/s" or set(axes) != set(GYRO_AXES)):
        raise InputError("gyro_triad: a gyro triad in deg/s needs models of all three gyro axes")
    if accel is not None and accel.unit != "g":
        raise InputError(f"accel_triad.unit: {accel.unit!r}; the accelerometer's is 'g'")


def _floats(values, count: int, name: str):
    if values is None:
        return None
    if len(values) != count:
        raise InputError(f"{name}: {len(values)} values, expected {count}")
    return tuple(float(v) for v in values)


def _in_g(d: Any, to_g: bool) -> Any:
    """An accelerometer axis's dictionary with its ``..._dps`` keys named ``..._g`` (and back): the same
    models serve both sensors, and the file says the unit of what it holds."""
    if not isinstance(d, dict):
        return d

    def renamed(key: str) -> str:
        if to_g:
            return key[:-4] + "_g" if key.endswith("_dps") else key
        return key[:-2] + "_dps" if key.endswith("_g") and not key.endswith("_per_g") else key

    return {renamed(k): _in_g(v, to_g) for k, v in d.items()}


@dataclass(frozen=True)
class AxisCalibration:
    """Everything known about one gyro axis, or (in ``Calibration.accel_axes``, ``unit="g"``) one accelerometer
    axis. Its values (the turn-on constants, its curves' outputs) are in ``unit``; the accessors whose names
    carry a unit (``turn_on_biases_dps``, ``turn_on_biases_g``) refuse an axis of the other.

    Attributes
    ----------
    temperature : TemperatureCurve or None
        The bias shape against temperature [unit] (a :class:`gyrocomp.curves.protocol.TemperatureCurve`: a
        polynomial, a network, a lookup table, any registered curve), or None for no temperature model.
    turn_on_biases : tuple of float
        Fitted turn-on constant of each calibration run [unit].
    temperature_column : str
        The temperature channel the model reads (``temperature`` or ``temperature_x`` ...).
    lag_time_constant_s : float
        Thermal lag [s]: the polynomial and the hysteresis read the reported temperature through a
        first-order lag of this time constant; 0 for none.
    hysteresis : HysteresisCurve, BranchCurve or None
        The thermal memory on top of the polynomial: turning-point hysteresis, or heating and cooling branches
        (a memory curve of :data:`gyrocomp.curves.hysteresis.MEMORY_CURVES`).
    g_sensitivity_dps_per_g : 3 floats or None
        This axis's row of the g-sensitivity matrix G, on accel_x, accel_y, accel_z [deg/s/g].
    g_squared_dps_per_g2 : 6 floats or None
        g x g sensitivity to the products xx, yy, zz, xy, xz, yz [deg/s/g^2].
    acceleration_network : NetworkCurve or None
        A network of the three accelerations (the second stage of the ``mlp>mlp-accel`` pipeline).
    unit : {"deg/s", "g"}
        The unit of the axis's values.
    rate_term : TemperatureRateTerm or None
        A bias in the smoothed rate of change of the model temperature (:mod:`gyrocomp.curves.rate`).
    """

    temperature: TemperatureCurve | None
    turn_on_biases: tuple[float, ...]
    temperature_column: str = "temperature"
    lag_time_constant_s: float = 0.0
    hysteresis: HysteresisCurve | BranchCurve | None = None
    g_sensitivity_dps_per_g: tuple[float, float, float] | None = None
    g_squared_dps_per_g2: tuple[float, ...] | None = None
    acceleration_network: NetworkCurve | None = None
    unit: AxisUnit = "deg/s"
    rate_term: TemperatureRateTerm | None = None

    def __post_init__(self) -> None:
        check_axis_unit(self.unit)

    #: the turn-on constants of a gyro axis [deg/s], of an accelerometer axis [g]
    turn_on_biases_dps = in_unit("turn_on_biases", "deg/s", "turn_on_biases_dps")
    turn_on_biases_g = in_unit("turn_on_biases", "g", "turn_on_biases_g")

    @property
    def has_acceleration_stage(self) -> bool:
        """Whether the axis has a g-sensitivity stage: G, g x g terms or an acceleration network."""
        return (
            self.g_sensitivity_dps_per_g is not None
            or self.g_squared_dps_per_g2 is not None
            or self.acceleration_network is not None
        )

    @property
    def needs_accel(self) -> bool:
        """Whether the correction reads the accelerometer (an acceleration stage, or a network with accel inputs)."""
        return self.has_acceleration_stage or (self.temperature is not None and self.temperature.needs_accel)

    @property
    def has_memory(self) -> bool:
        """Whether the correction depends on the temperature history (lag, hysteresis or a rate term), not only its
        value."""
        return self.lag_time_constant_s > 0 or self.hysteresis is not None or self.rate_term is not None

    @property
    def mean_turn_on_bias(self) -> float:
        """The constant subtracted when no turn-on window is given [unit]."""
        return float(np.mean(self.turn_on_biases))

    #: the constant subtracted from a gyro axis when no turn-on window is given [deg/s]
    mean_turn_on_bias_dps = in_unit("mean_turn_on_bias", "deg/s", "mean_turn_on_bias_dps")

    def shape_dps(self, temperature_degc: np.ndarray | None) -> np.ndarray | float:
        """A gyro axis's bias shape at ``temperature_degc`` [deg/s]; 0 without a temperature model."""
        require_unit(self.unit, "deg/s", "shape_dps", "temperature.shape")
        if self.temperature is None:
            return 0.0
        return self.temperature.shape(temperature_degc)

    def to_dict(self) -> dict[str, Any]:
        return {
            "temperature": None if self.temperature is None else self.temperature.to_dict(),
            "turn_on_biases_dps": list(self.turn_on_biases),  # an accelerometer's: renamed _g in the file
            "temperature_column": self.temperature_column,
            "lag_time_constant_s": self.lag_time_constant_s,
            "hysteresis": None if self.hysteresis is None else self.hysteresis.to_dict(),
            "g_sensitivity_dps_per_g": None
            if self.g_sensitivity_dps_per_g is None
            else list(self.g_sensitivity_dps_per_g),
            "g_squared_dps_per_g2": None if self.g_squared_dps_per_g2 is None else list(self.g_squared_dps_per_g2),
            "acceleration_network": None if self.acceleration_network is None else self.acceleration_network.to_dict(),
            "temperature_rate": None if self.rate_term is None else self.rate_term.to_dict(),
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any], unit: AxisUnit = "deg/s") -> "AxisCalibration":
        return cls(
            temperature=None if d["temperature"] is None else curve_from_dict(d["temperature"]),
            turn_on_biases=tuple(float(c) for c in d["turn_on_biases_dps"]),
            temperature_column=str(d.get("temperature_column", "temperature")),
            lag_time_constant_s=float(d["lag_time_constant_s"]),
            hysteresis=None if d["hysteresis"] is None else memory_curve_from_dict(d["hysteresis"]),
            g_sensitivity_dps_per_g=_floats(d["g_sensitivity_dps_per_g"], 3, "g_sensitivity_dps_per_g"),
            g_squared_dps_per_g2=_floats(d["g_squared_dps_per_g2"], 6, "g_squared_dps_per_g2"),
            acceleration_network=None
            if d["acceleration_network"] is None
            else NetworkCurve.from_dict(d["acceleration_network"]),
            unit=unit,
            rate_term=None if d["temperature_rate"] is None else TemperatureRateTerm.from_dict(d["temperature_rate"]),
        )


@dataclass(frozen=True)
class AxisSummary:
    """One axis of a model in a line: its unit, the model in words, the calibrated range [degC], the lag [s], the
    g-sensitivity row [unit/g] and the turn-on constants of the calibration runs [unit]."""

    axis: str
    unit: str
    model: str
    range_degc: tuple[float, float] | None
    lag_time_constant_s: float
    g_row: tuple[float, float, float] | None
    turn_on_biases: tuple[float, ...]

    @classmethod
    def of(cls, name: str, ax: "AxisCalibration") -> "AxisSummary":
        curve = ax.temperature
        words = "constant" if curve is None else curve.describe()
        if ax.hysteresis is not None:
            words += f", {ax.hysteresis.describe()}"
        if ax.rate_term is not None:
            words += f", {ax.rate_term.describe(ax.unit)}"
        if ax.has_acceleration_stage:
            words += ", g-sensitivity"
        return cls(
            name,
            ax.unit,
            words,
            None if curve is None else (curve.t_min_degc, curve.t_max_degc),
            ax.lag_time_constant_s,
            ax.g_sensitivity_dps_per_g,
            tuple(ax.turn_on_biases),
        )

    def to_dict(self) -> dict:
        return {
            "axis": self.axis,
            "unit": self.unit,
            "model": self.model,
            "range_degc": None if self.range_degc is None else list(self.range_degc),
            "lag_time_constant_s": self.lag_time_constant_s,
            "g_row": None if self.g_row is None else list(self.g_row),
            "turn_on_biases": list(self.turn_on_biases),
        }


@dataclass(frozen=True)
class Calibration:
    """A fitted compensation: per-axis models, units, valid ranges and provenance.

    Create one with :func:`gyrocomp.fit`; apply it with :func:`gyrocomp.apply`
    or a :class:`gyrocomp.Compensator`; store it with :meth:`save` / :meth:`load`.

    Attributes
    ----------
    axes : dict of str to AxisCalibration
        Each gyro axis's model (``gyro_x``, ...), in deg/s.
    model : str
        The model's short name (``poly:3 (auto) + lag``).
    provenance : dict
        What it was fitted on: the inputs' names and SHA-256, gyrocomp's version, the time.
    fit_report : dict
        How it was fitted (read typed through :attr:`report`).
    schema_version : int
        The model file's schema.
    accel_axes : dict of str to AxisCalibration
        Each accelerometer axis's temperature model, in g.
    accel_reference_degc : float, optional
        The temperature the accelerometer's models are relative to [degC].
    gyro_triad, accel_triad : TriadCalibration, optional
        Scale factor and misalignment of the gyro and the accelerometer triads.
    """

    axes: dict[str, AxisCalibration]
    model: str
    provenance: dict[str, Any] = field(default_factory=dict)
    fit_report: dict[str, Any] = field(default_factory=dict)
    schema_version: int = SCHEMA_VERSION
    #: accelerometer temperature models (accel_x ...): values in [g]; the correction is relative to
    #: ``accel_reference_degc``, since a static accelerometer's constant cannot be told from gravity
    accel_axes: dict[str, AxisCalibration] = field(default_factory=dict)
    accel_reference_degc: float | None = None
    #: the gyro's scale factor and misalignment K(T): corrected = K(T)^-1 (gyro - bias models)
    gyro_triad: TriadCalibration | None = None
    #: the accelerometer's bias, scale factor and misalignment: corrected = C (accel - b), after the
    #: accelerometer's temperature models
    accel_triad: TriadCalibration | None = None

    def __post_init__(self) -> None:
        for section, unit, axes in (("axes", "deg/s", self.axes), ("accel_axes", "g", self.accel_axes)):
            for name, ax in axes.items():
                if ax.unit != unit:
                    raise InputError(f"{section}[{name!r}].unit: {ax.unit!r}; the axes of {section} are in {unit}")

    def summaries(self) -> tuple[AxisSummary, ...]:
        """Every gyro, then accelerometer, axis in a line (:class:`AxisSummary`)."""
        return tuple(AxisSummary.of(n, ax) for n, ax in (*self.axes.items(), *self.accel_axes.items()))

    @property
    def report(self) -> FitReport:
        """How the model was fitted, typed (:class:`gyrocomp.calibration.fit_report.FitReport`), read from ``fit_report``."""
        return FitReport.from_dict(self.fit_report)

    def without(self, *parts: str) -> "Calibration":
        """The same calibration with parts switched off: ``"acceleration"`` (G and g x g), ``"hysteresis"``
        (turning-point), ``"lag"``, ``"rate"`` (the temperature-rate term), ``"scale-factor"`` (the gyro triad's K(T)). What is left is applied as fitted
        (the parts were fitted jointly), so this shows each part's contribution, as the stages of the thesis's
        Table 4.4.

        Parameters
        ----------
        *parts : str
            Any of ``acceleration``, ``hysteresis``, ``lag``, ``rate``, ``scale-factor``.
        """
        known = ("acceleration", "hysteresis", "lag", "rate", "scale-factor")
        for part in parts:
            if part not in known:
                raise InputError(f"unknown part {part!r}; use any of {', '.join(known)}")
        changes = {}
        if "acceleration" in parts:
            changes.update(g_sensitivity_dps_per_g=None, g_squared_dps_per_g2=None, acceleration_network=None)
        if "hysteresis" in parts:
            changes["hysteresis"] = None
        if "lag" in parts:
            changes["lag_time_constant_s"] = 0.0
        if "rate" in parts:
            changes["rate_term"] = None
        axes = {name: dataclasses.replace(ax, **changes) for name, ax in self.axes.items()}
        triad = None if "scale-factor" in parts else self.gyro_triad
        return dataclasses.replace(
            self, axes=axes, gyro_triad=triad, model=f"{self.model} without {', '.join(parts)}" if parts else self.model
        )

    def without_accel_triad(self) -> "Calibration":
        """The same calibration without the accelerometer's bias, scale and misalignment (its temperature models
        kept): the accelerations the gyro's g-sensitivity reads."""
        return dataclasses.replace(self, accel_triad=None)

    @property
    def has_acceleration(self) -> bool:
        """Whether some axis has a g-sensitivity stage (G or g x g) that ``without("acceleration")`` removes."""
        return any(ax.has_acceleration_stage for ax in self.axes.values())

    @property
    def has_hysteresis(self) -> bool:
        return any(ax.hysteresis is not None for ax in self.axes.values())

    @property
    def needs_temperature(self) -> bool:
        return any(ax.temperature is not None for ax in self.axes.values())

    # -- serialization -------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        return {
            "format": FORMAT_NAME,
            "schema_version": self.schema_version,
            "model": self.model,
            "units": dict(UNITS),
            "axes": {name: ax.to_dict() for name, ax in self.axes.items()},
            "accel_axes": {name: _in_g(ax.to_dict(), True) for name, ax in self.accel_axes.items()},
            "accel_reference_degc": self.accel_reference_degc,
            "gyro_triad": None if self.gyro_triad is None else self.gyro_triad.to_dict(),
            "accel_triad": None if self.accel_triad is None else self.accel_triad.to_dict(),
            "fit_report": self.fit_report,
            "provenance": self.provenance,
        }

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), indent=2, allow_nan=False) + "\n"

    def fitted_on(
        self, path: str | os.PathLike | None, time_range_s: tuple[float | None, float | None] | None = None
    ) -> bool:
        """Whether the rows of the file at ``path`` (those within ``time_range_s``) are all rows the model was
        fitted on: figures judged on them are in-sample, not the drift to expect on new data
        (:meth:`fitted_share`).

        Parameters
        ----------
        path : path or None
            The file (None: False).
        time_range_s : (float or None, float or None), optional
            The window of the file judged, [A, B) [s from its first sample] (None: an open end); default: the
            whole file.
        """
        return self.fitted_share(path, time_range_s) == "all"

    def fitted_share(
        self, path: str | os.PathLike | None, time_range_s: tuple[float | None, float | None] | None = None
    ) -> str:
        """How much of the window ``time_range_s`` [s from the file's first sample] of the file at ``path`` the
        model was fitted on: ``"all"``, ``"part"`` or ``"none"``. The file is an input when its name and SHA-256
        are an input's in the provenance; the rows fitted are the window that input was read with (``--time``),
        else the whole file (as model files written before the window was kept say).

        Parameters
        ----------
        path : path or None
            The file (None: ``"none"``).
        time_range_s : (float or None, float or None), optional
            The window judged, [A, B) [s from the file's first sample] (None: the whole file).
        """
        if path is None or not Path(path).is_file():
            return "none"
        named = [
            entry
            for entry in self.provenance.get("inputs", ())
            if isinstance(entry, dict) and entry.get("file") == Path(path).name and entry.get("sha256")
        ]
        if not named:
            return "none"
        digest = file_sha256(path)
        judged = _window(time_range_s)
        shares = {_overlap(_window(entry.get("time_range_s")), judged) for entry in named if entry["sha256"] == digest}
        return "all" if "all" in shares else "part" if "part" in shares else "none"

    def save(self, path: str | os.PathLike) -> None:
        """Write the model file atomically.

        Parameters
        ----------
        path : path
            The model file to write (JSON, versioned); an input of the model is never overwritten.
        """
        write_text_atomic(path, self.to_json())

    @classmethod
    def from_dict(cls, d: Any, source: str = "<dict>") -> "Calibration":
        """The calibration of a model file's content, upgraded from an earlier schema and validated.

        Parameters
        ----------
        d : dict
            The model file's JSON object.
        source : str
            Where it came from (a file name), for messages.
        """
        if not isinstance(d, dict) or d.get("format") != FORMAT_NAME:
            raise InputError(f'{source}: not a gyrocomp model file (no "format": "{FORMAT_NAME}")')
        version = d.get("schema_version")
        if not isinstance(version, int) or isinstance(version, bool) or version < 1:
            raise InputError(f"{source}: schema_version {version!r} is not a positive whole number")
        if version > SCHEMA_VERSION:
            raise InputError(
                f"{source}: written with model schema {version}, this gyrocomp reads schema {SCHEMA_VERSION} "
                "and older; upgrade gyrocomp to read it"
            )
        try:
            while version < SCHEMA_VERSION:
                d = UPGRADES[version](d)
                version += 1
            _require_finite(d)  # NaN compares false with any bound: named here, with its field
            validate_model(d)  # the published schema: every field typed, bounded, known (schema.py)
            _check_ranges(d)
            axes = {str(name): AxisCalibration.from_dict(ax) for name, ax in d["axes"].items()}
            accel_axes = {
                str(name): AxisCalibration.from_dict(_in_g(ax, False), unit="g") for name, ax in d["accel_axes"].items()
            }
            triads = {
                key: None if d[key] is None else TriadCalibration.from_dict(d[key], key)
                for key in ("gyro_triad", "accel_triad")
            }
            _check_triads(triads, axes)
            if not axes and not accel_axes and triads["accel_triad"] is None:
                raise InputError("no axes")
            reference = d["accel_reference_degc"]
            if accel_axes and reference is None:
                raise InputError("accel_axes need accel_reference_degc")
            report = dict(d.get("fit_report", {}))
            try:  # what show and the report read of it: typed, so that a damaged report is refused here
                FitReport.from_dict(report)
            except (KeyError, TypeError, ValueError, AttributeError, IndexError) as exc:
                raise InputError(f"fit_report: malformed ({type(exc).__name__}: {exc})") from None
            return cls(
                axes=axes,
                model=str(d["model"]),
                provenance=dict(d.get("provenance", {})),
                fit_report=report,
                schema_version=SCHEMA_VERSION,
                accel_axes=accel_axes,
                accel_reference_degc=None if reference is None else float(reference),
                **triads,
            )
        except InputError as exc:
            raise InputError(f"{source}: {exc}") from None
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            raise InputError(f"{source}: malformed model file ({type(exc).__name__}: {exc})") from None

    @classmethod
    def load(cls, path: str | os.PathLike) -> "Calibration":
        """Read and validate a model file written by :meth:`save`.

        Parameters
        ----------
        path : path
            The model file (JSON, any earlier schema: upgraded on load).

        Returns
        -------
        Calibration
            Refused in one line naming the file and field when it is not a valid model file.
        """
        if not isinstance(path, (str, os.PathLike)):
            raise InputError(f"path: expected a model file name or path, got {type(path).__name__}")
        path = Path(path)
        try:
            text = path.read_text(encoding="utf-8")
        except FileNotFoundError:
            raise InputError(f"{path}: no such model file") from None
        except (UnicodeDecodeError, IsADirectoryError):
            raise InputError(f"{path}: not a gyrocomp model file (not UTF-8 JSON text)") from None
        except OSError as exc:  # permissions, a symbolic link loop, a device that fails
            raise InputError(
                f"{path}: cannot read the model file ({(exc.strerror or type(exc).__name__).lower()})"
            ) from None
        data = jsontext.loads(
            text,
            str(path),
            "model file",
            "the file may be truncated, write it again with gyrocomp fit",
            non_finite=True,
        )
        return cls.from_dict(data, source=str(path))


def _window(value) -> tuple[float, float]:
    """A time window [A, B) [s] with open ends as infinities (None or a malformed value: the whole file)."""
    if not isinstance(value, (list, tuple)) or len(value) != 2:
        return (-math.inf, math.inf)
    lo, hi = (v if isinstance(v, (int, float)) and not isinstance(v, bool) else None for v in value)
    return (-math.inf if lo is None else float(lo), math.inf if hi is None else float(hi))


def _overlap(fitted: tuple[float, float], judged: tuple[float, float]) -> str:
    """``"all"`` when the window ``judged`` lies within ``fitted``, ``"none"`` when they share no time, else
    ``"part"``."""
    if judged[0] >= fitted[0] and judged[1] <= fitted[1]:
        return "all"
    if judged[1] <= fitted[0] or judged[0] >= fitted[1]:
        return "none"
    return "part"


__all__ = ["AxisCalibration", "AxisSummary", "Calibration", "FORMAT_NAME", "SCHEMA_VERSION"]
