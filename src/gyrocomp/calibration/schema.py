"""The published schema of model files (JSON Schema, draft 2020-12), and their validation on load.

The schema is shipped beside this module as ``model.schema.json`` (``importlib.resources.files("gyrocomp.calibration")
/ "model.schema.json"``), so that other tools can validate gyrocomp's model files; :func:`build_schema` makes it
(``python tools/model_schema.py`` writes the file, and a test checks that the two agree). It says, of the current
schema version (older files are upgraded first, then validated):

- every object's keys (any other is refused: a field is either used or refused);
- strict types: a number is a JSON number, never a boolean nor a numeric string;
- ranges a sensor model can have: rates within +-1e4 deg/s, accelerations within +-100 g, temperatures within
  -100..200 degC, a temperature scale of at least 0.01 degC, a lag of at most 1e6 s, sensitivities within +-10;
- the units block, where present, is exactly gyrocomp's (deg/s, degC, s, g): a model is never read in other units;
- each curve by its ``type`` (polynomial, mlp, table; turning-point, turning-table, play-bank, branch); a curve registered beyond these is
  left to its own reader (``from_dict``), which refuses an unknown type.

What a schema cannot say (a range whose minimum is above its maximum, a network's weights against its layers, a
triad needing all three gyro axes) the curves' and triads' own readers check. The validator is the ``jsonschema``
package's; its first error (:func:`jsonschema.exceptions.best_match`) is reported with the path of the field
(``axes.gyro_z.temperature.t_scale_degc: 0 is less than the minimum of 0.01``).
"""

from __future__ import annotations

import functools
import json
from importlib import resources
from typing import Any

import jsonschema
from jsonschema.exceptions import best_match

from ..curves.network import NETWORK_INPUTS
from ..curves.play_bank import MAX_PLAYS
from ..curves.polynomial import EXTRAPOLATIONS
from ..errors import InputError
from ..recording import ACCEL_AXES, GYRO_AXES, TEMPERATURE_COLUMN
from .triad import TRIAD_METHODS

SCHEMA_FILE = "model.schema.json"
SCHEMA_ID = "https://gyrocomp.invalid/model.schema.json"
#: the units every model file is in (its ``units`` block, where present, must say exactly these)
UNITS = {"gyro": "deg/s", "temperature": "degC", "time": "s", "accel": "g"}
#: the temperature channels a model may read: one shared, or one per gyro axis
TEMPERATURE_CHANNELS = (TEMPERATURE_COLUMN, *(f"{TEMPERATURE_COLUMN}_{a[-1]}" for a in GYRO_AXES))
#: physical bounds: rates [deg/s], accelerations [g], temperatures [degC], a lag [s], network weights
RATE_DPS, ACCEL_G, TEMPERATURE_DEGC, LAG_S, WEIGHT = 1e4, 100.0, (-100.0, 200.0), 1e6, 1e6
#: the most coefficients of a polynomial or hysteresis curve, values of a table, neurons of a layer, layers
MAX_COEFFICIENTS, MAX_TABLE, MAX_HIDDEN, MAX_LAYERS = 10, 1000, 50, 3


def _number(lo: float, hi: float, exclusive_lo: bool = False) -> dict:
    low = {"exclusiveMinimum": lo} if exclusive_lo else {"minimum": lo}
    return {"type": "number", **low, "maximum": hi}


def _array(item: dict, n: int | None = None, lo: int = 0, hi: int | None = None) -> dict:
    out: dict[str, Any] = {"type": "array", "items": item}
    if n is not None:
        out.update(minItems=n, maxItems=n)
    else:
        out["minItems"] = lo
        if hi is not None:
            out["maxItems"] = hi
    return out


def _provenance() -> dict:
    """What the model came from: its inputs (when given) a list of files, each named (``show`` and
    :meth:`~gyrocomp.calibration.Calibration.fitted_share` read them)."""
    return {
        "type": "object",
        "properties": {
            "inputs": _array({"type": "object", "properties": {"file": {"type": "string"}}}),
            "gyrocomp_version": {"type": "string"},
            "created_utc": {"type": "string"},
        },
    }


