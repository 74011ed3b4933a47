"""The reference thesis's comparison of methods on one data set: raw, polynomial, network, each with
and without hysteresis compensation (M. Ali, METU, 2014, Tables 3.x and 4.4).

With two runs or more every run is compensated by models fitted on the other runs (leave one run
out), so no method is scored on the data it was fitted on; with one run the models are fitted and
scored on that run, as the thesis did, and the result says so.
"""

from __future__ import annotations

import warnings
from dataclasses import asdict, dataclass

import numpy as np

from .compensate import apply
from .errors import DataQualityWarning, InputError, TemperatureRangeWarning
from .metrics import default_window_s, evaluate_run
from .models.pipelines import fit_calibration
from .recording import Recording

#: the thesis's methods: name -> options of :func:`fit_calibration`
THESIS_METHODS: dict[str, dict] = {
    "polynomial": {"temperature": "auto", "hysteresis": "none"},
    "polynomial + hysteresis": {"temperature": "auto", "hysteresis": "turning-point"},
    "network": {"temperature": "mlp", "hysteresis": "none"},
    "network + hysteresis": {"temperature": "mlp", "hysteresis": "turning-point"},
}
#: the thesis's methods and gyrocomp's default (lag and/or hysteresis chosen by the data)
DEFAULT_METHODS: dict[str, dict] = {**THESIS_METHODS,
                                    "gyrocomp default (auto)": {"temperature": "auto", "hysteresis": "auto"}}


@dataclass(frozen=True)
class MethodRow:
    """One method on one axis, averaged over the scored runs.

    Attributes
    ----------
    bias_offset_dps : float
        Peak-to-peak of the moving-averaged output [deg/s].
    improvement : float
        Raw bias offset / this method's.
    bias_instability_deg_per_h : float
    integration_time_s : float
    """

    method: str
    axis: str
    bias_offset_dps: float
    improvement: float
    bias_instability_deg_per_h: float
    integration_time_s: float


@dataclass(frozen=True)
class MethodComparison:
    rows: list[MethodRow]
    how: str
    window_s: dict[str, float]

    def to_dict(self) -> dict:
        return {"how": self.how, "window_s": self.window_s, "rows": [asdict(r) for r in self.rows]}


def compare_methods(recordings: list[Recording], *, methods: dict[str, dict] | None = None,
                    window_s: float | None = None, hysteresis_band_degc: tuple[float, float] | None = None,
                    seed: int = 0) -> MethodComparison:
    """Score each method on the runs (see the module doc); the raw output is the first row of each axis.

    Parameters
    ----------
    recordings : list of Recording
        Runs of one sensor at rest through temperature changes.
    methods : dict, optional
        Name -> :func:`fit_calibration` options; default ``DEFAULT_METHODS``.
    window_s : float, optional
        Moving-average window [s]; default each run's raw Allan-minimum tau (the thesis's choice).
    hysteresis_band_degc : (lo, hi), optional
        Passed to the methods with hysteresis.
    """
    methods = DEFAULT_METHODS if methods is None else methods
    if not recordings:
        raise InputError("compare: give at least one run")
    n = len(recordings)
    scored: dict[str, list] = {name: [] for name in ("raw", *methods)}
    windows = {}
    for held in range(n):
        rec = recordings[held]
        train = [r for i, r in enumerate(recordings) if i != held] if n > 1 else [rec]
        w = window_s if window_s is not None else default_window_s(rec)
        windows[rec.source] = w
        for name, options in methods.items():
            opts = dict(options)
            if opts.get("hysteresis") not in (None, "none"):
                opts["hysteresis_band_degc"] = hysteresis_band_degc
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", TemperatureRangeWarning)
                warnings.simplefilter("ignore", DataQualityWarning)
                cal = fit_calibration(train, mlp_seed=seed, **opts)
                result = evaluate_run(rec, apply(cal, rec), window_s=w)
            scored[name].append(result)
            if name == next(iter(methods)):
                scored["raw"].append(result)
    rows = []
    for axis in recordings[0].gyro_axes:
        for name, results in scored.items():
            metrics = [r.axes[axis] for r in results]
            if name == "raw":
                offset = float(np.mean([m.bias_offset_raw_dps for m in metrics]))
                bi = float(np.mean([m.bias_instability_raw_dph for m in metrics]))
                tau = float(np.mean([m.integration_time_raw_s for m in metrics]))
                improvement = 1.0
            else:
                offset = float(np.mean([m.bias_offset_comp_dps for m in metrics]))
                bi = float(np.mean([m.bias_instability_comp_dph for m in metrics]))
                tau = float(np.mean([m.integration_time_comp_s for m in metrics]))
                raw = float(np.mean([m.bias_offset_raw_dps for m in metrics]))
                improvement = raw / offset if offset > 0 else float("inf")
            rows.append(MethodRow(name, axis, offset, improvement, bi, tau))
    how = ("leave one run out: each run compensated by models fitted on the other runs" if n > 1 else
           "one run: the models are fitted and scored on the same run, as in the thesis (optimistic)")
    return MethodComparison(rows, how, windows)


__all__ = ["DEFAULT_METHODS", "MethodComparison", "MethodRow", "THESIS_METHODS", "compare_methods"]
