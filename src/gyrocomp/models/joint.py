"""The gyro's joint fit: temperature curve, thermal memory, g-sensitivity and run constants in one least-squares
fit, what is left to choose chosen by held-out drift (:mod:`gyrocomp.fitting.selection`), a network trained on top
where asked for. :func:`fit_joint` takes runs prepared once; :func:`fit_calibration` is its keyword form."""

from __future__ import annotations

import dataclasses
import math
import warnings
from typing import Literal

import numpy as np

from ..calibration import AxisCalibration, Calibration
from ..effects import g_sensitivity_offset, thermal_lag
from ..errors import DataQualityWarning, InputError, ModelChoiceWarning, user_stacklevel
from ..calibration.fit_report import (
    THIN_FOLDS,
    AxisFit,
    GSensitivityReport,
    HysteresisReport,
    MemoryChoice,
    NetworkReport,
)
from ..measures.plausibility import calibration_concerns, temperature_span_concern
from ..measures.data_check import MIN_SPAN_DEGC
from ..measures.ramp_rate import separation_sentence
from ..runs.prepared import PreparedRun, fit_axes, prepare
from ..recording import Recording
from ..fitting.acceleration import acceleration_report, excited_columns, fit_g_sensitivity, turned_between_positions
from ..runs.prepared import one_temperature_column
from ..fitting.provenance import provenance
from ..fitting.temperature_bins import bin_width_for
from ..curves.hysteresis import heats_and_cools
from ..curves.network import NETWORK_BLOCK_S
from ..curves.play_bank import PLAY_BANK_SIZES
from ..curves.protocol import memory_offset
from ..curves.turning_table import TURNING_TABLE_SIZES
from ..fitting.network_model import NetworkTemperatureModel
from ..fitting.folds import FOLD_KINDS
from ..fitting.choice import TWO_FOLDS, select_axes, share_fold_lags
from ..fitting.axis_selection import AxisSelection
from ..fitting.selection import FOLD_RATE_SMOOTHINGS_S, prepare_axis
from ..fitting.polynomial_model import PolynomialTemperatureModel
from .triads import SCALE_FACTOR_CHOICES, ScaleFactor, fit_accel_triad, fit_gyro_triad, spanning_poses  # noqa: F401
from .options import (
    Acceleration,
    Curve,
    CurveCandidates,
    FitOptions,
    FoldChoice,
    Memory,
    Network,
    Polynomial,
    Target,
    curve_candidates,
)
from ..fitting.grid_search import LAG_EVIDENCE_CHI2
from ..fitting.thermal import CANDIDATES, MAX_BRANCH_ORDER, MAX_HYSTERESIS_ORDER, ThermalHysteresisModel, static_pieces
from ..threads import single_threaded_blas

#: the branch candidates' terms of the heating-cooling difference: a constant; a constant and a slope
BRANCH_ORDERS = tuple(range(1, MAX_BRANCH_ORDER + 1))


#: how the fit report names each kind of fold
FOLD_SELECTION = {"runs": "leave-one-run-out", "legs": "leave-one-leg-out", "blocks": "leave-one-block-out"}


def _fit_network(
    network: NetworkTemperatureModel,
    recordings: list[Recording],
    axis: str,
    lag_s: float,
    hysteresis,
    scaffold,
    bin_width_degc: float | None,
    g_row=None,
    g_squared=None,
    segments=None,
    inputs: tuple[str, ...] = ("temperature",),
):
    """Train the network on the block means of the runs, through the lag and without the hysteresis
    that the least-squares stage found (a cascade: the network replaces its curve, ``scaffold``, and takes the
    middle of its range as the reference temperature)."""
    width = bin_width_for([rec.temperature_for(axis) for rec in recordings], bin_width_degc)
    block_s = max(NETWORK_BLOCK_S, 1.0 / recordings[0].rate_hz)
    t_in, y_in, w_in, a_in = [], [], [], []
    for r, rec in enumerate(recordings):
        pieces = [slice(g.start, g.stop) for g in segments[r]] if segments and segments[r] else None
        blocks = PreparedRun.of(rec).block_means(axis, block_s, width, pieces)
        temp = blocks.temperature_degc
        if lag_s > 0:
            temp, _ = thermal_lag(blocks.time_s, temp, lag_s, period_s=block_s)
        value = blocks.value
        if hysteresis is not None:
            value = value - memory_offset(hysteresis, temp)[0]
        if g_row is not None:
            q = None if g_squared is None else np.asarray(g_squared)[None, :]
            value = value - g_sensitivity_offset(blocks.accel_g, np.asarray(g_row)[None, :], q)[:, 0]
        t_in.append(temp)
        y_in.append(value)
        w_in.append(blocks.weight)
        a_in.append(blocks.accel_g)
    needs_accel = any(name != "temperature" for name in inputs)
    if needs_accel and any(a is None for a in a_in):
        raise InputError("pipeline=joint-mlp: the runs need accel_x, accel_y and accel_z columns")
    t_ref_degc = 0.5 * (scaffold.t_min_degc + scaffold.t_max_degc)
    network.fit_blocks(
        axis, t_in, y_in, w_in, t_ref_degc=t_ref_degc, accel_g=a_in if needs_accel else None, inputs=inputs
    )
    return network.curves_[axis], network.turn_on_biases_[axis]