def _with_input_ranges(network: dict) -> dict:
    """An MLP curve's schema with its input ranges and reference one value per input (as many as ``inputs``, which
    defaults to the temperature alone): one ``if``/``then`` per count of inputs."""
    ranges = ("input_min", "input_max", "reference")
    network["allOf"] = [
        {
            "if": {"required": ["inputs"], "properties": {"inputs": {"minItems": k, "maxItems": k}}},
            "then": {"required": list(ranges), "properties": {key: {"minItems": k, "maxItems": k} for key in ranges}},
        }
        for k in range(2, len(NETWORK_INPUTS) + 1)
    ] + [
        {
            "if": {"anyOf": [{"not": {"required": ["inputs"]}}, {"properties": {"inputs": {"maxItems": 1}}}]},
            "then": {"properties": {key: {"maxItems": 1} for key in ranges}},
        }
    ]
    return network


def _object(properties: dict, required: list[str] | None = None) -> dict:
    return {
        "type": "object",
        "properties": properties,
        "required": list(properties) if required is None else required,
        "additionalProperties": False,
    }


def _nullable(schema: dict) -> dict:
    return {"anyOf": [{"type": "null"}, schema]}


def _curves(u: str, value: dict) -> dict:
    """The temperature curves of an axis whose values are in unit suffix ``u`` (``_dps`` or ``_g``), bounded by
    ``value``."""
    temperature = {"$ref": "#/$defs/temperature_degc"}
    scale = _number(0.01, 1000.0)
    return {
        "polynomial": _object(
            {
                "type": {"const": "polynomial"},
                f"coefficients{u}": _array(value, hi=MAX_COEFFICIENTS),
                "t_ref_degc": temperature,
                "t_scale_degc": scale,
                "t_min_degc": temperature,
                "t_max_degc": temperature,
                "extrapolation": {"enum": list(EXTRAPOLATIONS)},
            },
            ["type", f"coefficients{u}", "t_ref_degc", "t_scale_degc", "t_min_degc", "t_max_degc"],
        ),
        "mlp": _with_input_ranges(
            _object(
                {
                    "type": {"const": "mlp"},
                    "hidden": _array({"type": "integer", "minimum": 1, "maximum": MAX_HIDDEN}, lo=1, hi=MAX_LAYERS),
                    "activation": {"const": "tanh"},
                    "output": {"const": "linear"},
                    "inputs": {
                        **_array({"enum": list(NETWORK_INPUTS)}, lo=1, hi=len(NETWORK_INPUTS)),
                        "uniqueItems": True,
                    },
                    "input_min": _array(_number(-1e3, 1e3), hi=len(NETWORK_INPUTS)),
                    "input_max": _array(_number(-1e3, 1e3), hi=len(NETWORK_INPUTS)),
                    "reference": _array(_number(-1e3, 1e3), hi=len(NETWORK_INPUTS)),
                    "weights": _array(_array(_number(-WEIGHT, WEIGHT), lo=1, hi=10000), lo=2, hi=MAX_LAYERS + 1),
                    f"output_mean{u}": value,
                    f"output_scale{u}": {**value, "exclusiveMinimum": 0},
                    "t_ref_degc": temperature,
                    "t_min_degc": temperature,
                    "t_max_degc": temperature,
                },
                [
                    "type",
                    "hidden",
                    "weights",
                    f"output_mean{u}",
                    f"output_scale{u}",
                    "t_ref_degc",
                    "t_min_degc",
                    "t_max_degc",
                ],
            )
        ),
        "table": _object(
            {
                "type": {"const": "table"},
                f"values{u}": _array(value, lo=2, hi=MAX_TABLE),
                "t_min_degc": temperature,
                "t_max_degc": temperature,
            }
        ),
    }


