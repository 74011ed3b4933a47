"""The whole model as dependency-free C99 for firmware: ``gyrocomp.h`` and ``gyrocomp.c`` (and, beside them, the
online learner: :mod:`gyrocomp.export.c_learner`).

Interface (``gyrocomp_state`` is defined in the header, so callers allocate it; no dynamic memory)::

    void gyrocomp_init(gyrocomp_state *s);
    void gyrocomp_step(gyrocomp_state *s, double t, const double gyro[3], const double accel[3],
                       double temperature, double out[3]);

Units: t [s], gyro and out [deg/s] on x, y, z, accel [g] on x, y, z, temperature [degC]. Axes the model
does not cover pass through unchanged. When the model compensates the accelerometer for temperature, each
step leaves the compensated accelerations [g] in ``s->accel_out`` (else the input), and the g-sensitivity
reads them, as ``gyrocomp apply`` does. The code does what :class:`gyrocomp.Compensator` does, sample by
sample and in the same order of operations: g-sensitivity, the temperature curve (its own C:
:meth:`gyrocomp.curves.protocol.TemperatureCurve.c_code`) on the lagged temperature (the first-order-hold lag
steps one nominal period per sample and bridges longer gaps exactly), the turning-point hysteresis, and the
mean turn-on constant of the calibration runs; then
the gyro's scale factor and misalignment (out = K(T)^-1 out, K(T) at the input temperature). An
accelerometer triad corrects ``s->accel_out`` after its temperature models (the g-sensitivity reads the
accelerations before it, as it was fitted).
"""

from __future__ import annotations


import contextlib
import os
from pathlib import Path

import numpy as np

from ..calibration import AxisCalibration, Calibration
from ..c_literals import c_array, c_number
from ..errors import InputError
from ..io.atomic import write_texts_atomic
from .encode import c_comment
from ..curves.hysteresis import BranchCurve, HysteresisCurve
from ..fitting.online import LearnerSettings
from ..calibration.triad import TriadCalibration
from .c_learner import learner_c_sources
from .exporters import ExportOptions, Exported, Exporter, register

AXES = ("gyro_x", "gyro_y", "gyro_z")
ACCEL = ("accel_x", "accel_y", "accel_z")


def _temperature_code(j: int, curve) -> list[str]:
    """C statements setting `shape` for axis slot j from `tm` (model temperature) and `acc`: the curve's own
    (:meth:`gyrocomp.curves.protocol.TemperatureCurve.c_code`)."""
    if curve is None:
        return ["    shape = 0.0;"]
    return ["    " + line for line in curve.c_code(f"net{j}").statements]


def _turning_point_code(j: int, h: HysteresisCurve) -> list[str]:
    lines = [f"    turn_update(&s->turn[{j}], tm, {c_number(h.threshold_degc)});",
             f"    if (s->turn[{j}].has_turn) {{"]
    band = "" if h.band_degc is None else f" && tm >= {c_number(h.band_degc[0])} && tm <= {c_number(h.band_degc[1])}"
    reach = h.max_distance_degc or (None, None)
    for sign, coefs, d_max in ((-1, h.descending, reach[0]), (1, h.ascending, reach[1])):
        lines.append(f"        if (s->turn[{j}].direction == {sign}{band}) {{")
        lines.append(f"            const double h[] = {c_array(coefs)};")
        lines.append(f"            double d = fabs(tm - s->turn[{j}].turn), off = 0.0;")
        if d_max is not None:
            lines.append(f"            if (d > {c_number(d_max)}) d = {c_number(d_max)};")
        lines.append(f"            for (int k = {len(coefs) - 1}; k >= 0; --k) off = (off + h[k]) * d;")
        lines.append("            shape += off;")
        lines.append("        }")
    lines.append("    }")
    return lines