def _set_accel_columns(problem, acceleration: str, columns: tuple | None) -> tuple:
    """Give an axis's problem the excited acceleration columns (and squared columns for ``matrix2``): ``columns``
    as the first axis found them, or found from this axis's runs when None; returns them."""
    if any(r.accel_g is None for r in problem.runs):
        raise InputError(
            "acceleration: the runs need accel_x, accel_y and accel_z columns for a "
            "g-sensitivity fit; map them with columns= or fit with acceleration='none'"
        )
    if columns is None:
        accel_cols, square_cols, _ = excited_columns(
            [r.accel_g for r in problem.runs],
            [r.weight for r in problem.runs],
            squares=acceleration == "matrix2",
            warn=False,
        )
        columns = (accel_cols, square_cols)
    problem.accel_cols, problem.square_cols = columns
    return columns


def _axis_problems(recordings: list[Recording], acceleration: str, static_min_duration_s: float, **settings) -> dict:
    """Each gyro axis's selection problem (:func:`gyrocomp.fitting.selection.prepare_axis` with ``settings``), with
    the acceleration columns of ``acceleration`` and the static pieces of at least ``static_min_duration_s`` [s]."""
    _, pieces = static_pieces(recordings, static_min_duration_s, warn=False)  # the final fit says it
    columns = None
    problems = {}
    for axis in fit_axes(recordings):
        problem = prepare_axis(recordings, axis, pieces=pieces, **settings)
        if acceleration != "none":
            columns = _set_accel_columns(problem, acceleration, columns)
        problems[axis] = problem
    return problems


def select_models(
    recordings: list[Recording],
    *,
    orders: tuple[int, ...],
    memories: tuple[str, ...],
    hysteresis_orders: tuple[int, ...] = (1, 2, 3),
    acceleration: str = "none",
    static_min_duration_s: float = 10.0,
    bin_width_degc: float | None = None,
    run_folds: tuple[int, ...] | None = None,
    folds: str = "auto",
    shared_lag: bool = True,
    do_no_harm: bool = True,
    other_curves: tuple[tuple[str, int], ...] = (),
) -> dict[str, AxisSelection]:
    """Choose each gyro axis's model by held-out drift (:mod:`gyrocomp.fitting.selection`).

    Parameters
    ----------
    orders : tuple of int
        Polynomial orders to try (0: the run constant alone).
    memories : tuple of str
        Among ``none``, ``lag``, ``turning-point``, ``turning-point+lag``, ``turning-table``, ``turning-table+lag``,
        ``branch``, ``branch+lag``, ``play-bank``, ``play-bank+lag``, ``rate``, ``rate+lag``.
    hysteresis_orders : tuple of int
        Turning-point orders to try.
    acceleration : {"none", "matrix", "matrix2"}
        g-sensitivity columns fitted with every candidate.
    run_folds : tuple of int, optional
        The run of each recording (pieces of one run are held out together).
    folds : {"auto", "runs", "legs", "blocks"}
    shared_lag : bool
        With one temperature column, score every lag candidate at one lag per fold shared by the axes
        (:func:`gyrocomp.fitting.choice.share_fold_lags`), and let an axis whose folds cannot tell its model with
        and without the lag another axis chose take that lag (:func:`gyrocomp.fitting.choice.select_axes`).
    do_no_harm : bool
        Keep a temperature model only where it beats the run constant on the held-out folds
        (:func:`gyrocomp.fitting.scores.beats_constant`); False when the order was asked for.
    other_curves : tuple of (str, int)
        Curves of other families to score beside the polynomial's ``orders``: (name in
        :data:`gyrocomp.curves.protocol.BASES`, size) pairs (:func:`gyrocomp.models.options.curve_candidates`).
    """
    if folds not in FOLD_KINDS:
        raise InputError(f"folds: {folds!r}; use one of {', '.join(FOLD_KINDS)}")
    problems = _axis_problems(
        recordings,
        acceleration,
        static_min_duration_s,
        groups=run_folds,
        bin_width_degc=bin_width_degc,
        fold_kind=folds,
        max_order=max(orders, default=0),
        hysteresis_orders=hysteresis_orders,
        both_directions="none" in memories,
        branch_orders=BRANCH_ORDERS if any("branch" in m for m in memories) else (),
        other_curves=other_curves,
        rate_smoothings_s=FOLD_RATE_SMOOTHINGS_S if any("rate" in m for m in memories) else (),
        turning_table_sizes=TURNING_TABLE_SIZES if any("turning-table" in m for m in memories) else (),
        play_bank_sizes=PLAY_BANK_SIZES if any("play-bank" in m for m in memories) else (),
    )
    one_die = shared_lag and one_temperature_column(recordings)
    if one_die and any("lag" in m for m in memories):
        share_fold_lags(list(problems.values()), orders)
    return select_axes(problems, orders, memories, do_no_harm, one_die)


