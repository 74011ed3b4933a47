"""Any registered curve family asked for by name (Curve, --temperature NAME:N): checked against the registry,
offered to the model choice as asked (curve_candidates, the one place that knows what the automatic choice
tries), fitted, stored, applied and shown; a family registered for the test is offered too, so the tests check
the registry's behaviour rather than its contents."""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pytest

from gyrocomp import Calibration, Curve, FitOptions, Polynomial, apply, fit_calibration
from gyrocomp.curves.kinds import BASES
from gyrocomp.curves.lookup import LookupTableCurve
from gyrocomp.errors import InputError
from gyrocomp.models.options import MAX_CURVE_SIZE, curve_candidates
from gyrocomp.simulation import get_profile, simulate

from ..conftest import run


@pytest.mark.parametrize(
    "make, message",
    [
        (lambda: Curve("spline"), r"Curve.family: 'spline'; the registered curves are .*\btable\b"),
        (
            lambda: Curve("table", 0),
            rf"Curve.size: table takes a whole number from 1 to {MAX_CURVE_SIZE}, or 'auto'; "
            r"got 0",
        ),
        (lambda: Curve("table", MAX_CURVE_SIZE + 1), r"Curve.size: table takes a whole number"),
        (lambda: Curve("poly", 6), r"Curve.size: poly takes a whole number from 0 to 5"),
        (
            lambda: FitOptions(temperature=Curve("table", 8), hysteresis="lag"),
            r"FitOptions.hysteresis: table is fitted without lag or hysteresis; leave hysteresis='auto' or 'none'",
        ),
        (
            lambda: FitOptions(temperature=Curve("table"), target="px4"),
            r"FitOptions.target: px4 carries a polynomial of order 3 at most",
        ),
    ],
)
def test_a_curve_not_registered_or_of_a_size_it_has_not_is_refused(make, message):
    with pytest.raises(InputError, match=message):
        make()


def test_a_polynomial_asked_by_family_is_the_polynomial():
    assert FitOptions(temperature=Curve("poly", 3)).temperature == Polynomial(3)
    assert FitOptions(temperature=Curve("table", 8), hysteresis="auto").hysteresis == "none"


@dataclass(frozen=True)
class _Probe:
    name: ClassVar[str] = "probe"
    description: ClassVar[str] = "a family registered by the test"
    sizes: ClassVar[tuple[int, ...]] = (2, 5)


def test_what_each_temperature_option_offers_the_model_choice():
    BASES["probe"] = _Probe
    try:
        automatic = curve_candidates(Polynomial())
        assert automatic.orders == (0, 1, 2, 3, 4, 5) and automatic.do_no_harm
        assert set(automatic.others) == {
            (name, size) for name, basis in BASES.items() if name != "poly" for size in basis.sizes
        }
        assert ("probe", 2) in automatic.others and ("probe", 5) in automatic.others
        assert curve_candidates(Curve("probe")).others == (("probe", 2), ("probe", 5))
        assert curve_candidates(Polynomial(), "px4").others == () and curve_candidates(Polynomial(), "px4").orders == (
            0,
            1,
            2,
            3,
        )
    finally:
        BASES.pop("probe")
    asked = curve_candidates(Curve("table", 16))
    assert (asked.orders, asked.others, asked.do_no_harm) == ((), (("table", 16),), False)
    assert curve_candidates(Polynomial(3)) == type(asked)((3,), (), False)
    polys = curve_candidates(Curve("poly"))
    assert polys.others == () and polys.orders == (0, 1, 2, 3, 4, 5) and polys.do_no_harm


@pytest.fixture(scope="module")
def cycles():
    profile = get_profile("cycle", set_points_degc=(-10.0, 60.0), cycles=1)
    return [simulate("consumer", profile=profile, rate_hz=1.0, seed=s) for s in range(3)]


def test_a_lookup_table_asked_for_is_fitted_stored_and_applied(cycles, tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = fit_calibration([c.recording for c in cycles[:2]], temperature=Curve("table", 16))
    assert all(
        isinstance(ax.temperature, LookupTableCurve) and len(ax.temperature.values) == 17 for ax in model.axes.values()
    )
    model.save(tmp_path / "m.json")
    back = Calibration.load(tmp_path / "m.json")
    held_out = cycles[2]
    np.testing.assert_allclose(
        apply(back, held_out.recording).gyro_dps, apply(model, held_out.recording).gyro_dps, rtol=0, atol=1e-12
    )
    raw = held_out.recording.gyro_dps - held_out.truth.true_rate_dps
    left = apply(model, held_out.recording).gyro_dps - held_out.truth.true_rate_dps
    # the held-out run's drift about its own constant: the table takes most of it out
    assert np.all(np.std(left, axis=0) < 0.3 * np.std(raw, axis=0))


@pytest.mark.slow
def test_the_command_line_fits_a_table_asked_for_and_lists_every_registered_family(tmp_path):
    help_text = "".join(run("fit", "--help").stdout.split())  # as wrapped, without the wrapping

    def said(text):
        return "".join(text.split()) in help_text

    assert all(said(f"{name} or {name}:N") and said(BASES[name].description) for name in BASES)
    for k in range(3):
        assert (
            run(
                "simulate",
                "--preset",
                "consumer",
                "--profile",
                "cycle",
                "--rate",
                1,
                "--seed",
                k,
                "-o",
                tmp_path / f"run{k}.csv",
            ).returncode
            == 0
        )
    fitted = run(
        "fit", tmp_path / "run0.csv", tmp_path / "run1.csv", "-o", tmp_path / "m.json", "--temperature", "table:16"
    )
    assert fitted.returncode == 0, fitted.stderr
    assert "table:16" in fitted.stdout
    shown = run("show", tmp_path / "m.json").stdout
    assert shown.count("lookup table, 17 points") == 3, shown
    applied = run("apply", tmp_path / "m.json", tmp_path / "run2.csv", "-o", tmp_path / "c.csv")
    assert applied.returncode == 0, applied.stderr
    exported = run("export", tmp_path / "m.json", "-o", tmp_path / "c")
    assert exported.returncode == 0, exported.stderr
    assert "static const double v[17]" in (tmp_path / "c" / "gyrocomp.c").read_text()
    refused = run("fit", tmp_path / "run0.csv", "-o", tmp_path / "x.json", "--temperature", "table:99")
    assert refused.returncode == 2 and refused.stderr.strip() == (
        f"gyrocomp: error: --temperature: 'table:99': the size of table must be a whole number from 1 to "
        f"{MAX_CURVE_SIZE}"
    )
    assert not (tmp_path / "x.json").exists()