def _branch_code(j: int, h: BranchCurve) -> list[str]:
    """The heating and cooling branches: s * sum c_k u^k (gyrocomp.effects.branch_position for s)."""
    return [f"    turn_update(&s->turn[{j}], tm, {c_number(h.threshold_degc)});",
            "    {",
            f"        const double c[] = {c_array(h.coefficients)};",
            f"        double tc = tm < {c_number(h.t_min_degc)} ? {c_number(h.t_min_degc)} : "
            f"(tm > {c_number(h.t_max_degc)} ? {c_number(h.t_max_degc)} : tm);",
            f"        double u = (tc - {c_number(h.t_ref_degc)}) / {c_number(h.t_scale_degc)}, half = 0.0;",
            f"        for (int k = {h.order - 1}; k >= 0; --k) half = half * u + c[k];",
            f"        const gyrocomp_turn *tp = &s->turn[{j}];",
            "        double position = (double)tp->direction;",
            f"        if (tp->has_turn) position *= 1.0 - 2.0 * exp(-fabs(tm - tp->turn) / {c_number(h.transition_degc)});",
            f"        else position *= 1.0 - exp(-fabs(tm - (tp->direction > 0 ? tp->low : tp->high)) / "
            f"{c_number(h.transition_degc)});",
            "        shape += position * half;",
            "    }"]


#: the C of each memory curve a model can hold (gyrocomp.curves.hysteresis.MEMORY_CURVES), by its class
_MEMORY_CODE = {HysteresisCurve: _turning_point_code, BranchCurve: _branch_code}


def _hysteresis_code(j: int, ax: AxisCalibration) -> list[str]:
    h = ax.hysteresis
    if h is None:
        return []
    if type(h) not in _MEMORY_CODE:
        raise InputError(f"export: no C code for a {type(h).__name__} memory model")
    return _MEMORY_CODE[type(h)](j, h)


_HEADER = """/* gyrocomp model {model}, generated by gyrocomp. C99, no dynamic memory.
 * Units: t [s], gyro and out [deg/s], accel [g], temperature [degC]. Axes x, y, z. */
#ifndef GYROCOMP_H
#define GYROCOMP_H

typedef struct {
    int started;         /* the lag filter starts in equilibrium on the first sample */
    double last_input;   /* temperature of the previous sample [degC] */
    double last_output;  /* lagged temperature of the previous sample [degC] */
} gyrocomp_lag;

typedef struct {
    int direction;       /* +1 rising, -1 falling, 0 not yet known */
    int has_turn;        /* a reversal has been confirmed */
    double extreme;      /* running extreme of the current branch [degC] */
    double turn;         /* temperature of the last reversal [degC] */
    double low, high;    /* range seen while the direction is not known [degC] */
} gyrocomp_turn;

typedef struct gyrocomp_state {
    int started;
    double last_t;
    gyrocomp_lag lag[6];      /* gyro x, y, z, then accelerometer x, y, z */
    gyrocomp_turn turn[6];
    double accel_out[3];      /* accelerations of the last step, compensated as modelled [g] */
} gyrocomp_state;

void gyrocomp_init(gyrocomp_state *s);
void gyrocomp_step(gyrocomp_state *s, double t, const double gyro[3], const double accel[3],
                   double temperature, double out[3]);

#endif
"""