def _warn_at_one_rate(selections: dict[str, AxisSelection]) -> None:
    """Where the runs ramp at one rate and an axis's model carries a memory, say that one rate cannot check it."""
    first = next(iter(selections.values()))
    # every memory (a lag, a rate term, a memory of the turn) differs at another ramp rate from what one rate shows
    remembering = [f"{axis} {sel.chosen.label}" for axis, sel in selections.items() if sel.chosen.memory != "none"]
    if remembering and first.ramp_rates_degc_per_min and not first.rates_separate:
        warnings.warn(
            f"model choice: {separation_sentence(first.ramp_rates_degc_per_min)}; the choice of "
            + ", ".join(remembering)
            + " could not be checked at another rate",
            ModelChoiceWarning,
            stacklevel=user_stacklevel(),
        )


def _warn_about_choice(selections: dict[str, AxisSelection]) -> None:
    first = next(iter(selections.values()))
    across = {"runs": "runs", "legs": "heating and cooling legs", "blocks": "time blocks"}[first.fold_kind]
    if first.fold_note:
        warnings.warn(f"model choice: {first.fold_note}", ModelChoiceWarning, stacklevel=user_stacklevel())
    if first.validated and len(first.folds) < THIN_FOLDS:
        warnings.warn(
            f"model choice: only {len(first.folds)} {across} to hold out; the evidence for each axis's "
            f"choice is thin (more runs, or runs that heat and cool more than once, make it firmer)",
            ModelChoiceWarning,
            stacklevel=user_stacklevel(),
        )
    _warn_at_one_rate(selections)
    for axis, sel in selections.items():
        unit = sel.unit
        if sel.lag_from_unit:
            warnings.warn(
                f"{axis}: the held-out {across} cannot tell {sel.chosen.label} from the same without the lag "
                "the other axes found; the die's lag is kept",
                ModelChoiceWarning,
                stacklevel=user_stacklevel(),
            )
        if sel.branch_test is not None:
            warnings.warn(sel.branch_test.sentence(axis), ModelChoiceWarning, stacklevel=user_stacklevel())
        if not sel.validated:
            warnings.warn(
                f"{axis}: too little data to hold out {across}; {sel.chosen.label} fitted without validation",
                ModelChoiceWarning,
                stacklevel=user_stacklevel(),
            )
        elif not sel.generalizes:
            warnings.warn(
                f"{axis}: left with its constant only; {sel.decided_by or 'do no harm'} (best: {sel.best.label})",
                ModelChoiceWarning,
                stacklevel=user_stacklevel(),
            )
        elif len(sel.folds) == TWO_FOLDS:  # thin evidence: which rule chose, in one line
            above = (
                f" (its mean held-out drift, {sel.chosen_drift:.3g} {unit}, is above the constant's "
                f"{sel.raw_drift:.3g} {unit}, by less than the standard error of their difference over the two legs: the rule above kept it)"
                if sel.chosen_drift > sel.raw_drift
                else ""
            )
            warnings.warn(
                f"{axis}: {sel.chosen.label}; {sel.decided_by}{above}", ModelChoiceWarning, stacklevel=user_stacklevel()
            )
        elif sel.chosen_drift > sel.raw_drift:
            warnings.warn(
                f"{axis}: the chosen model ({sel.chosen.label}) leaves {sel.chosen_drift:.3g} {unit} of "
                f"held-out drift, more than the raw output's {sel.raw_drift:.3g} {unit}",
                ModelChoiceWarning,
                stacklevel=user_stacklevel(),
            )