def _memory(u: str, value: dict) -> dict:
    temperature = {"$ref": "#/$defs/temperature_degc"}
    threshold = _number(0.0, 100.0)
    return {
        "turning-point": _object(
            {
                "type": {"const": "turning-point"},
                f"descending{u}": _array(value, hi=MAX_COEFFICIENTS),
                f"ascending{u}": _array(value, hi=MAX_COEFFICIENTS),
                "threshold_degc": threshold,
                "band_degc": _nullable(_array(temperature, 2)),
                "max_distance_degc": _nullable(_array(_number(0.0, 300.0), 2)),
            },
            ["type", f"descending{u}", f"ascending{u}", "threshold_degc", "band_degc"],
        ),
        "turning-table": _object(
            {
                "type": {"const": "turning-table"},
                "knots_degc": _array(_number(0.0, 300.0, exclusive_lo=True), lo=1, hi=MAX_TABLE),
                f"descending{u}": _array(value, lo=1, hi=MAX_TABLE),
                f"ascending{u}": _array(value, lo=1, hi=MAX_TABLE),
                "threshold_degc": threshold,
            }
        ),
        "play-bank": _object(
            {
                "type": {"const": "play-bank"},
                "half_widths_degc": _array(_number(0.0, 300.0, exclusive_lo=True), lo=1, hi=MAX_PLAYS),
                f"weights{u}": _array(value, lo=1, hi=MAX_PLAYS),
            }
        ),
        "branch": _object(
            {
                "type": {"const": "branch"},
                f"coefficients{u}": _array(value, lo=1, hi=MAX_COEFFICIENTS),
                "t_ref_degc": temperature,
                "t_scale_degc": _number(0.01, 1000.0),
                "transition_degc": _number(0.0, 1000.0, exclusive_lo=True),
                "threshold_degc": threshold,
                "t_min_degc": temperature,
                "t_max_degc": temperature,
            }
        ),
    }


def _by_type(defs: dict[str, dict], prefix: str, what: str) -> dict:
    """One of ``defs`` chosen by the object's ``type`` (so that an error is about that kind's fields, not a list
    of every kind that did not match); another type is left to the registry's reader (``what`` names the kind)."""
    return {
        "type": "object",
        "required": ["type"],
        "properties": {"type": {"type": "string", "description": f"the {what}'s kind"}},
        "allOf": [
            {"if": {"properties": {"type": {"const": kind}}}, "then": {"$ref": f"#/$defs/{prefix}{kind}"}}
            for kind in defs
        ],
    }


def _axis(u: str, value: dict, per_g: bool) -> dict:
    """An axis of unit suffix ``u`` (``_dps`` for a gyro axis, ``_g`` for an accelerometer axis)."""
    sensitivity = _number(-1e3, 1e3)
    return _object(
        {
            "temperature": _nullable({"$ref": f"#/$defs/curve{u}"}),
            f"turn_on_biases{u}": _array(value, lo=0 if per_g else 1, hi=10000),
            "temperature_column": {"enum": list(TEMPERATURE_CHANNELS)},
            "lag_time_constant_s": _number(0.0, LAG_S),
            "hysteresis": _nullable({"$ref": f"#/$defs/memory{u}"}),
            "g_sensitivity_dps_per_g": _nullable(_array(sensitivity, 3)),
            "g_squared_dps_per_g2": _nullable(_array(sensitivity, 6)),
            "acceleration_network": _nullable({"$ref": f"#/$defs/curve{u}_mlp"}),
            "temperature_rate": _nullable(
                _object(
                    {
                        "type": {"const": "temperature-rate"},
                        "coefficient_per_degc_per_s": _number(-1e6, 1e6),
                        "smoothing_s": _number(0.0, LAG_S, exclusive_lo=True),
                    }
                )
            ),
        },
        [
            "temperature",
            f"turn_on_biases{u}",
            "lag_time_constant_s",
            "hysteresis",
            "g_sensitivity_dps_per_g",
            "g_squared_dps_per_g2",
            "acceleration_network",
            "temperature_rate",
        ],
    )


def _triad(u: str, unit: str, value: dict) -> dict:
    matrix = _array(_array(_number(-10.0, 10.0), 3), 3)
    error = _array(_array(_number(0.0, 10.0), 3), 3)
    per_degc = _array(_array(_number(-1.0, 1.0), 3), 3)
    return _object(
        {
            "method": {"enum": list(TRIAD_METHODS)},
            "unit": {"const": unit},
            "sensitivity": matrix,
            "sensitivity_stderr": error,
            f"bias{u}": _array(value, 3),
            f"bias_stderr{u}": _array({**value, "minimum": 0}, 3),
            "reference_degc": _nullable({"$ref": "#/$defs/temperature_degc"}),
            "sensitivity_per_degc": _array(per_degc, hi=4),
            "sensitivity_per_degc_stderr": _array(_array(_array(_number(0.0, 1.0), 3), 3), hi=4),
        },
        ["method", "unit", "sensitivity", "sensitivity_stderr", f"bias{u}", f"bias_stderr{u}"],
    )