_HELPERS = [
    "static inline void lag_coefficients(double step, double tau, double *a, double *b0, double *b1)",
    "{",
    "    double h = step / tau;",
    "    *a = exp(-h);",
    "    double g = -expm1(-h) / h;",
    "    *b0 = 1.0 - g;",
    "    *b1 = g - *a;",
    "}", "",
    "static inline double lag_update(gyrocomp_lag *l, double step, double u, double tau)",
    "{",
    "    if (!l->started) { l->started = 1; l->last_input = u; l->last_output = u; return u; }",
    "    double a, b0, b1;",
    "    lag_coefficients(step > 1.5 * PERIOD_S ? step : PERIOD_S, tau, &a, &b0, &b1);",
    "    double y = step > 1.5 * PERIOD_S ? a * l->last_output + b0 * u + b1 * l->last_input",
    "                                     : b0 * u + (a * l->last_output + b1 * l->last_input);",
    "    l->last_input = u;",
    "    l->last_output = y;",
    "    return y;",
    "}", "",
    "static inline void turn_update(gyrocomp_turn *s, double x, double thr)",
    "{",
    "    if (s->direction == 0) {",
    "        if (x < s->low) s->low = x;",
    "        if (x > s->high) s->high = x;",
    "        int up = x - s->low > thr, down = s->high - x > thr;",
    "        if (down) { s->direction = -1; s->extreme = s->low; }",
    "        else if (up) { s->direction = 1; s->extreme = s->high; }",
    "        return;",
    "    }",
    "    double running = s->direction == 1 ? (x > s->extreme ? x : s->extreme) : (x < s->extreme ? x : s->extreme);",
    "    double back = s->direction == 1 ? running - x : x - running;",
    "    if (back > thr) { s->turn = running; s->has_turn = 1; s->direction = -s->direction; s->extreme = x; }",
    "    else s->extreme = running;",
    "}", ""]


def _shape_code(k: int, ax: AxisCalibration) -> list[str]:
    """C statements setting `shape` for state slot k: the (lagged) temperature, its curve and hysteresis."""
    if ax.lag_time_constant_s > 0:
        lines = [f"    tm = lag_update(&s->lag[{k}], step, temperature, {c_number(ax.lag_time_constant_s)});"]
    else:
        lines = ["    tm = temperature;"]
    return lines + _temperature_code(k, ax.temperature) + _hysteresis_code(k, ax)


_SOLVE3 = [
    "/* v <- K^-1 v for a 3 x 3 K (row-major) by its adjugate; K is near the identity */",
    "static inline void solve3(const double k[9], double v[3])",
    "{",
    "    double c0 = k[4] * k[8] - k[5] * k[7], c1 = k[5] * k[6] - k[3] * k[8], c2 = k[3] * k[7] - k[4] * k[6];",
    "    double det = k[0] * c0 + k[1] * c1 + k[2] * c2;",
    "    double x = (c0 * v[0] + (k[2] * k[7] - k[1] * k[8]) * v[1] + (k[1] * k[5] - k[2] * k[4]) * v[2]) / det;",
    "    double y = (c1 * v[0] + (k[0] * k[8] - k[2] * k[6]) * v[1] + (k[2] * k[3] - k[0] * k[5]) * v[2]) / det;",
    "    double z = (c2 * v[0] + (k[1] * k[6] - k[0] * k[7]) * v[1] + (k[0] * k[4] - k[1] * k[3]) * v[2]) / det;",
    "    v[0] = x; v[1] = y; v[2] = z;",
    "}", ""]


def _triad_code(triad: TriadCalibration, vector: str, label: str) -> list[str]:
    """C statements correcting ``vector`` (a double[3]) by a triad: v = K(T)^-1 (v - bias), K(T) from the raw
    temperature, as :meth:`TriadCalibration.correct` does."""
    lines = [f"    {{   /* {label}: scale factor and misalignment ({triad.method}) */",
             f"        double k[9] = {c_array(np.ravel(triad.sensitivity))};"]
    for p, block in enumerate(triad.sensitivity_per_degc, start=1):
        lines += [f"        const double k{p}[9] = {c_array(np.ravel(block))};",
                  f"        double d{p} = pow(temperature - {c_number(triad.reference_degc)}, {p});",
                  f"        for (int i = 0; i < 9; ++i) k[i] += k{p}[i] * d{p};"]
    lines += [f"        {vector}[{i}] -= {c_number(b)};" for i, b in enumerate(triad.bias) if b != 0.0]
    return lines + [f"        solve3(k, {vector});", "    }"]