def _selection_report(selections: dict[str, AxisSelection], thermal: ThermalHysteresisModel, mode: str) -> dict:
    """The hysteresis part of the fit report from the selection: per axis the memory chosen, its lag, and the best
    held-out drift of each memory at the chosen order and weighting [the axes' unit]."""
    kind = FOLD_SELECTION[next(iter(selections.values())).fold_kind]
    axes = {}
    for axis, sel in selections.items():
        c = sel.chosen
        by_memory = {}
        for s in sel.scores:
            same = s.candidate.order == c.order and s.candidate.weighting == c.weighting
            if same or (s.candidate.order == 0 and c.order == 0):
                m = s.candidate.memory
                if math.isfinite(s.mean_drift):
                    by_memory[m] = min(by_memory.get(m, s.mean_drift), s.mean_drift)
        axes[axis] = MemoryChoice(
            c.memory, c.hysteresis_order, thermal.lag_time_constants_s_[axis], c.order, c.weighting, by_memory
        )
    return HysteresisReport(mode, kind, axes, next(iter(selections.values())).unit).to_dict()


def _thermal_report(thermal: ThermalHysteresisModel, mode: str, unit: str) -> dict:
    """The hysteresis part of the fit report from the thermal model's own choice (a fixed order or memory)."""
    axes = {
        axis: MemoryChoice(
            memory,
            order,
            thermal.lag_time_constants_s_[axis],
            thermal.curves_[axis].order,
            None,
            {k: (None if math.isnan(v) else float(v)) for k, v in thermal.scores_[axis].items()},
            {int(o): float(v) for o, v in thermal.order_scores_.get(axis, {}).items()},
        )
        for axis, (memory, order) in thermal.memories_.items()
    }
    return HysteresisReport(mode, thermal.selection_, axes, unit).to_dict()


def _fit_selected(recordings: list[Recording], options: FitOptions, accel_mode: str):
    """Select by held-out drift among the curves the temperature option offers
    (:func:`gyrocomp.models.options.curve_candidates`) and the memories ``options`` allow, then fit each axis's
    chosen model on all runs."""
    offered = curve_candidates(options.temperature, options.target)
    memories = tuple(CANDIDATES) if options.hysteresis == "auto" else (options.hysteresis,)
    span = combined_span_degc(recordings)
    if offered.do_no_harm and span is not None and span < MIN_SPAN_DEGC:
        # over less than a degree a curve (and a memory of the temperature's path) follows the drift in time
        warnings.warn(
            f"{recordings[0].source}: the runs span {span:.3g} degC, less than {MIN_SPAN_DEGC:g} degC: a temperature "
            "curve over so little follows the drift in time, not the temperature; the automatic choice fits each "
            "run's constant alone (ask for a curve by name to fit one over this span anyway)",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )
        offered, memories = CurveCandidates((0,), (), True), ("none",)
    h_orders = (
        tuple(range(1, MAX_HYSTERESIS_ORDER + 1))
        if options.hysteresis_order == "auto"
        else (int(options.hysteresis_order),)
    )
    selections = select_models(
        recordings,
        orders=offered.orders,
        memories=memories,
        hysteresis_orders=h_orders,
        acceleration=accel_mode,
        static_min_duration_s=options.static_min_duration_s,
        bin_width_degc=options.bin_width_degc,
        run_folds=options.run_folds,
        folds=options.folds,
        do_no_harm=offered.do_no_harm,
        other_curves=offered.others,
    )
    _refuse_what_cannot_be_judged(recordings, selections)
    thermal = _fit_chosen(recordings, selections, options, accel_mode)
    unseen = {
        axis
        for axis, sel in selections.items()
        if sel.lag_from_unit and not thermal.lag_evidence_[axis] > LAG_EVIDENCE_CHI2
    }
    if unseen:
        # an axis that took the die's lag keeps it where its own data, all runs together, see it (a fit at the
        # die's lag apart from one at the bottom of the search); elsewhere it goes back to its own choice
        selections = {axis: sel.alone if axis in unseen else sel for axis, sel in selections.items()}
        thermal = _fit_chosen(recordings, selections, options, accel_mode)
    _warn_about_choice(selections)
    return selections, thermal


