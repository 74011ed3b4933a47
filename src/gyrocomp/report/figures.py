"""The figures of a test report, as matplotlib figures (extra ``[plot]``, Agg backend), and written
atomically as PNG, SVG or PDF (from the suffix).

Every figure is computed on the full data and drawn from a decimated copy: a 24 h run at 100 Hz
(8.6 million samples) is drawn as a min/max envelope of ``DRAW_POINTS`` columns, and scatter plots
are binned or thinned, so the figures stay readable and fast.

- :func:`allan_plot`: Allan deviation of raw and compensated data, 68 % intervals, the -1/2, 0 and +1/2
  slope lines of the identified noise terms, the bias-instability points;
- :func:`temperature_plot`: bias against temperature, heating and cooling branches in their own colours,
  the fitted curve, the turning points, and the residual against temperature;
- :func:`timeseries_plot`: raw and compensated output against time with their moving averages;
- :func:`g_sensitivity_plot`: the offset of each static position against each accelerometer axis, with G.
"""

from __future__ import annotations

import os
import weakref

import numpy as np

from ..allan import BIAS_INSTABILITY_FACTOR
from ..effects import find_turns
from ..errors import InputError, MissingDependencyError, install_hint
from ..io.atomic import atomic_path
from ..measures.merit import moving_average, window_samples
from ..curves.hysteresis import turn_threshold_degc
from ..measures.noise import NoiseAnalysis

FIGURE_SUFFIXES = (".png", ".svg", ".pdf")


DRAW_POINTS = 2000
RAW_COLOUR, COMP_COLOUR = "tab:gray", "tab:blue"
HEATING_COLOUR, COOLING_COLOUR = "tab:red", "tab:blue"


def _pyplot():
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise MissingDependencyError(
            "plots need the optional package matplotlib; install it with: " + install_hint("plot")
        ) from None
    return plt


def require_matplotlib() -> None:
    """Raise the one-line :class:`MissingDependencyError` now, before long work, when matplotlib is missing."""
    _pyplot()


def save_figure(fig, path: str | os.PathLike, dpi: int = 110) -> None:
    """Write a figure atomically, in the format its suffix names, and close it."""
    suffix = check_figure_path(path)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=suffix[1:], dpi=dpi)
    _pyplot().close(fig)