def _init_code(codes: dict) -> list[str]:
    body = ["void gyrocomp_init(gyrocomp_state *s)", "{",
            "    s->started = 0;", "    s->last_t = 0.0;",
            "    for (int j = 0; j < 3; ++j) s->accel_out[j] = 0.0;",
            "    for (int j = 0; j < 6; ++j) {",
            "        s->lag[j].started = 0; s->lag[j].last_input = 0.0; s->lag[j].last_output = 0.0;",
            "        s->turn[j].direction = 0; s->turn[j].has_turn = 0; s->turn[j].extreme = 0.0;",
            "        s->turn[j].turn = 0.0; s->turn[j].low = INFINITY; s->turn[j].high = -INFINITY;",
            "    }"]
    for code in codes.values():
        body += list(code.init)
    return body + ["}", ""]


def _accel_step_code(calibration: Calibration, accel_axes: dict) -> list[str]:
    """The accelerometer: temperature models into ``acc`` (what the g-sensitivity reads), then its triad into
    ``s->accel_out``."""
    body = []
    reference = calibration.accel_reference_degc
    for i, name in enumerate(ACCEL):
        ax = accel_axes.get(name)
        if ax is None or ax.temperature is None:
            continue
        body.append(f"    /* {name}: temperature error relative to {reference:g} degC */")
        body += _shape_code(3 + i, ax)
        at_reference = float(ax.temperature.shape(np.array([reference]))[0])
        body.append(f"    acc[{i}] -= shape - {c_number(at_reference)};")
    body.append("    for (int j = 0; j < 3; ++j) s->accel_out[j] = acc[j];")
    if calibration.accel_triad is not None:
        body += _triad_code(calibration.accel_triad, "s->accel_out", "accelerometer bias")
    return body


def _gyro_step_code(calibration: Calibration, axes: dict) -> list[str]:
    body = []
    for j, name in enumerate(AXES):
        ax = axes.get(name)
        if ax is None:
            continue
        body.append(f"    /* {name} */")
        g, q = ax.g_sensitivity_dps_per_g, ax.g_squared_dps_per_g2
        if g is not None or q is not None:
            g = g or (0.0, 0.0, 0.0)
            expr = f"acc[0] * {c_number(g[0])} + acc[1] * {c_number(g[1])} + acc[2] * {c_number(g[2])}"
            if q is not None:
                products = ("acc[0] * acc[0]", "acc[1] * acc[1]", "acc[2] * acc[2]",
                            "acc[0] * acc[1]", "acc[0] * acc[2]", "acc[1] * acc[2]")
                expr = f"({expr}) + (" + " + ".join(f"{p} * {c_number(c)}" for p, c in zip(products, q)) + ")"
            body.append(f"    out[{j}] -= {expr};")
        if ax.acceleration_network is not None:
            body.append(f"    out[{j}] -= anet{j}(0.0, acc) - anet{j}_ref;")
        if ax.temperature is not None:
            body += _shape_code(j, ax)
            body.append(f"    out[{j}] -= shape;")
        body.append(f"    out[{j}] -= {c_number(ax.mean_turn_on_bias_dps)};")
    if calibration.gyro_triad is not None:
        body += _triad_code(calibration.gyro_triad, "out", "gyro")
    return body