def combined_span_degc(recordings: list[Recording]) -> float | None:
    """The temperature range of all the runs together [degC] (highest minus lowest finite reading), None without a
    temperature."""
    temps = [np.asarray(r.temperature_degc, dtype=float).ravel() for r in recordings if r.temperature_degc is not None]
    finite = [t[np.isfinite(t)] for t in temps]
    finite = [t for t in finite if t.size]
    if not finite:
        return None
    return float(max(t.max() for t in finite) - min(t.min() for t in finite))


def _refuse_what_cannot_be_judged(recordings: list[Recording], selections: dict[str, AxisSelection]) -> None:
    """Refuse runs that neither span a temperature range nor hold enough data to hold any of it out: nothing
    could be fitted or validated there but the constants, and a model file of constants would pass for a
    calibration (a log of a few samples at one temperature, e.g. a truncated ULog)."""
    if any(sel.validated for sel in selections.values()) or temperature_span_concern(recordings) is None:
        return
    rows = sum(rec.n_samples for rec in recordings)
    span = max(float(np.ptp(rec.temperature_degc)) for rec in recordings)
    raise InputError(
        f"{recordings[0].source}: {rows} samples over {span:.3g} degC: too little to hold any of it "
        "out, and no temperature range to fit a curve over; a calibration needs runs over a temperature "
        "range (for the turn-on constants alone, fit with temperature=None)"
    )


def _fit_chosen(
    recordings: list[Recording], selections: dict[str, AxisSelection], options: FitOptions, accel_mode: str
) -> ThermalHysteresisModel:
    """Each axis's chosen model (``selections``) fitted on all the runs."""
    chosen = {axis: sel.chosen for axis, sel in selections.items()}
    return ThermalHysteresisModel(
        order={a: c.order for a, c in chosen.items()},
        hysteresis={a: c.memory for a, c in chosen.items()},
        hysteresis_order={a: c.hysteresis_order for a, c in chosen.items()},
        weighting={a: c.weighting for a, c in chosen.items()},
        band_degc={a: selections[a].band_degc if c.band else None for a, c in chosen.items()},
        branch_order={a: c.branch for a, c in chosen.items()},
        turning_table_size={a: c.turning_table for a, c in chosen.items()},
        play_bank_size={a: c.plays for a, c in chosen.items()},
        curve={a: c.curve for a, c in chosen.items()},
        bin_width_degc=options.bin_width_degc,
        acceleration=accel_mode,
        static_min_duration_s=options.static_min_duration_s,
        refine_band=True,
        extended=True,
    ).fit(recordings)


@single_threaded_blas
def fit_calibration(
    recordings: list[Recording] | Recording,
    *,
    temperature: Polynomial | Curve | Network | None = Polynomial(),
    bin_width_degc: float | None = None,
    hysteresis: Memory = "auto",
    hysteresis_order: int | Literal["auto"] = "auto",
    hysteresis_band_degc: tuple[float, float] | None = None,
    acceleration: Acceleration = "auto",
    static_min_duration_s: float = 10.0,
    network_inputs: tuple[str, ...] = ("temperature",),
    run_folds: tuple[int, ...] | None = None,
    folds: FoldChoice = "auto",
    target: Target = "model",
) -> Calibration:
    """Fit a compensation on calibration runs (each one power-on, the gyro at rest), the options as keyword
    arguments: the gyro's ``joint`` fit of :func:`gyrocomp.fit` (``gyrocomp.models.fit.fit``) with those options
    as a :class:`~gyrocomp.models.options.FitOptions`, which documents each one (``temperature``, the curve and its
    order; ``hysteresis``, ``hysteresis_order`` and ``hysteresis_band_degc``, the thermal memory; ``acceleration``,
    the g-sensitivity; ``bin_width_degc``, ``static_min_duration_s``, ``run_folds``, ``folds``; ``target``, the
    model or what a firmware carries) and checks them.

    ``network_inputs``, which only this call takes: what a network (``temperature=Network()``) reads, the
    temperature, or also ``accel_x``, ``accel_y``, ``accel_z`` (the joint network of the ``joint-mlp`` pipeline,
    which then fits no separate G).

    What is left to choose is chosen by held-out drift (:mod:`gyrocomp.fitting.selection`: the simplest within one
    standard error of the best); an axis no temperature model helps gets none, with a
    :class:`~gyrocomp.errors.ModelChoiceWarning`.
    """
    options = FitOptions(
        temperature=temperature,
        bin_width_degc=bin_width_degc,
        hysteresis=hysteresis,
        hysteresis_order=hysteresis_order,
        hysteresis_band_degc=hysteresis_band_degc,
        acceleration=acceleration,
        static_min_duration_s=static_min_duration_s,
        run_folds=run_folds,
        folds=folds,
        target=target,
    )
    return fit_joint(
        prepare([recordings] if isinstance(recordings, Recording) else recordings or ()), options, network_inputs
    )