def build_schema(version: int) -> dict:
    """The JSON Schema of model files of schema ``version`` (the current one: older files are upgraded first)."""
    rate, accel = _number(-RATE_DPS, RATE_DPS), _number(-ACCEL_G, ACCEL_G)
    defs: dict[str, Any] = {"temperature_degc": _number(*TEMPERATURE_DEGC)}
    for u, value in (("_dps", rate), ("_g", accel)):
        curves, memories = _curves(u, value), _memory(u, value)
        defs.update({f"curve{u}_{kind}": schema for kind, schema in curves.items()})
        defs.update({f"memory{u}_{kind}": schema for kind, schema in memories.items()})
        defs[f"curve{u}"] = _by_type(curves, f"curve{u}_", "temperature curve")
        defs[f"memory{u}"] = _by_type(memories, f"memory{u}_", "thermal memory")
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "$id": SCHEMA_ID,
        "title": f"gyrocomp model file, schema {version}",
        "description": "A calibration gyrocomp fitted: per gyro (and accelerometer) axis its temperature curve, "
        "turn-on constants, thermal lag and memory, g-sensitivity; the triads' scale factor and "
        "misalignment; how it was fitted and from what. Units: deg/s, g, degC, s.",
        "type": "object",
        "properties": {
            "format": {"const": "gyrocomp-calibration"},
            "schema_version": {"type": "integer", "minimum": 1},
            "model": {"type": "string", "maxLength": 1000},
            "units": _object({name: {"const": unit} for name, unit in UNITS.items()}),
            "axes": {
                "type": "object",
                "propertyNames": {"enum": list(GYRO_AXES)},
                "additionalProperties": _axis("_dps", rate, False),
            },
            "accel_axes": {
                "type": "object",
                "propertyNames": {"enum": list(ACCEL_AXES)},
                "additionalProperties": _axis("_g", accel, True),
            },
            "accel_reference_degc": _nullable({"$ref": "#/$defs/temperature_degc"}),
            "gyro_triad": _nullable(_triad("_dps", "deg/s", rate)),
            "accel_triad": _nullable(_triad("_g", "g", accel)),
            "fit_report": {"type": "object"},
            "provenance": _provenance(),
        },
        "required": [
            "format",
            "schema_version",
            "model",
            "axes",
            "accel_axes",
            "accel_reference_degc",
            "gyro_triad",
            "accel_triad",
        ],
        "additionalProperties": False,
        "$defs": defs,
    }


@functools.lru_cache(maxsize=1)
def published_schema() -> dict:
    """The schema shipped with the package (``model.schema.json``)."""
    return json.loads(resources.files(__package__).joinpath(SCHEMA_FILE).read_text(encoding="utf-8"))


def _path(error: jsonschema.ValidationError) -> str:
    out = ""
    for part in error.absolute_path:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out


def validate_model(d: dict) -> None:
    """Refuse a model file's content (after upgrading) that does not follow the published schema, naming the
    field's path (:class:`InputError`)."""
    validator = jsonschema.Draft202012Validator(published_schema())
    error = best_match(validator.iter_errors(d))
    if error is None:
        return
    if error.validator in ("maxItems", "minItems") and isinstance(error.instance, list):
        bound = "at most" if error.validator == "maxItems" else "at least"
        message = f"{len(error.instance)} values; {bound} {error.validator_value}"
    else:
        message = error.message if len(error.message) <= 200 else error.message[:200] + "..."
    path = _path(error)
    raise InputError(f"{path}: {message}" if path else message)


__all__ = ["SCHEMA_FILE", "TEMPERATURE_CHANNELS", "UNITS", "build_schema", "published_schema", "validate_model"]
