"""The library's hot paths hold BLAS to one thread while they run and give the caller its setting back (#21)."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest
from threadpoolctl import threadpool_limits

from gyrocomp.allan import allan_deviation
from gyrocomp.errors import InputError
from gyrocomp.models import accelerometer, joint, pipelines
from gyrocomp.models import fit as fit_module
from gyrocomp.threads import blas_threads, single_threaded_blas

pytestmark = pytest.mark.skipif(blas_threads() is None, reason="numpy loaded no BLAS library threadpoolctl can see")


def test_blas_runs_on_one_thread_inside_and_the_callers_setting_returns():
    seen = []

    @single_threaded_blas
    def work():
        seen.append(blas_threads())
        return np.linalg.lstsq(np.eye(3), np.ones(3), rcond=None)[0]

    with threadpool_limits(2, user_api="blas"):
        before = blas_threads()
        np.testing.assert_allclose(work(), np.ones(3))
        assert seen == [1] and blas_threads() == before


@pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="one core: BLAS runs one thread anyway")
def test_scipys_blas_loaded_late_is_held_to_one_thread_too():
    """In a new interpreter that has not imported scipy: scipy.linalg brings its own BLAS, and a fit imports it
    late, inside the limit. Every BLAS library loaded (numpy's and scipy's) runs on one thread in the call, and
    keeps the caller's setting after."""
    code = """
import json
from threadpoolctl import threadpool_info
import numpy
from gyrocomp.threads import single_threaded_blas

def threads():
    return [i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"]

@single_threaded_blas
def work():
    import scipy.linalg
    return threads()

inside = work()
print(json.dumps([inside, threads()]))
"""
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "2"}  # the caller's setting, for libraries not loaded yet too
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, env=env).stdout
    inside, after = json.loads(out)
    assert inside and set(inside) == {1}, out
    assert len(after) == len(inside) and max(after) > 1, out


def test_the_setting_returns_when_the_call_raises():
    with threadpool_limits(2, user_api="blas"):
        before = blas_threads()
        with pytest.raises(InputError, match="rate_hz: must be positive"):
            allan_deviation(np.ones(100), 0.0)
        assert blas_threads() == before


@pytest.mark.parametrize(
    "module, entry",
    [
        (fit_module, "fit"),
        (joint, "fit_calibration"),
        (pipelines, "fit_pipeline"),
        (fit_module, "fit_channels"),
        (accelerometer, "fit_accelerometer"),
    ],
)
def test_every_fit_entry_point_fits_with_blas_on_one_thread(monkeypatch, module, entry):
    """What the fit runs sees one BLAS thread, whichever public entry point it came through."""
    seen = []

    def prepare(recordings):  # the first step of every fit: note the setting, then stop the fit
        seen.append(blas_threads())
        raise InputError("stopped here")

    monkeypatch.setattr(module, "prepare", prepare)
    with threadpool_limits(2, user_api="blas"), pytest.raises(InputError, match="stopped here"):
        getattr(module, entry)([])
    assert seen and set(seen) == {1}


@pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="one core: BLAS runs one thread anyway")
@pytest.mark.parametrize("setting, expected", [(None, 1), ("2", 2)])
def test_a_command_runs_blas_on_one_thread_unless_the_environment_says_otherwise(setting, expected):
    """The console script, in a new interpreter: what its command runs sees one BLAS thread (its many small
    solves' threads would wait for each other on a shared machine), or the number the environment sets."""
    code = """
import sys
import gyrocomp.cli.entry_point as entry
from gyrocomp.cli import main

def look(*args, **kwargs):
    from gyrocomp.threads import blas_threads
    print(blas_threads())
    return 0

entry.cli.main = look
sys.argv = ["gyrocomp", "--help"]
sys.exit(main())
"""
    env = {
        k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")
    }
    if setting is not None:
        env["OPENBLAS_NUM_THREADS"] = setting
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, env=env)
    assert out.stdout.split() == [str(expected)], out


@pytest.mark.parametrize("entry", ["plan", "forecast_drift"])
def test_the_planning_entry_points_run_blas_on_one_thread(monkeypatch, entry):
    """The forecast's many small decompositions (SVD, Cholesky) run on one BLAS thread whichever entry point."""
    from gyrocomp.evaluation import drift_forecast, run_advice

    seen = []

    def information(calibration, recordings, window_s):  # the first step of both: note the setting, then stop
        seen.append(blas_threads())
        raise InputError("stopped here")

    monkeypatch.setattr(run_advice, "axis_information", information)
    monkeypatch.setattr(drift_forecast, "axis_information", information)
    function = run_advice.plan if entry == "plan" else drift_forecast.forecast_drift
    with threadpool_limits(2, user_api="blas"), pytest.raises(InputError, match="stopped here"):
        function(None, [], drift_forecast.UseProfile.cycle(10, 60, 1.0))
    assert seen == [1]