def _network_report(network: NetworkTemperatureModel, unit: str) -> dict:
    """The fit report's entry for a trained network (its validation errors in ``unit``)."""
    return NetworkReport(
        tuple(network.hidden),
        network.restarts,
        network.seed,
        "Levenberg-Marquardt, early stopping on 20 % held-out segments",
        {a: tuple(network.validation_rmse_[a]) for a in network.curves_},
        {a: network.epochs_[a] for a in network.curves_},
        unit,
    ).to_dict()


def fit_joint(
    recordings: list[PreparedRun], options: FitOptions, network_inputs: tuple[str, ...] = ("temperature",)
) -> Calibration:
    """The joint fit of prepared runs (:func:`gyrocomp.runs.prepared.prepare`) with checked options: the route (no
    temperature model, a selection by held-out drift, one binned fit), then each axis's frozen result, the network
    trained on top where asked for.

    Parameters
    ----------
    recordings : list of PreparedRun
        The runs, prepared once by the entry point [s, deg/s, g, degC].
    options : FitOptions
        What to fit.
    network_inputs : tuple of str
        What a network reads: ``temperature``, and ``accel_x``, ``accel_y``, ``accel_z`` for the joint network.
    """
    spec = options.temperature
    _check_fit_inputs(recordings, spec)
    if spec is None:
        return _fit_without_temperature(recordings, options.acceleration, options.static_min_duration_s)
    # a network keeps the polynomial stage with its order chosen: it still finds lag and hysteresis for the network
    order = spec.order if isinstance(spec, Polynomial) else "auto"  # a Curve is chosen among what it offers
    accel_mode = options.acceleration
    if accel_mode == "auto":
        accel_mode = "matrix" if turned_between_positions(recordings, options.static_min_duration_s) else "none"
    selections, model, thermal = None, None, None
    if options.hysteresis_band_degc is None and (order == "auto" or options.hysteresis == "auto"):
        selections, thermal = _fit_selected(recordings, options, accel_mode)
    else:
        model, thermal = _fit_binned(recordings, order, options, accel_mode)
    unit = recordings[0].unit_of(fit_axes(recordings)[0])
    report = _report_of_choice(selections, model, thermal, options.hysteresis, options.acceleration, accel_mode, unit)
    network = NetworkTemperatureModel(hidden=spec.hidden, seed=spec.seed) if isinstance(spec, Network) else None
    axes = {}
    for axis in fit_axes(recordings):
        axes[axis], report["axes"][axis] = _axis_calibration(
            axis, recordings, selections, model, thermal, network, accel_mode, options.bin_width_degc, network_inputs
        )
    if network is not None:
        report["temperature"] = "mlp"
        report["network"] = _network_report(network, unit)
    name = _model_name(
        axes, network, network_inputs, spec.size if isinstance(spec, Curve) else order, thermal, accel_mode
    )
    if options.target != "model":  # what the firmware computes: the curve held at its range's edges (it clamps)
        axes = {
            a: dataclasses.replace(ax, temperature=ax.temperature.clamped()) if ax.temperature is not None else ax
            for a, ax in axes.items()
        }
        report["target"] = options.target
        name += f" for {options.target}"
    if PreparedRun.of(recordings[0]).channel == "accel":
        return _accelerometer_calibration(axes, name, provenance(recordings), report)
    return Calibration(axes=axes, model=name, provenance=provenance(recordings), fit_report=report)


def checked_options(options: FitOptions | None) -> FitOptions:
    """``options``, or ``FitOptions()`` for None; anything else is refused naming the type."""
    if options is None:
        return FitOptions()
    if not isinstance(options, FitOptions):
        raise InputError(f"options: a FitOptions (gyrocomp.models.options), got {type(options).__name__}")
    return options


