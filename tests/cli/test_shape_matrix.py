"""Every command on a sample of the shapes of input (tools/shape_matrix.py: runs written from the physics, each
unit's runs through check, fit (the default, a rate term, a turning-point table, a bank of plays and a lookup
table), learn and its resume, show, apply,
evaluate, validate, report, export, split, noise, allan, convert, fleet fit, show, report and certificate): each
call succeeds with its invariant holding (apply equals the library's
apply; a certificate names its unit and verdict) or refuses in one line, never an internal error. The whole matrix
runs as the script; its table is in docs/reliability.md."""

from __future__ import annotations

import pytest

from ..conftest import run, shape_matrix

#: the sample the suite runs (the whole matrix takes half an hour): the certificate's unit of a cycle and one leg,
#: a constant temperature (refusals); epoch clocks are the bag tests' (tests/files/test_apply_bag.py)
SAMPLE = ("cycle and a leg", "constant temperature")


@pytest.mark.parametrize(
    "name", [pytest.param(n, marks=() if n == "cycle and a leg" else pytest.mark.slow) for n in SAMPLE]
)
def test_every_command_on_a_shape_succeeds_or_refuses_in_one_line(name, tmp_path):
    calls = shape_matrix.run_shape(name, shape_matrix.SHAPES[name], tmp_path, lambda *a: run("--no-config", *a))
    failures = [f"{c.command}: {c.detail}" for c in calls if c.result == "failure"]
    assert not failures, failures
    by = {c.command: c.result for c in calls}
    if name != "constant temperature":  # a temperature model needs a temperature that varies
        assert by["fit"] == by["apply"] == by["fleet certificate"] == "ok", calls
        assert by["fit rate+lag"] == by["fit table"] == by["fleet show"] == by["fleet report"] == "ok", calls
        assert by["fit turning-table"] == by["fit play-bank"] == "ok", calls


def test_the_matrix_covers_thirty_shapes_of_every_kind_the_issue_names():
    assert len(shape_matrix.SHAPES) >= 30
    for kind in ("heating only", "cooling only", "a hold only", "one cycle", "two cycles", "epoch ms", "epoch us"):
        assert kind in shape_matrix.SHAPES
