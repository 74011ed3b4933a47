"""`gyrocomp validate`, run through the real entry point in a subprocess."""

import pytest
import json
from pathlib import Path

from ..conftest import run


@pytest.mark.slow
def test_validate_prints_every_method_and_json_holds_the_folds(workdir):
    runs = sorted(str(p) for p in Path(workdir).glob("run*.csv"))[:3]
    out = run("validate", *runs, "--json")
    assert out.returncode == 0, out.stderr
    result = json.loads(out.stdout)
    assert result["fold_kind"] == "runs" and len(result["folds"]) == 3
    assert result["methods"] == [
        "raw",
        "PX4 cubic",
        "ArduPilot cubic",
        "cubic + run constants",
        "gyrocomp default",
        "gyrocomp for firmware",
    ]
    means = result["mean_over_axes_dps"]
    # chamber runs with a strong tempco: every model beats the raw output
    assert all(means[m] < means["raw"] for m in result["methods"] if m != "raw")
    table = run("validate", *runs, "--candidate", "poly:1")
    assert table.returncode == 0, table.stderr
    assert "gyrocomp poly:1" in table.stdout and "vs cubic" in table.stdout
    bad = run("validate", *runs, "--folds", "sideways")
    assert bad.returncode == 2 and "--folds" in bad.stderr


def test_validate_refuses_a_run_given_twice(workdir):
    """Leave-one-run-out with a run given twice would hold it out against its own copy."""
    first, second = sorted(Path(workdir).glob("run*.csv"))[:2]
    out = run("validate", first, second, first)
    assert out.returncode == 2 and out.stderr.count("\n") == 1, out.stderr
    assert f"{first}: the same samples as {first} (a run given twice)" in out.stderr
    assert "give each run once" in out.stderr