def _accelerometer_calibration(axes: dict[str, AxisCalibration], name: str, source: dict, report: dict) -> Calibration:
    """The accelerometer's axes as a calibration: relative to the middle of the calibrated temperature range
    (``accel_reference_degc``), since at rest the accelerometer's constant cannot be told from gravity."""
    curves = [ax.temperature for ax in axes.values() if ax.temperature is not None]
    reference = 0.5 * (min(c.t_min_degc for c in curves) + max(c.t_max_degc for c in curves)) if curves else None
    return Calibration(
        axes={}, model=name, provenance=source, fit_report=report, accel_axes=axes, accel_reference_degc=reference
    )


def _check_fit_inputs(recordings: list[Recording], spec: Polynomial | Curve | Network | None) -> None:
    """Refuse what cannot be fitted; warn about what is probably not calibration data."""
    if not recordings:
        raise InputError("fit: give at least one calibration run")
    concerns = [c for rec in recordings for c in calibration_concerns(rec)]
    if isinstance(spec, (Network, Curve)) or (isinstance(spec, Polynomial) and spec.order not in ("auto", 0)):
        concerns.append(temperature_span_concern(recordings))  # a curve asked for
    for concern in filter(None, concerns):
        warnings.warn(concern.warning(), stacklevel=user_stacklevel())
    if spec is not None:
        for rec in recordings:
            if rec.temperature_degc is None:
                raise InputError(
                    f"{rec.source}: no temperature column; a temperature model needs one "
                    "(map it with columns={'temperature': 'NAME'}, or fit with temperature=None)"
                )


def _fit_without_temperature(recordings: list[Recording], acceleration: str, static_min_duration_s: float):
    """G alone (when the runs turn between positions or it is asked for), else the run constants alone."""
    if acceleration != "none" and (
        acceleration != "auto" or turned_between_positions(recordings, static_min_duration_s)
    ):
        return fit_g_sensitivity(
            recordings, "matrix" if acceleration == "auto" else acceleration, static_min_duration_s
        )
    axes = {
        axis: AxisCalibration(None, tuple(float(rec.signal(axis).mean()) for rec in recordings))
        for axis in fit_axes(recordings)
    }
    return Calibration(axes=axes, model="none", provenance=provenance(recordings), fit_report={"temperature": None})


def _fit_binned(recordings: list[Recording], order: int | str, options: FitOptions, accel_mode: str):
    """The earlier path (a fixed band, or a fixed order and memory): the binned polynomial of ``order`` (or
    "auto"), then lag, hysteresis and G on top where asked for or where the runs heat and cool."""
    model = PolynomialTemperatureModel(order=order, bin_width_degc=options.bin_width_degc, folds=options.run_folds).fit(
        recordings
    )
    mode = options.hysteresis
    if mode == "auto" and not any(heats_and_cools(recordings, a) for a in fit_axes(recordings)):
        mode = "none"
    thermal = None
    if mode != "none" or accel_mode != "none":
        orders = {axis: curve.order for axis, curve in model.curves_.items()}
        thermal = ThermalHysteresisModel(
            order=orders,
            hysteresis=mode,
            hysteresis_order=options.hysteresis_order,
            band_degc=options.hysteresis_band_degc,
            bin_width_degc=options.bin_width_degc,
            reselect_order=order == "auto",
            acceleration=accel_mode,
            static_min_duration_s=options.static_min_duration_s,
        ).fit(recordings)
    return model, thermal


def _report_of_choice(
    selections, model, thermal, hysteresis: str, acceleration: str, accel_mode: str, unit: str
) -> dict:
    """The fit report's account of what was chosen and how (the axes are filled in after)."""
    report = {
        "temperature": "polynomial",
        "axes": {},
        "order_selection": FOLD_SELECTION[next(iter(selections.values())).fold_kind]
        if selections
        else model.selection_,
    }
    if selections is not None:
        report["selection"] = {axis: sel.to_dict() for axis, sel in selections.items()}
        report["hysteresis"] = _selection_report(selections, thermal, hysteresis)
    elif thermal is not None:
        report["hysteresis"] = _thermal_report(thermal, hysteresis, unit)
    else:
        report["hysteresis"] = HysteresisReport(
            hysteresis, "none: the runs do not both heat and cool" if hysteresis == "auto" else "none", {}
        ).to_dict()
    if accel_mode != "none":
        report["acceleration"] = acceleration_report(thermal, accel_mode)
    else:
        report["acceleration"] = GSensitivityReport(
            "none",
            "the runs do not turn the unit between positions" if acceleration == "auto" else "not asked for",
            (),
            (),
            {},
        ).to_dict()
    return report


