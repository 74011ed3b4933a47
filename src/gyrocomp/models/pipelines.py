"""The thesis's cascades (section 2.8): named pipelines of stages, each fitted on the output of the one before
(:func:`fit_pipeline`); ``joint`` is the joint fit itself (:mod:`gyrocomp.models.joint`)."""

from __future__ import annotations

import dataclasses
import warnings
from typing import Literal, get_args


from ..calibration import AxisCalibration, Calibration
from ..calibration.compensate import apply
from ..errors import InputError, TemperatureRangeWarning
from ..runs.prepared import PreparedRun, prepare
from ..recording import Recording
from ..fitting.acceleration import fit_acceleration_network
from ..fitting.provenance import provenance
from ..curves.network import NETWORK_INPUTS
from .triads import SCALE_FACTOR_CHOICES, ScaleFactor, fit_accel_triad, fit_gyro_triad, spanning_poses  # noqa: F401
from .joint import checked_options, fit_joint
from .options import FitOptions, Network
from ..threads import single_threaded_blas


#: the named pipelines of ``gyrocomp fit --pipeline`` (thesis 2.8): stages left to right, each fitted on the
#: output of the one before; ``joint`` is the default joint least-squares fit, ``joint-mlp`` one network
#: reading the temperature and the three accelerations
Pipeline = Literal["joint", "poly>matrix", "matrix>poly", "mlp>matrix", "mlp>mlp-accel", "joint-mlp"]
PIPELINES: tuple[str, ...] = get_args(Pipeline)


def _residual_runs(calibration: Calibration, recordings: list[Recording]) -> list[Recording]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TemperatureRangeWarning)
        return [apply(calibration, rec) for rec in recordings]


def _chain(first: Calibration, second: Calibration, recordings: list[Recording], name: str) -> Calibration:
    """One calibration applying ``first`` then ``second``: the temperature part from whichever has it, G from
    whichever has it, and per-run constants that add up (the second stage saw the first's mean removed)."""
    axes = {}
    for axis, a in first.axes.items():
        b = second.axes[axis]
        temp_stage = a if a.temperature is not None or a.has_memory else b
        g_stage = a if a.needs_accel else b
        consts = tuple(a.mean_turn_on_bias_dps + cb for cb in b.turn_on_biases_dps)
        axes[axis] = AxisCalibration(
            temp_stage.temperature,
            consts,
            temp_stage.temperature_column,
            temp_stage.lag_time_constant_s,
            temp_stage.hysteresis,
            g_stage.g_sensitivity_dps_per_g,
            g_stage.g_squared_dps_per_g2,
            g_stage.acceleration_network,
        )
    report = {
        "pipeline": name,
        "stages": [first.fit_report, second.fit_report],
        "acceleration": (first.fit_report if first.has_acceleration else second.fit_report).get("acceleration", {}),
    }
    return Calibration(
        axes=axes, model=f"{name}: {first.model} > {second.model}", provenance=provenance(recordings), fit_report=report
    )


@single_threaded_blas
def fit_pipeline(
    recordings: list[Recording] | Recording, pipeline: Pipeline = "joint", options: FitOptions | None = None
) -> Calibration:
    """Fit a named pipeline (``PIPELINES``); ``options`` (:class:`gyrocomp.models.options.FitOptions`, default
    ``FitOptions()``) are :func:`fit_calibration`'s for the temperature stage.

    - ``joint``: temperature model, lag/hysteresis, G and run constants in one least-squares fit (the default);
    - ``poly>matrix``, ``mlp>matrix``: the temperature model (polynomial or network, with lag/hysteresis as
      chosen) first, then G on its output;
    - ``matrix>poly``: G first (no temperature model), then the temperature model on its output;
    - ``mlp>mlp-accel``: the temperature network first, then a network of the three accelerations on its
      output (thesis 2.7.2);
    - ``joint-mlp``: one network with the (lagged) temperature and the three accelerations as inputs.
    """
    return run_pipeline(
        prepare([recordings] if isinstance(recordings, Recording) else recordings), pipeline, checked_options(options)
    )


def run_pipeline(recordings: list[PreparedRun], pipeline: Pipeline, options: FitOptions) -> Calibration:
    """:func:`fit_pipeline` on runs prepared once, with checked options; a stage fitted on the output of the one
    before prepares that output once."""
    if pipeline not in PIPELINES:
        raise InputError(f"pipeline: {pipeline!r}; use one of {', '.join(PIPELINES)} (quote the > in a shell)")
    if pipeline == "joint":
        return fit_joint(recordings, options)
    accel_mode = "matrix" if options.acceleration in ("auto", "none") else options.acceleration
    min_static = options.static_min_duration_s
    # the network pipelines use the network asked for, else the thesis's 1-3-1
    network = options.temperature if isinstance(options.temperature, Network) else Network()
    if pipeline == "joint-mlp":
        cal = fit_joint(
            recordings, dataclasses.replace(options, temperature=network, acceleration=accel_mode), NETWORK_INPUTS
        )
        return dataclasses.replace(
            cal, model=f"joint-mlp: {cal.model}", fit_report={**cal.fit_report, "pipeline": pipeline}
        )
    temperature_first = dataclasses.replace(
        options, acceleration="none", temperature=network if pipeline.startswith("mlp") else options.temperature
    )
    if pipeline == "mlp>mlp-accel":
        first = fit_joint(recordings, temperature_first)
        second = fit_acceleration_network(
            _residual_runs(first, recordings), hidden=network.hidden, seed=network.seed, min_static=min_static
        )
        return _chain(first, second, recordings, pipeline)
    if pipeline in ("poly>matrix", "mlp>matrix"):
        first = fit_joint(recordings, temperature_first)
        second = fit_joint(
            prepare(_residual_runs(first, recordings)),
            FitOptions(temperature=None, acceleration=accel_mode, static_min_duration_s=min_static),
        )
        return _chain(first, second, recordings, pipeline)
    first = fit_joint(
        recordings, FitOptions(temperature=None, acceleration=accel_mode, static_min_duration_s=min_static)
    )
    second = fit_joint(prepare(_residual_runs(first, recordings)), temperature_first)
    return _chain(first, second, recordings, pipeline)


__all__ = ["PIPELINES", "Pipeline", "fit_pipeline", "run_pipeline"]
