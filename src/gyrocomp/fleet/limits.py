"""Pass/fail limits on a unit's figures of merit, read from a TOML file.

One table per figure; a figure name alone applies to every gyro axis, prefixed by an axis to that axis only;
the bounds are ``min``, ``max`` and ``abs_max`` (a bound on the magnitude, for signed figures)::

    [noise_density_dps_per_sqrt_hz]
    max = 0.01

    [temperature_sensitivity_dps_per_degc]
    abs_max = 0.05

    [gyro_z_held_out_drift_dps]
    max = 0.02

    [temperature_max_degc]   # figures of the whole unit: runs, temperature_min_degc, temperature_max_degc
    min = 60

A figure that was not measured (NaN: no g-sensitivity fitted, a reference temperature outside the runs) fails
its limit: a production line cannot pass what it did not measure.
"""

from __future__ import annotations

import math
import os
import tomllib
from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError
from .unit_figures import FIGURE_NAMES, UnitFigures

UNIT_FIGURES = ("runs", "temperature_min_degc", "temperature_max_degc")
BOUNDS = ("min", "max", "abs_max")


@dataclass(frozen=True)
class Limit:
    """Bounds on one figure; ``axis`` None: every axis (or a figure of the whole unit)."""

    figure: str
    axis: str | None = None
    min: float | None = None
    max: float | None = None
    abs_max: float | None = None

    def violation(self, value: float) -> str | None:
        """Why ``value`` fails (a short phrase), or None when it passes."""
        if math.isnan(value):
            return "not measured"
        if self.min is not None and value < self.min:
            return f"{value:.4g} < min {self.min:.4g}"
        if self.max is not None and value > self.max:
            return f"{value:.4g} > max {self.max:.4g}"
        if self.abs_max is not None and abs(value) > self.abs_max:
            return f"|{value:.4g}| > abs_max {self.abs_max:.4g}"
        return None


@dataclass(frozen=True)
class Failure:
    """One figure outside its limit: the flat figure name (``gyro_z_noise_density_dps_per_sqrt_hz``), its value
    and why."""

    figure: str
    value: float
    reason: str


@dataclass(frozen=True)
class Verdict:
    """Pass or fail, with every failing figure."""

    passed: bool
    failures: tuple[Failure, ...] = ()

    @property
    def label(self) -> str:
        return "pass" if self.passed else "fail"

    def summary(self) -> str:
        return "; ".join(f"{f.figure} {f.reason}" for f in self.failures)


@dataclass(frozen=True)
class Limits:
    """A set of limits (see the module); ``check`` gives a unit's verdict."""

    limits: tuple[Limit, ...]
    source: str = "<limits>"

    def check(self, figures: UnitFigures) -> Verdict:
        row = figures.as_row()
        failures = []
        for limit in self.limits:
            if limit.figure in UNIT_FIGURES:
                names = [limit.figure]
            elif limit.axis is not None:
                names = [f"{limit.axis}_{limit.figure}"]
                if names[0] not in row:
                    failures.append(Failure(names[0], math.nan, "axis not in the model"))
                    continue
            else:
                names = [f"{axis}_{limit.figure}" for axis in figures.axes]
            for name in names:
                reason = limit.violation(row[name])
                if reason is not None:
                    failures.append(Failure(name, row[name], reason))
        return Verdict(not failures, tuple(failures))

    @classmethod
    def from_mapping(cls, document: dict, source: str = "<limits>") -> "Limits":
        limits = []
        for key, bounds in document.items():
            where = f"{source}: [{key}]"
            figure, axis = _figure_of(key, where)
            if not isinstance(bounds, dict) or not bounds:
                raise InputError(f"{where}: give bounds as a table, e.g. max = 0.01 ({', '.join(BOUNDS)})")
            unknown = sorted(set(bounds) - set(BOUNDS))
            if unknown:
                raise InputError(f"{where}: unknown bound {unknown[0]!r}; use {', '.join(BOUNDS)}")
            for name, value in bounds.items():
                if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                    raise InputError(f"{where}: {name} = {value!r} is not a finite number")
            if "min" in bounds and "max" in bounds and bounds["min"] > bounds["max"]:
                raise InputError(f"{where}: min {bounds['min']} is above max {bounds['max']}")
            if bounds.get("abs_max", 0) < 0:
                raise InputError(f"{where}: abs_max must be >= 0, got {bounds['abs_max']}")
            limits.append(Limit(figure, axis, **{k: float(v) for k, v in bounds.items()}))
        return cls(tuple(limits), source)

    @classmethod
    def load(cls, path: str | os.PathLike) -> "Limits":
        path = Path(path)
        try:
            document = tomllib.loads(path.read_text(encoding="utf-8"))
        except FileNotFoundError:
            raise InputError(f"{path}: no such limits file") from None
        except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
            raise InputError(f"{path}: not a TOML file: {exc}") from None
        return cls.from_mapping(document, str(path))


def _figure_of(key: str, where: str) -> tuple[str, str | None]:
    """(figure, axis) of a limit's key: ``noise_density_dps_per_sqrt_hz`` or ``gyro_z_noise_density_...``."""
    if key in FIGURE_NAMES or key in UNIT_FIGURES:
        return key, None
    for figure in FIGURE_NAMES:
        if key.endswith("_" + figure):
            return figure, key[: -len(figure) - 1]
    raise InputError(
        f"{where}: unknown figure; use one of {', '.join(FIGURE_NAMES + UNIT_FIGURES)}, optionally "
        f"after an axis (gyro_z_...)"
    )


__all__ = ["BOUNDS", "Failure", "Limit", "Limits", "UNIT_FIGURES", "Verdict"]