def _thermal_terms(thermal, axis: str, accel_mode: str) -> tuple:
    """An axis's lag [s], hysteresis, g-sensitivity row [deg/s/g] and squared row [deg/s/g^2] from the thermal
    fit (``None``: lag 0 and no other term)."""
    lag, hyst, g_row, g_sq = 0.0, None, None, None
    if thermal is not None:
        lag, hyst = thermal.lag_time_constants_s_[axis], thermal.hysteresis_[axis]
        if accel_mode != "none" and thermal.excited_axes_:
            g_row = tuple(float(v) for v in thermal.g_sensitivity_dps_per_g_[axis])
            if accel_mode == "matrix2":
                g_sq = tuple(float(v) for v in thermal.g_squared_dps_per_g2_[axis])
    return lag, hyst, g_row, g_sq


def _axis_calibration(
    axis: str,
    recordings: list[Recording],
    selections,
    model,
    thermal,
    network,
    accel_mode: str,
    bin_width_degc,
    network_inputs: tuple[str, ...],
) -> tuple[AxisCalibration, dict]:
    """One axis's frozen result from the fitted models (the network trained on top when asked for), and its
    entry in the fit report."""
    curve, consts = (
        (thermal.curves_[axis], thermal.turn_on_biases_[axis])
        if thermal is not None
        else (model.curves_[axis], model.turn_on_biases_[axis])
    )
    lag, hyst, g_row, g_sq = _thermal_terms(thermal, axis, accel_mode)
    if network is not None:
        joint = network_inputs != ("temperature",)
        curve, consts = _fit_network(
            network,
            recordings,
            axis,
            lag,
            hyst,
            curve,
            bin_width_degc,
            None if joint else g_row,
            None if joint else g_sq,
            thermal.segments_ if thermal is not None else None,
            network_inputs,
        )
        if joint:  # the network reads the accelerations itself: the least-squares G was only a scaffold
            g_row = g_sq = None
    keep_curve = curve if selections is None or selections[axis].generalizes or network is not None else None
    result = AxisCalibration(
        keep_curve,
        tuple(float(c) for c in consts),
        recordings[0].temperature_column_for(axis),
        lag,
        hyst,
        g_row,
        g_sq,
        unit=recordings[0].unit_of(axis),
        rate_term=thermal.rate_terms_.get(axis) if thermal is not None else None,
    )
    fit_rms = None
    if network is not None:
        fit_rms = network.train_rmse_[axis]
    elif model is not None and thermal is None:
        fit_rms = model.fit_rms_[axis]
    scores = {} if model is None else dict(model.scores_[axis])
    entry = AxisFit(curve.order, curve.t_min_degc, curve.t_max_degc, fit_rms, result.unit, scores)
    return result, entry.to_dict()


def _model_name(
    axes: dict[str, AxisCalibration], network, network_inputs, order: int | str, thermal, accel_mode: str
) -> str:
    """The short name of the fitted model, e.g. ``poly:2/3 (auto) + lag + g-sensitivity``."""
    if network is not None:
        name = f"mlp:{len(network_inputs)}-" + "-".join(map(str, network.hidden)) + "-1"
    else:
        labels = {ax.temperature.label if ax.temperature is not None else "poly:0" for ax in axes.values()}
        orders = sorted(int(label[5:]) for label in labels if label.startswith("poly:"))
        others = sorted(label for label in labels if not label.startswith("poly:"))
        name = "/".join((["poly:" + "/".join(map(str, orders))] if orders else []) + others)
        if order == "auto":
            name += " (auto)"
    if thermal is not None:
        extras = sorted({memory for memory, _ in thermal.memories_.values()} - {"none"})
        if extras:
            name += " + " + "/".join(extras)
        if any(ax.g_sensitivity_dps_per_g is not None for ax in axes.values()):
            name += " + g-sensitivity" + (" (g x g)" if accel_mode == "matrix2" else "")
    return name


__all__ = ["BRANCH_ORDERS", "FOLD_SELECTION", "checked_options", "fit_calibration", "fit_joint", "select_models"]
