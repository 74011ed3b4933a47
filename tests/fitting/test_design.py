"""The thermal design: one builder of the fit's columns, and each memory curve's offset equal to its columns times its
coefficients (what evaluates an effect also fits it)."""

import numpy as np
import pytest

from gyrocomp.curves.hysteresis import BranchCurve, HysteresisCurve, branch_columns, turning_point_columns
from gyrocomp.curves.polynomial import POLY_FAMILY
from gyrocomp.curves.play_bank import play_bank_columns
from gyrocomp.curves.turning_table import turning_table_columns
from gyrocomp.effects import find_turns
from gyrocomp.fitting.design import Terms, ThermalDesign


def _chamber_path(seed: int = 0) -> np.ndarray:
    """A chamber temperature [degC]: cold, hot, cold, half way up, with sensor noise (not a model of ours)."""
    rng = np.random.default_rng(seed)
    knots = np.interp(np.linspace(0, 3.5, 3000), [0, 1, 2, 3, 3.5], [-20.0, 70.0, -10.0, 60.0, 25.0])
    return knots + rng.normal(0.0, 0.02, knots.size)


def test_the_turning_point_curve_is_its_columns_times_its_coefficients():
    t = _chamber_path()
    turns = find_turns(t, 0.3)
    for band in (None, (10.0, 50.0)):
        curve = HysteresisCurve((2e-3, -4e-5, 3e-7), (-1e-3, 2e-5, 0.0), 0.3, band)
        x = turning_point_columns(t, turns, 3, band)
        assert x.shape == (t.size, 6)
        np.testing.assert_allclose(x @ np.r_[curve.descending, curve.ascending], curve.offset(t, turns), atol=1e-15)
    # scaled distances are the same columns divided by scale^j
    np.testing.assert_allclose(
        turning_point_columns(t, turns, 2, scale_degc=45.0) * 45.0 ** np.array([1, 2, 1, 2]),
        turning_point_columns(t, turns, 2),
        rtol=1e-12,
    )


def test_the_branch_curve_is_its_columns_times_its_coefficients():
    t = _chamber_path(1)
    turns = find_turns(t, 0.3)
    curve = BranchCurve((4e-3, -1e-3), 25.0, 45.0, 6.0, 0.3, -15.0, 65.0)
    x = branch_columns(t, turns, 6.0, 2, 25.0, 45.0, -15.0, 65.0)
    np.testing.assert_allclose(x @ np.asarray(curve.coefficients), curve.offset(t, turns), atol=1e-15)


def test_each_block_of_a_design_is_where_its_layout_says():
    t = _chamber_path(2)
    accel = np.random.default_rng(3).normal(0.0, 0.5, (t.size, 3))
    design = ThermalDesign(25.0, 45.0, 0.3, accel_cols=(0, 2), square_cols=(1,))
    every = Terms(
        shapes=((POLY_FAMILY, 3), ("table", 5)),
        turning_point_order=2,
        bands_degc=(None, (0.0, 40.0)),
        turning_table_knots_degc=((20.0, 40.0, 60.0), (30.0, 60.0)),
        branch_order=2,
        branch_widths_degc=(2.0, 6.0),
        play_half_widths_degc=((1.0, 4.0, 16.0),),
    )
    x = design.columns(t, accel, every)
    at = design.layout(every)
    assert x.shape == (t.size, design.width(every)) == (t.size, 3 + 5 + 2 * 4 + 2 * 3 + 2 * 2 + 2 * 2 + 3 + 3)
    turns = find_turns(t, 0.3)
    np.testing.assert_array_equal(x[:, at[("shape", "table", 5)]], design.basis("table").columns(t, 5))
    np.testing.assert_array_equal(
        x[:, at[("turning-point", (0.0, 40.0))]], turning_point_columns(t, turns, 2, (0.0, 40.0))
    )
    np.testing.assert_array_equal(
        x[:, at[("turning-table", (30.0, 60.0))]], turning_table_columns(t, turns, (30.0, 60.0))
    )
    np.testing.assert_array_equal(x[:, at[("branch", 6.0)]], branch_columns(t, turns, 6.0, 2, 25.0, 45.0))
    np.testing.assert_array_equal(x[:, at[("play-bank", (1.0, 4.0, 16.0))]], play_bank_columns(t, (1.0, 4.0, 16.0))[0])
    np.testing.assert_array_equal(
        x[:, at[("acceleration",)]], np.column_stack([accel[:, 0], accel[:, 2], accel[:, 1] ** 2])
    )
    # a candidate's own design is the same columns as its blocks in the design of every candidate
    one = Terms(
        shapes=((POLY_FAMILY, 3),),
        turning_point_order=2,
        bands_degc=((0.0, 40.0),),
        branch_order=2,
        branch_widths_degc=(6.0,),
    )
    picked = np.hstack(
        [
            x[:, at[k]]
            for k in [("shape", POLY_FAMILY, 3), ("turning-point", (0.0, 40.0)), ("branch", 6.0), ("acceleration",)]
        ]
    )
    np.testing.assert_array_equal(design.columns(t, accel, one), picked)


def test_a_design_without_terms_has_no_columns():
    design = ThermalDesign(25.0, 45.0, 0.3)
    assert design.columns(np.linspace(0, 50, 7), None, Terms(acceleration=False)).shape == (7, 0)
    assert design.layout(Terms()) == {("acceleration",): slice(0, 0)}
    with pytest.raises(KeyError):
        design.basis("no-such-family")
