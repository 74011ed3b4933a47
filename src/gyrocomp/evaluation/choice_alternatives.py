"""The model choice's own uncertainty: the candidates its held-out folds could not tell from the chosen one,
fitted in their own right, so that a forecast can say how far they part on a use profile and which run would
tell them apart (:mod:`gyrocomp.evaluation.drift_forecast`, :mod:`gyrocomp.evaluation.run_advice`)."""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..calibration.calibration import Calibration
from ..calibration.compensate import predict_error
from ..calibration.candidate import Candidate
from ..curves.polynomial import POLY_FAMILY
from ..errors import GyrocompError
from ..models.fit import fit
from ..models.options import Curve, FitOptions, Polynomial
from ..recording import ACCEL_AXES, Recording

#: the most alternatives an axis adds (its nearest forms): each is a fit of the runs
MOST_ALTERNATIVES = 2


@dataclass(frozen=True, eq=False)  # one fit is one alternative (compared and hashed by identity)
class Alternative:
    """A form of model the choice could not tell from the chosen one on ``axes``, fitted on the same runs.

    Attributes
    ----------
    form : str
        The candidate's label without its weighting (``poly:3 + lag``).
    axes : tuple of str
        The axes on which its held-out drift was within one standard error of the chosen candidate's.
    calibration : Calibration
        The runs fitted with that form.
    """

    form: str
    axes: tuple[str, ...]
    calibration: Calibration


def form_of(candidate: Candidate) -> str:
    """A candidate's label without its weighting (what a fit of that form is, whatever it weighs)."""
    return candidate.label.rsplit(" (", 1)[0]


def options_of(candidate: Candidate) -> FitOptions:
    """The fit options that ask for ``candidate``'s form (its curve, size and memory)."""
    curve = Polynomial(candidate.order) if candidate.curve == POLY_FAMILY else Curve(candidate.curve, candidate.order)
    order = candidate.hysteresis_order if candidate.hysteresis_order else "auto"
    return FitOptions(temperature=curve, hysteresis=candidate.memory, hysteresis_order=order)


def within_one_standard_error(calibration: Calibration, axis: str) -> list[tuple[float, Candidate]]:
    """(held-out drift, candidate) of the model choice's candidates for ``axis`` whose held-out drift was within
    one standard error of the chosen candidate's, the chosen one left out, the nearest first (none when the fit
    kept no choice)."""
    sel = calibration.report.selection.get(axis) if calibration.report is not None else None
    if sel is None or sel.chosen_drift is None:
        return []
    limit = sel.chosen_drift + (sel.chosen_standard_error or 0.0)
    close = [
        (c.mean_drift, c.candidate)
        for c in sel.candidates
        if c.candidate != sel.chosen and c.mean_drift is not None and c.mean_drift <= limit
    ]
    return sorted(close, key=lambda item: item[0])


def close_candidates(calibration: Calibration, axis: str) -> tuple[str, ...]:
    """The labels of :func:`within_one_standard_error`'s candidates, the nearest first.

    Parameters
    ----------
    calibration : Calibration
        The fitted model (its fit report holds the choice).
    axis : str
        The gyro axis.
    """
    return tuple(c.label for _, c in within_one_standard_error(calibration, axis))


def choice_alternatives(
    calibration: Calibration, recordings: Sequence[Recording], most: int = MOST_ALTERNATIVES
) -> tuple[Alternative, ...]:
    """The nearest ``most`` forms of each axis that the model choice could not tell from the axis's chosen one
    (held-out drift within the chosen candidate's standard error), each fitted on ``recordings`` once; a form the
    runs cannot be fitted with is left out.

    Parameters
    ----------
    calibration : Calibration
        The fitted model (its fit report holds the choice).
    recordings : sequence of Recording
        The runs it was fitted on.
    most : int
        The most alternatives an axis adds.

    Returns
    -------
    tuple of Alternative
        The nearest first.
    """
    report = calibration.report
    nearest: dict[str, tuple[float, Candidate, set]] = {}
    for axis, sel in (report.selection if report is not None else {}).items():
        forms: dict[str, tuple[float, Candidate]] = {}
        for drift, c in within_one_standard_error(calibration, axis):  # the nearest first: each form's nearest kept
            if form_of(c) != form_of(sel.chosen):
                forms.setdefault(form_of(c), (drift, c))
        for form, (drift, candidate) in list(forms.items())[:most]:
            gap = drift - sel.chosen_drift
            if form in nearest:
                gap, candidate = min(nearest[form][:2], (gap, candidate), key=lambda item: item[0])
            nearest[form] = (gap, candidate, nearest.get(form, (0.0, candidate, set()))[2] | {axis})
    out = []
    for form, (_, candidate, axes) in sorted(nearest.items(), key=lambda item: item[1][0]):
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                refit = fit(list(recordings), options_of(candidate))
        except GyrocompError:
            continue
        out.append(Alternative(form, tuple(sorted(axes)), refit))
    return tuple(out)


def predicted(calibration: Calibration, axis: str, time_s: np.ndarray, temperature_degc: np.ndarray) -> np.ndarray:
    """The error ``calibration`` predicts for gyro ``axis`` at rest (z up) at times ``time_s`` [s] and reported
    temperatures ``temperature_degc`` [degC] [deg/s]."""
    axes = tuple(calibration.axes)
    rec = Recording(
        time_s=np.asarray(time_s, dtype=float),
        gyro_dps=np.zeros((np.size(time_s), len(axes))),
        gyro_axes=axes,
        temperature_degc=np.asarray(temperature_degc, dtype=float),
        accel_g=np.tile([0.0, 0.0, 1.0], (np.size(time_s), 1)),
        accel_axes=ACCEL_AXES,
        source="use profile",
    )
    with warnings.catch_warnings():  # a profile past the range is the forecast's to say
        warnings.simplefilter("ignore")
        return predict_error(calibration, rec)[:, axes.index(axis)]


__all__ = [
    "Alternative",
    "MOST_ALTERNATIVES",
    "choice_alternatives",
    "close_candidates",
    "form_of",
    "options_of",
    "predicted",
    "within_one_standard_error",
]