def c_sources(calibration: Calibration, *, rate_hz: float | None = None) -> dict[str, str]:
    """``{"gyrocomp.h": ..., "gyrocomp.c": ...}`` for the model; ``rate_hz`` [Hz] is needed with thermal lag."""
    axes = {name: ax for name, ax in calibration.axes.items() if name in AXES}
    accel_axes = {name: ax for name, ax in calibration.accel_axes.items() if name in ACCEL}
    if not axes and not accel_axes and calibration.gyro_triad is None and calibration.accel_triad is None:
        raise InputError("export: the model has none of gyro_x, gyro_y, gyro_z, accel_x, accel_y, accel_z")
    if any(ax.temperature_column != "temperature" for ax in axes.values()):
        raise InputError("C export: the model reads one temperature per axis; the C interface takes one")
    every = list(axes.values()) + list(accel_axes.values())
    if any(ax.lag_time_constant_s > 0 for ax in every) and not (rate_hz and rate_hz > 0):
        raise InputError("C export: the model has thermal lag; give the data's sample rate with rate_hz=")
    period = 1.0 / rate_hz if rate_hz else 0.0
    body = [f"/* gyrocomp model '{c_comment(calibration.model)}', generated by gyrocomp. */",
            "#include <math.h>", "#include \"gyrocomp.h\"", "",
            "static inline double clip(double x, double lo, double hi) { return x < lo ? lo : (x > hi ? hi : x); }", "",
            f"static const double PERIOD_S = {c_number(period)};", ""] + _HELPERS + _SOLVE3
    codes = {}  # C name -> the curve's code (functions and init statements; the step's come per axis)
    for j, name in enumerate(AXES + ACCEL):
        ax = axes.get(name) or accel_axes.get(name)
        if ax is not None and ax.temperature is not None:
            codes[f"net{j}"] = ax.temperature.c_code(f"net{j}")
        if ax is not None and ax.acceleration_network is not None:
            codes[f"anet{j}"] = ax.acceleration_network.c_code(f"anet{j}")
    for code in codes.values():
        body += list(code.functions)
    body += _init_code(codes)
    body += ["void gyrocomp_step(gyrocomp_state *s, double t, const double gyro[3], const double accel[3],",
             "                   double temperature, double out[3])", "{",
             "    double step = s->started ? t - s->last_t : 0.0;",
             "    s->started = 1;", "    s->last_t = t;",
             "    for (int j = 0; j < 3; ++j) out[j] = gyro[j];",
             "    double acc[3] = {accel[0], accel[1], accel[2]};",
             "    double tm, shape;", "    (void)step; (void)tm; (void)shape;"]
    body += _accel_step_code(calibration, accel_axes) + _gyro_step_code(calibration, axes) + ["}", ""]
    return {"gyrocomp.h": _HEADER.replace("{model}", f"'{c_comment(calibration.model)}'"),
            "gyrocomp.c": "\n".join(body)}


def write_c_sources(calibration: Calibration, folder: str | os.PathLike, *, rate_hz: float | None = None,
                    learner: LearnerSettings | None = None, with_learner: bool = True) -> list[Path]:
    """Write gyrocomp.h and gyrocomp.c (:func:`c_sources`) into ``folder`` (created if needed), with the online
    learner beside them (gyrocomp_learn.h and gyrocomp_learn.c, :func:`learner_c_sources` with ``learner``'s
    settings, the defaults when None) unless ``with_learner`` is false; all or none: a write that fails leaves the
    files there as they were. Returns the paths written."""
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise InputError(f"{folder}: the C export writes a folder (gyrocomp.h, gyrocomp.c); this is a file")
    sources = c_sources(calibration, rate_hz=rate_hz)
    if with_learner:
        sources.update(learner_c_sources(learner))
    created = not folder.exists()
    folder.mkdir(parents=True, exist_ok=True)
    try:
        return write_texts_atomic(folder, sources)
    except BaseException:
        if created:  # a failed export (a full disk) leaves no empty folder behind
            with contextlib.suppress(OSError):
                folder.rmdir()
        raise


def _write_c(calibration: Calibration, path: Path, options: ExportOptions) -> Exported:
    return Exported("c", tuple(write_c_sources(calibration, path, rate_hz=options.rate_hz, learner=options.learner)))


register(Exporter("c", "the whole model as C99: gyrocomp.h, gyrocomp.c, with the online learner beside them",
                  "a temperature from each axis's own sensor (the C interface takes one)", _write_c, folder=True))

__all__ = ["c_sources", "write_c_sources"]
