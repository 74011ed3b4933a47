"""Typed fit options: each field checked when made (errors name the field), fit_calibration's keywords checked the
same way (the plain forms of earlier releases refused with the typed form to write), the choices agree with the
fitting's own, and a fit with options equals the fit with the keywords they stand for."""

from __future__ import annotations

import warnings
from typing import get_args

import pytest

from gyrocomp.errors import InputError
from gyrocomp.fitting.gsensitivity import ACCELERATION_CHOICES
from gyrocomp.models.options import Acceleration, FitOptions, FoldChoice, Memory, Network, Polynomial
from gyrocomp.models.joint import fit_calibration
from gyrocomp.models.fit import fit_channels
from gyrocomp.models.pipelines import fit_pipeline
from gyrocomp.fitting.folds import FOLD_KINDS
from gyrocomp.fitting.thermal import HYSTERESIS_CHOICES
from gyrocomp.simulation import simulate


def test_the_literal_choices_are_the_fittings_own():
    assert set(get_args(Memory)) == set(HYSTERESIS_CHOICES)
    assert set(get_args(Acceleration)) == {"auto", *ACCELERATION_CHOICES}
    assert set(get_args(FoldChoice)) == set(FOLD_KINDS)


@pytest.mark.parametrize(
    "make, message",
    [
        (lambda: Polynomial(6), r"Polynomial.order: a whole number from 0 to 5, or 'auto'; got 6"),
        (lambda: Polynomial(True), r"Polynomial.order: .* got True"),
        (lambda: Network(hidden=(0,)), r"Network.hidden: 1 to 3 layers of 1..50 neurons, e.g. \(3,\); got \(0,\)"),
        (lambda: Network(hidden=(3, 3, 3, 3)), r"Network.hidden: 1 to 3 layers"),
        (lambda: Network(seed=1.5), r"Network.seed: a whole number, got 1.5"),
        (
            lambda: FitOptions(temperature=3),
            r"FitOptions.temperature: Polynomial\(order=...\), Curve\(family, size\), Network\(hidden=...\) or "
            r"None; got 3",
        ),
        (lambda: FitOptions(hysteresis="lagg"), r"FitOptions.hysteresis: 'lagg'; use one of auto, none, turning-point"),
        (lambda: FitOptions(hysteresis_order=4), r"FitOptions.hysteresis_order: 4; use one of auto, 1, 2, 3"),
        (lambda: FitOptions(acceleration="network"), r"FitOptions.acceleration: 'network'; use one of auto, none"),
        (lambda: FitOptions(folds="weeks"), r"FitOptions.folds: 'weeks'; use one of auto, runs, legs, blocks"),
        (lambda: FitOptions(bin_width_degc=0), r"FitOptions.bin_width_degc: a positive number of degC, got 0"),
        (lambda: FitOptions(static_min_duration_s=-1), r"FitOptions.static_min_duration_s: a positive number"),
        (lambda: FitOptions(hysteresis_band_degc=(80, 55)), r"FitOptions.hysteresis_band_degc: \(lo, hi\) in degC"),
        (lambda: FitOptions(hysteresis_band_degc="55,80"), r"FitOptions.hysteresis_band_degc: .* got '55,80'"),
        (lambda: FitOptions(hysteresis_band_degc=(55, None)), r"FitOptions.hysteresis_band_degc: .* got \(55, None\)"),
    ],
)
def test_a_bad_option_is_refused_naming_its_field(make, message):
    with pytest.raises(InputError, match=message):
        make()


@pytest.mark.parametrize("plain", ["auto", 3, "mlp", ("mlp", (5, 2))])
def test_fit_calibration_refuses_the_plain_temperature_forms_naming_the_typed_ones(plain):
    run = simulate("mti10", profile="chamber", rate_hz=1, duration_s=600, seed=1).recording
    with pytest.raises(
        InputError,
        match=r"temperature: Polynomial\(order=...\), Curve\(family, size\), Network\(hidden=...\) or None; got "
        r".*\(an order N is Polynomial\(N\), 'auto' is Polynomial\(\), 'mlp' is "
        r"Network\(\)\)",
    ):
        fit_calibration([run], temperature=plain)


@pytest.mark.parametrize(
    "keywords, message",
    [
        (dict(hysteresis="magic"), r"hysteresis: 'magic'; use one of auto, none"),
        (dict(acceleration="cube"), r"acceleration: 'cube'; use one of auto, none, matrix, matrix2"),
        (dict(static_min_duration_s=0), r"static_min_duration_s: a positive number of seconds, got 0"),
        (dict(hysteresis_band_degc=(80.0, 55.0)), r"hysteresis_band_degc: \(lo, hi\) in degC with lo < hi"),
        (dict(mlp_seed=3), r"unexpected keyword argument 'mlp_seed'"),
    ],
)
def test_fit_calibration_checks_its_keywords_as_the_options_do(keywords, message):
    run = simulate("mti10", profile="chamber", rate_hz=1, duration_s=600, seed=1).recording
    with pytest.raises((InputError, TypeError), match=message):
        fit_calibration([run], **keywords)


def test_a_network_keeps_its_seed_through_the_fit():
    runs = [simulate("mti10", profile="chamber", rate_hz=1, duration_s=1800, seed=s).recording for s in range(2)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_calibration(runs, temperature=Network((2,), seed=11), hysteresis="none", acceleration="none")
    assert cal.report.network.hidden == (2,) and cal.report.network.seed == 11


def test_a_fit_with_options_is_the_fit_with_their_keywords():
    runs = [simulate("mti10", profile="chamber", rate_hz=1, duration_s=3600, seed=s).recording for s in range(3)]
    options = FitOptions(temperature=Polynomial(2), hysteresis="none", acceleration="none")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        by_keywords = fit_calibration(runs, temperature=Polynomial(2), hysteresis="none", acceleration="none")
        typed = fit_calibration(runs, temperature=Polynomial(2), hysteresis="none", acceleration="none")
        by_options = fit_pipeline(runs, "joint", options)
        channels = fit_channels(runs, options=options)
    for cal in (typed, by_options, channels):
        assert cal.axes == by_keywords.axes
    assert all(ax.temperature.order == 2 for ax in by_keywords.axes.values())
    with pytest.raises(InputError, match="options: a FitOptions .gyrocomp.models.options., got dict"):
        fit_pipeline(runs, "joint", {"temperature": 2})