def envelope(time_s: np.ndarray, values: np.ndarray, columns: int = DRAW_POINTS) -> tuple[np.ndarray, np.ndarray]:
    """A series cut to at most ``2 * columns`` points that keep its look: each column's minimum and maximum,
    in time order (for drawing only)."""
    n = values.size
    if n <= 2 * columns:
        return time_s, values
    edges = np.linspace(0, n, columns + 1).astype(int)
    starts = edges[:-1]
    lo = np.minimum.reduceat(values, starts)
    hi = np.maximum.reduceat(values, starts)
    mid_t = time_s[np.minimum((edges[:-1] + edges[1:]) // 2, n - 1)]
    t = np.repeat(mid_t, 2)
    v = np.column_stack([lo, hi]).reshape(-1)
    return t, v


def envelope_band(
    time_s: np.ndarray, values: np.ndarray, columns: int = DRAW_POINTS
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The band a series fills, cut to at most ``columns`` columns: each column's middle time, minimum and
    maximum (for drawing only: one polygon renders in a fraction of the time of the zigzag line through the same
    extremes)."""
    n = values.size
    if n <= 2 * columns:
        return time_s, values, values
    edges = np.linspace(0, n, columns + 1).astype(int)
    mid_t = time_s[np.minimum((edges[:-1] + edges[1:]) // 2, n - 1)]
    return mid_t, np.minimum.reduceat(values, edges[:-1]), np.maximum.reduceat(values, edges[:-1])


def _slope_lines(panel, terms, tau: np.ndarray, colour) -> None:
    """The identified terms' asymptotes: N/sqrt(tau), the bias-instability floor 0.664 B, K sqrt(tau/3)."""
    tau = np.asarray(tau, dtype=float)
    if terms.white_noise_density > 0:
        panel.plot(tau, terms.white_noise_density / np.sqrt(tau), ":", color=colour, lw=0.9)
    if terms.bias_instability > 0:
        panel.plot(tau, np.full(tau.size, terms.bias_instability * BIAS_INSTABILITY_FACTOR), ":", color=colour, lw=0.9)
    if terms.random_walk > 0:
        panel.plot(tau, terms.random_walk * np.sqrt(tau / 3.0), ":", color=colour, lw=0.9)


def check_figure_path(path) -> str:
    """The figure format of ``path`` from its suffix; InputError for one matplotlib is not asked to write."""
    suffix = os.path.splitext(str(path))[1].lower()
    if suffix not in FIGURE_SUFFIXES:
        raise InputError(f"{path}: figure suffix {suffix!r} is not one of {', '.join(FIGURE_SUFFIXES)}")
    return suffix


def allan_figure(analysis: NoiseAnalysis, path: str | os.PathLike) -> None:
    """Log-log Allan curves of every axis with their 68 % intervals, the fitted IEEE 952 model (dashed)
    and the bias-instability floor (dotted) at the integration time."""
    suffix = check_figure_path(path)
    plt = _pyplot()
    # a constant channel (all deviations zero) has nothing to draw on log axes
    drawable = {name: a for name, a in analysis.axes.items() if np.any(a.curve.deviation > 0)}
    if not drawable:
        raise InputError(f"{analysis.source}: every analysed channel is constant; nothing to plot")
    units = sorted({a.unit for a in drawable.values()})
    fig, panels = plt.subplots(1, len(units), figsize=(7.0 * len(units), 5.0), squeeze=False)
    for panel, unit in zip(panels[0], units):
        for name, a in drawable.items():
            if a.unit != unit:
                continue
            c = a.curve
            errors = np.vstack([c.deviation - c.ci_low, c.ci_high - c.deviation])
            line = panel.errorbar(
                c.tau, c.deviation, yerr=np.nan_to_num(errors), fmt="o-", ms=3, capsize=2, label=f"{name} ({c.kind})"
            )[0]
            terms = a.terms
            panel.plot(a.allan.tau, terms.model_deviation(a.allan.tau), "--", color=line.get_color(), lw=1)
            panel.plot(
                [terms.integration_time_s],
                [terms.bias_instability * BIAS_INSTABILITY_FACTOR],
                "v",
                color=line.get_color(),
            )
        panel.set_xscale("log")
        panel.set_yscale("log")
        panel.set_xlabel("averaging time tau [s]")
        panel.set_ylabel(f"deviation [{unit}]")
        panel.grid(True, which="both", alpha=0.3)
        panel.legend(fontsize="small")
    fig.suptitle(
        f"Allan deviation: {os.path.basename(analysis.source)}  "
        "(dashed: IEEE 952 fit; triangle: bias-instability floor)",
        fontsize="medium",
    )
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=suffix[1:], dpi=120)
    plt.close(fig)


def allan_plot(analyses: dict, title: str = "Allan deviation"):
    """Allan deviation of each labelled analysis (``{"raw": NoiseAnalysis, "compensated": ...}``), one panel
    per axis, with 68 % intervals, the slope lines (dotted) of the identified white noise (-1/2), bias
    instability (0) and rate random walk (+1/2), and the bias-instability points (triangles)."""
    plt = _pyplot()
    first = next(iter(analyses.values()))
    axes = [a for a in first.axes if np.any(first.axes[a].curve.deviation > 0)]
    if not axes:
        raise InputError(f"{first.source}: every analysed channel is constant; nothing to plot")
    fig, panels = plt.subplots(1, len(axes), figsize=(5.5 * len(axes), 4.4), squeeze=False)
    colours = {"raw": RAW_COLOUR, "compensated": COMP_COLOUR}
    for panel, axis in zip(panels[0], axes):
        unit = first.axes[axis].unit
        for i, (label, analysis) in enumerate(analyses.items()):
            a = analysis.axes[axis]
            c, colour = a.curve, colours.get(label, f"C{i + 2}")
            errors = np.vstack([c.deviation - c.ci_low, c.ci_high - c.deviation])
            b = a.terms.bias_instability
            b_text = (
                f"{b * 3600.0:.3g} deg/h"
                if unit == "deg/s"
                else f"{b * 1e6:.3g} ug"
                if unit == "g"
                else f"{b:.3g} {unit}"
            )
            panel.errorbar(
                c.tau,
                c.deviation,
                yerr=np.nan_to_num(errors),
                fmt="o-",
                ms=3,
                capsize=2,
                color=colour,
                label=f"{label}: B = {b_text} at {a.terms.integration_time_s:.3g} s",
            )
            _slope_lines(panel, a.terms, c.tau, colour)
            panel.plot(
                [a.terms.integration_time_s],
                [a.terms.bias_instability * BIAS_INSTABILITY_FACTOR],
                "v",
                color=colour,
                ms=9,
                mec="black",
            )
        panel.set_xscale("log")
        panel.set_yscale("log")
        panel.set_title(axis)
        panel.set_xlabel("averaging time tau [s]")
        panel.set_ylabel(f"Allan deviation [{unit}]")
        panel.grid(True, which="both", alpha=0.3)
        panel.legend(fontsize="small", loc="best")
    fig.suptitle(
        f"{title} (dotted: -1/2, 0, +1/2 slope lines of the identified terms; triangle: bias instability)",
        fontsize="medium",
    )
    fig.tight_layout()
    return fig


#: what is derived from the temperature arrays drawn lately, by identity: the axes of one run share its
#: temperature, so its turning points and its temperature bins are found once per run, not once per axis
_DERIVED: dict[int, tuple[weakref.ref, dict]] = {}


def _derived(temperature: np.ndarray) -> dict:
    hit = _DERIVED.get(id(temperature))
    if hit is not None and hit[0]() is temperature:
        return hit[1]
    for key in [k for k, (ref, _) in _DERIVED.items() if ref() is None]:
        del _DERIVED[key]
    found: dict = {}
    _DERIVED[id(temperature)] = (weakref.ref(temperature), found)
    return found


def _branches(temperature: np.ndarray) -> np.ndarray:
    """+1 where the temperature rises, -1 where it falls (robust turning points), 0 before the first move."""
    found = _derived(temperature)
    if "direction" not in found:
        found["direction"] = find_turns(temperature, turn_threshold_degc(temperature)).direction
    return found["direction"]


def _binned(t: np.ndarray, width: float, *series: np.ndarray) -> tuple[np.ndarray, ...]:
    """Mean temperature and mean of each series in temperature bins of ``width`` [degC] (the bins found once
    for all the series)."""
    if t.size == 0:
        return (t, *series)
    index = np.floor((t - t.min()) / width).astype(np.intp)
    counts = np.bincount(index)
    keep = counts > 0
    return tuple(np.bincount(index, y)[keep] / counts[keep] for y in (t, *series))


def _binned_by_branch(t: np.ndarray, width: float, *series: np.ndarray) -> dict:
    """For each branch of ``t`` (:func:`_branches`: 1 heating, -1 cooling, 0 before the first move): the mean
    temperature and the mean of each series in temperature bins of ``width`` [degC]. The bins of a temperature
    array are found once (every axis of a run shares them), and each series takes one pass of bincount (no copy
    of a branch's samples)."""
    if t.size == 0:
        return {}
    found = _derived(t)
    if found.get("width") != width:
        index = np.floor((t - t.min()) / width).astype(np.intp)
        bins = int(index.max()) + 1
        key = (_branches(t).astype(np.intp) + 1) * bins + index
        counts = np.bincount(key, minlength=3 * bins)
        found.update(width=width, bins=bins, key=key, counts=counts, t_sums=np.bincount(key, t, minlength=3 * bins))
    bins, key, counts = found["bins"], found["key"], found["counts"]
    sums = [found["t_sums"]] + [np.bincount(key, y, minlength=3 * bins) for y in series]
    out = {}
    for sign in (1, -1, 0):
        part = slice((sign + 1) * bins, (sign + 2) * bins)
        keep = counts[part] > 0
        if keep.any():
            out[sign] = tuple(s[part][keep] / counts[part][keep] for s in sums)
    return out


def _axis_temperature(rec, axis: str, accel: bool) -> np.ndarray:
    """The temperature [degC] an axis of ``rec`` is drawn against (an accelerometer's: the mean of the sensors')."""
    if rec.temperature_degc.ndim == 1:
        return rec.temperature_degc
    return rec.temperature_degc.mean(axis=1) if accel else rec.temperature_for(axis)


def _plot_turns(ax, direction: np.ndarray, t: np.ndarray, correction: np.ndarray, labelled: set) -> None:
    """Diamonds at the turning points of the temperature ``t`` [degC], at the model's ``correction``."""
    turns = np.flatnonzero(np.diff(direction) != 0) + 1
    turns = turns[direction[turns - 1] != 0]
    if turns.size:
        label = None if "turn" in labelled else "turning points"
        ax.plot(t[turns], correction[turns], "D", color="black", ms=6, mfc="gold", label=label)
        labelled.add("turn")


def temperature_plot(raw, compensated, axis: str, unit: str = "deg/s", title: str | None = None):
    """Bias against temperature of one axis of one or more runs: the raw output (binned by 0.25 % of the
    range on each branch, heating red, cooling blue), the model's correction (black), the turning points
    (diamonds); and, below, the residual after compensation against temperature.

    ``raw`` and ``compensated`` are lists of recordings (the same runs before and after); each run is
    shifted by the mean of its compensated output so runs with different turn-on biases line up."""
    plt = _pyplot()
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(8.0, 7.0), sharex=True, height_ratios=(3, 2))
    accel = axis.startswith("accel")
    labelled = set()
    for rec, comp in zip(raw, compensated):
        j = (rec.accel_axes if accel else rec.gyro_axes).index(axis)
        y_raw = (rec.accel_g if accel else rec.gyro_dps)[:, j]
        y_comp = (comp.accel_g if accel else comp.gyro_dps)[:, j]
        t = _axis_temperature(rec, axis, accel)
        offset = float(np.mean(y_comp))
        width = max(float(np.ptp(t)) / 400.0, 1e-3)
        direction = _branches(t)
        binned = _binned_by_branch(t, width, y_raw, y_comp)
        for sign, colour, name in (
            (1, HEATING_COLOUR, "heating"),
            (-1, COOLING_COLOUR, "cooling"),
            (0, "tab:gray", "before the first move"),
        ):
            if sign not in binned:
                continue
            tb, raw_mean, comp_mean = binned[sign]  # the correction's bin mean is their difference
            yb, yc, yr = raw_mean - offset, raw_mean - comp_mean, comp_mean - offset
            top.plot(tb, yb, ".", ms=3, color=colour, alpha=0.7, label=None if name in labelled else f"raw, {name}")
            labelled.add(name)
            top.plot(tb, yc, "-", color="black", lw=1.2, label=None if "model" in labelled else "model correction")
            labelled.add("model")
            bottom.plot(tb, yr, ".", ms=3, color=colour, alpha=0.7)
        _plot_turns(top, direction, t, y_raw - y_comp, labelled)
    top.set_ylabel(f"bias [{unit}]")
    top.set_title(title or f"{axis}: bias against temperature")
    top.grid(True, alpha=0.3)
    top.legend(fontsize="small", loc="best")
    bottom.axhline(0.0, color="black", lw=0.8)
    bottom.set_xlabel("temperature [degC]")
    bottom.set_ylabel(f"residual [{unit}]")
    bottom.set_title("after compensation", fontsize="medium")
    bottom.grid(True, alpha=0.3)
    fig.tight_layout()
    return fig


def timeseries_plot(raw, compensated, axis: str, window_s: float, unit: str = "deg/s", title: str | None = None):
    """Raw and compensated output of one axis against time (min/max envelope), with their moving averages
    over ``window_s`` [s] (computed on every sample, drawn decimated), and the temperature."""
    plt = _pyplot()
    accel = axis.startswith("accel")
    j = (raw.accel_axes if accel else raw.gyro_axes).index(axis)
    series = {
        "raw": (raw.accel_g if accel else raw.gyro_dps)[:, j],
        "compensated": (compensated.accel_g if accel else compensated.gyro_dps)[:, j],
    }
    hours = raw.duration_s > 3 * 3600
    scale, t_unit = (1 / 3600.0, "h") if hours else (1.0, "s")
    t = (raw.time_s - raw.time_s[0]) * scale
    w = window_samples(window_s, raw.rate_hz, raw.n_samples)
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(9.0, 6.5), sharex=True, height_ratios=(3, 1))
    for (label, y), colour in zip(series.items(), (RAW_COLOUR, COMP_COLOUR)):
        te, low, high = envelope_band(t, y)
        top.fill_between(te, low, high, color=colour, lw=0.5, alpha=0.35)
        smooth = moving_average(y, w)
        ts = t[w // 2 : w // 2 + smooth.size]
        ts, smooth = envelope(ts, smooth)
        top.plot(ts, smooth, "-", color=colour, lw=1.6, label=f"{label}, {window_s:.3g} s moving average")
    top.set_ylabel(f"{axis} [{unit}]")
    top.set_title(title or f"{axis}: raw and compensated output")
    top.grid(True, alpha=0.3)
    top.legend(fontsize="small", loc="best")
    if raw.temperature_degc is not None:
        temp = raw.die_temperature_degc
        bottom.plot(*envelope(t, temp), "-", color="tab:red", lw=1.0)
    bottom.set_ylabel("temperature [degC]")
    bottom.set_xlabel(f"time [{t_unit}]")
    bottom.grid(True, alpha=0.3)
    fig.tight_layout()
    return fig


def drift_panels(time_s: np.ndarray, errors: dict[str, np.ndarray], window_s: float, title: str, unit: str = "deg/s"):
    """The error each method leaves [unit] against time, one panel per method (``errors``: name to its series,
    about its mean), each its ``window_s`` [s] moving average; the panels after the first (raw) share one vertical
    scale, so that what compensation leaves is compared at its own size, not flattened by raw's."""
    plt = _pyplot()
    t = np.asarray(time_s, dtype=float)
    hours = t[-1] - t[0] > 3 * 3600
    scale, t_unit = (1 / 3600.0, "h") if hours else (1.0, "s")
    t = (t - t[0]) * scale
    period = float(np.median(np.diff(time_s))) if len(time_s) > 1 else 1.0
    w = window_samples(window_s, 1.0 / period, len(time_s))
    fig, panels = plt.subplots(len(errors), 1, figsize=(9.0, 1.8 * len(errors) + 0.8), sharex=True, squeeze=False)
    smooth = {name: moving_average(np.asarray(y, float) - np.mean(y), w) for name, y in errors.items()}
    shared = max((np.max(np.abs(v)) for name, v in list(smooth.items())[1:]), default=0.0) * 1.1 or 1.0
    for k, (panel, (name, y)) in enumerate(zip(panels[:, 0], smooth.items())):
        ts = t[w // 2 : w // 2 + y.size]
        panel.plot(*envelope(ts, y), "-", color=RAW_COLOUR if k == 0 else COMP_COLOUR, lw=1.2)
        rms = float(np.sqrt(np.mean(y**2)))
        panel.set_title(f"{name}: RMS {rms:.2g} {unit}", fontsize="small", loc="left")
        if k > 0:
            panel.set_ylim(-shared, shared)
        panel.set_ylabel(unit)
        panel.grid(True, alpha=0.3)
    panels[-1, 0].set_xlabel(f"time [{t_unit}]")
    fig.suptitle(f"{title}; {window_s:g} s moving average")
    fig.tight_layout()
    return fig


def g_sensitivity_plot(positions: dict, g_matrix: dict, title: str = "g-sensitivity"):
    """The offset of each static position against each accelerometer axis, with the fitted G.

    ``positions``: gyro axis -> (gravity [g] (m, 3), offset [deg/s] (m,)), the offsets with the temperature
    model and the run constants removed; ``g_matrix``: gyro axis -> (G row [deg/s/g], standard errors)."""
    plt = _pyplot()
    names = list(positions)
    fig, panels = plt.subplots(len(names), 3, figsize=(11.0, 3.0 * len(names)), squeeze=False)
    for r, axis in enumerate(names):
        gravity, offset = positions[axis]
        row, errors = g_matrix[axis]
        for k, accel_axis in enumerate(("accel_x", "accel_y", "accel_z")):
            panel = panels[r][k]
            x = gravity[:, k]
            others = offset - sum(row[i] * gravity[:, i] for i in range(3) if i != k)
            panel.plot(x, others, "o", ms=4, color="tab:blue", label="static positions")
            grid = np.linspace(min(-1.0, float(x.min())), max(1.0, float(x.max())), 3)
            se = "" if errors[k] is None else f" +- {errors[k]:.2g}"
            panel.plot(grid, row[k] * grid, "-", color="black", label=f"G = {row[k]:.3g}{se} deg/s/g")
            panel.set_xlabel(f"{accel_axis} [g]")
            panel.set_ylabel(f"{axis} offset [deg/s]")
            panel.grid(True, alpha=0.3)
            panel.legend(fontsize="x-small", loc="best")
    fig.suptitle(f"{title} (other axes' terms removed from each panel's points)", fontsize="medium")
    fig.tight_layout()
    return fig


def triad_plot(
    triads: dict,
    temperature_range_degc: tuple[float, float] | None,
    poses: dict,
    title: str = "Scale factor and misalignment",
):
    """Left: each triad's scale-factor error (diagonal of K(T) - I) [ppm] against temperature over
    ``temperature_range_degc`` [degC] (a constant K: flat lines), with its standard error band at the reference.
    Right: the residual of each still pose or turn before and after the calibration: ``poses`` maps a label
    (e.g. "accelerometer |a| - 1 g [mg]") to (before (m,), after (m,)).

    ``triads``: name ("gyro", "accelerometer") -> TriadCalibration."""
    plt = _pyplot()
    fig, (left, right) = plt.subplots(1, 2, figsize=(11.0, 3.6))
    lo, hi = temperature_range_degc or (20.0, 30.0)
    grid = np.linspace(lo, hi, 50)
    styles = {"gyro": "-", "accelerometer": "--"}
    for name, triad in triads.items():
        k = (
            triad.sensitivity_at(grid)
            if triad.sensitivity_per_degc
            else np.broadcast_to(np.asarray(triad.sensitivity, dtype=float), (grid.size, 3, 3))
        )
        se = np.diag(np.asarray(triad.sensitivity_stderr, dtype=float))
        for j, colour in enumerate(("tab:red", "tab:green", "tab:blue")):
            error_ppm = (k[:, j, j] - 1.0) * 1e6
            left.plot(grid, error_ppm, styles.get(name, "-"), color=colour, label=f"{name} {'xyz'[j]}")
            left.fill_between(grid, error_ppm - se[j] * 1e6, error_ppm + se[j] * 1e6, color=colour, alpha=0.15)
    left.set_xlabel("temperature [degC]")
    left.set_ylabel("scale-factor error [ppm]")
    left.grid(True, alpha=0.3)
    left.legend(fontsize="x-small", loc="best")
    for (label, (before, after)), marker, colour in zip(poses.items(), ("o", "s"), (COMP_COLOUR, "tab:orange")):
        index = np.arange(len(before))
        right.plot(index, before, marker, ms=4, color=RAW_COLOUR, mfc="none", label=f"{label}, raw")
        right.plot(index, after, marker, ms=4, color=colour, label=f"{label}, calibrated")
    right.set_xlabel("pose or turn (in recording order)")
    right.set_ylabel("residual (unit in the legend)")
    right.grid(True, alpha=0.3)
    if poses:
        right.legend(fontsize="x-small", loc="best")
    else:
        right.text(0.5, 0.5, "no still poses in these runs", ha="center", va="center", transform=right.transAxes)
    fig.suptitle(title, fontsize="medium")
    fig.tight_layout()
    return fig


def fleet_distributions(
    table,
    figure_names: tuple[str, ...],
    axes: tuple[str, ...],
    limits=None,
    title: str = "fleet: distribution of each figure",
):
    """One histogram per figure of a fleet table (every axis overlaid), the limits as dashed lines.

    Parameters
    ----------
    table : pandas.DataFrame
        :func:`gyrocomp.fleet.fleet_table` (the fitted units' rows are drawn).
    figure_names : tuple of str
        The per-axis figures to draw (``noise_density_dps_per_sqrt_hz``, ...).
    axes : tuple of str
        The gyro axes (``gyro_x``, ...).
    limits : Limits, optional
        Drawn where they bound a figure (``abs_max`` on both sides).
    """
    plt = _pyplot()
    names = [n for n in figure_names if any(f"{a}_{n}" in table.columns for a in axes)]
    columns = 4
    rows = max(1, (len(names) + columns - 1) // columns)
    fig, panels = plt.subplots(rows, columns, figsize=(4.2 * columns, 2.6 * rows), squeeze=False)
    ok = table[table["status"] == "ok"]
    for panel, name in zip(panels.flat, names):
        series = [(a, ok[f"{a}_{name}"].to_numpy(dtype=float)) for a in axes if f"{a}_{name}" in ok.columns]
        values = np.concatenate([v[np.isfinite(v)] for _, v in series]) if series else np.array([])
        if values.size == 0:
            panel.text(0.5, 0.5, "not measured", ha="center", va="center", transform=panel.transAxes)
        else:
            bins = np.histogram_bin_edges(values, bins=min(40, max(5, int(np.sqrt(values.size)))))
            for axis, v in series:
                panel.hist(v[np.isfinite(v)], bins=bins, histtype="step", label=axis.replace("gyro_", ""))
        for limit in limits.limits if limits is not None else ():
            if limit.figure != name:
                continue
            for bound in (limit.min, limit.max, limit.abs_max, -limit.abs_max if limit.abs_max is not None else None):
                if bound is not None:
                    panel.axvline(bound, color="k", ls="--", lw=0.9)
        panel.set_title(name, fontsize=8)
        panel.tick_params(labelsize=7)
    for panel in list(panels.flat)[len(names) :]:
        panel.set_visible(False)
    if names:
        panels.flat[0].legend(fontsize=7)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def stillness_plot(recording, detection, title: str | None = None):
    """A log's gyro rate against time [deg/s] (min/max envelope) with its still segments shaded, and its
    temperature [degC] on the right axis (:func:`gyrocomp.motion.stillness.detect_still`)."""
    plt = _pyplot()
    fig, panel = plt.subplots(figsize=(11, 3.6))
    t = recording.time_s - recording.time_s[0]
    for j, axis in enumerate(recording.gyro_axes):
        panel.plot(*envelope(t, recording.gyro_dps[:, j]), lw=0.6, label=axis)
    for k, segment in enumerate(detection.segments):
        panel.axvspan(
            segment.start_s - recording.time_s[0],
            segment.stop_s - recording.time_s[0],
            color="tab:green",
            alpha=0.18,
            lw=0,
            label="still" if k == 0 else None,
        )
    panel.set_xlabel("time [s]")
    panel.set_ylabel("rate [deg/s]")
    if recording.temperature_degc is not None:
        right = panel.twinx()
        right.plot(
            *_binned(t, max(float(t[-1]) / DRAW_POINTS, 1e-9), recording.temperature_degc), color="k", lw=0.9, ls="--"
        )  # means over short time bins: a whole-degree sensor's steps and noise averaged
        right.set_ylabel("temperature [degC] (dashed)")
    panel.legend(loc="upper left", fontsize=8, ncol=4)
    panel.set_title(title or f"still segments: {recording.source.rsplit('/', 1)[-1]}")
    fig.tight_layout()
    return fig
