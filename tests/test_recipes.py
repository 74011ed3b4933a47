"""docs/architecture.md's "Where new things go", followed to the letter: a reader, an export format and a
temperature curve, each added to a copy of the package as its own module plus one registration line (two source
files), then run through the command line of that copy (``fit``, ``apply``, ``export``, ``show``, ``--format``,
``--help``). If the recipe needs a third file, or a list it does not name, these tests fail."""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import gyrocomp
from gyrocomp.simulation import get_profile, simulate

pytestmark = pytest.mark.slow

PACKAGE = Path(gyrocomp.__file__).parent

READER = '''"""``.imuz`` files (a made-up format: NumPy's npz archive) of ``time_s``, ``gyro_dps`` (n, 3) and
``temperature_degc`` arrays."""

from __future__ import annotations

import numpy as np

from .log_samples import log_recording
from .readers import Reader, register_reader


def read_imuz(path, options, progress=None):
    with np.load(path, allow_pickle=False) as archive:
        return log_recording(path, options, archive["time_s"], archive["gyro_dps"], None,
                             archive["temperature_degc"], {"path": str(path), "format": "imuz"})


register_reader(Reader("imuz", "arrays time_s, gyro_dps, temperature_degc", read_imuz,
                       suffixes=(".imuz",), aliases=("imuzip",)))
'''

EXPORT = '''"""Each gyro axis's mean turn-on constant, one line each."""

from __future__ import annotations

from ..io.atomic import write_text_atomic
from .exporters import Exported, Exporter, register


def write_offsets(calibration, path, options):
    write_text_atomic(path, "".join(f"{axis} {ax.mean_turn_on_bias!r}\\n" for axis, ax in calibration.axes.items()))
    return Exported("offsets", (path,))


register(Exporter("offsets", "each axis's mean turn-on constant", "every curve", write_offsets,
                  suffixes=(".offsets",)))
'''

CURVE = '''"""A step function of temperature: N + 1 levels on equal bins of the calibrated range, held past it."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from ..c_literals import c_array, c_number
from .protocol import CCode, register_basis, register_curve


@register_curve
@dataclass(frozen=True)
class StepCurve:
    kind: ClassVar[str] = "step"
    inputs: ClassVar[tuple[str, ...]] = ("temperature",)
    needs_accel: ClassVar[bool] = False
    beyond_range: ClassVar[str] = "held at its edge"

    levels: tuple[float, ...]
    t_min_degc: float
    t_max_degc: float

    @property
    def order(self) -> str:
        return f"step:{len(self.levels) - 1}"

    @property
    def label(self) -> str:
        return self.order

    def _bin(self, temperature_degc):
        n = len(self.levels)
        x = (np.asarray(temperature_degc, dtype=float) - self.t_min_degc) / (self.t_max_degc - self.t_min_degc)
        return np.clip((x * n).astype(int), 0, n - 1)

    def shape(self, temperature_degc, accel_g=None):
        return np.asarray(self.levels)[self._bin(temperature_degc)]

    def outside_range(self, temperature_degc):
        t = np.asarray(temperature_degc)
        return bool(np.any(t < self.t_min_degc - 0.5) or np.any(t > self.t_max_degc + 0.5))

    def describe(self):
        return f"step function, {len(self.levels)} levels"

    def clamped(self):
        return self

    def plus_slope(self, slope_per_degc):
        return None

    def c_code(self, name):
        n = len(self.levels)
        return CCode((f"{{ static const double v[{n}] = {c_array(self.levels)};",
                      f"  int k = (int)((clip(tm, {c_number(self.t_min_degc)}, {c_number(self.t_max_degc)}) - "
                      f"{c_number(self.t_min_degc)}) / {c_number((self.t_max_degc - self.t_min_degc) / n)});",
                      f"  if (k > {n - 1}) k = {n - 1};",
                      "  shape = v[k];",
                      "}"))

    def to_dict(self) -> dict[str, Any]:
        return {"type": self.kind, "levels_dps": list(self.levels), "t_min_degc": self.t_min_degc,
                "t_max_degc": self.t_max_degc}

    @classmethod
    def from_dict(cls, d):
        return cls(tuple(float(v) for v in d["levels_dps"]), float(d["t_min_degc"]), float(d["t_max_degc"]))


@register_basis
@dataclass(frozen=True)
class StepBasis:
    name: ClassVar[str] = "step"
    description: ClassVar[str] = "a step function of N + 1 levels on equal bins of the calibrated range"
    sizes: ClassVar[tuple[int, ...]] = (6,)

    lo_degc: float
    hi_degc: float

    @classmethod
    def over(cls, lo_degc, hi_degc, extended=True):
        return cls(lo_degc, hi_degc if hi_degc > lo_degc else lo_degc + 1.0)

    def columns(self, temperature_degc, size, lo_degc=None, hi_degc=None):
        k = StepCurve((0.0,) * (size + 1), self.lo_degc, self.hi_degc)._bin(temperature_degc)
        return (k[:, None] == np.arange(1, size + 1)[None, :]).astype(float)

    def curve(self, coefficients, lo_degc, hi_degc):
        return StepCurve((0.0, *map(float, coefficients)), self.lo_degc, self.hi_degc)
'''

#: the recipe of each kind: (its module's path in the package, its text, the file that names it, the line)
RECIPES = {
    "reader": ("io/imuz.py", READER, "io/read_formats.py", "from . import imuz  # noqa: F401"),
    "export": ("export/offsets.py", EXPORT, "export/formats.py", "from . import offsets  # noqa: F401"),
    "curve": ("curves/step.py", CURVE, "curves/kinds.py", "from . import step  # noqa: F401"),
}


@pytest.fixture(scope="module")
def extended(tmp_path_factory):
    """A copy of the package with the three recipes followed, and a gyrocomp that runs it."""
    root = tmp_path_factory.mktemp("extended")
    target = root / "gyrocomp"
    shutil.copytree(PACKAGE, target, ignore=shutil.ignore_patterns("__pycache__"))
    before = {p.relative_to(target): p.read_bytes() for p in target.rglob("*.py")}
    for module, text, registry, line in RECIPES.values():
        (target / module).write_text(text)
        names = target / registry
        lines = names.read_text().splitlines()
        last = max(i for i, x in enumerate(lines) if x.startswith("from . import "))
        names.write_text("\n".join(lines[: last + 1] + [line] + lines[last + 1 :]) + "\n")
    changed = {
        p.relative_to(target) for p in target.rglob("*.py") if before.get(p.relative_to(target)) != p.read_bytes()
    }
    assert changed == {Path(m) for m, _, r, _ in RECIPES.values()} | {Path(r) for _, _, r, _ in RECIPES.values()}

    def run(*args, cwd=root):
        env = {**os.environ, "PYTHONPATH": str(root), "COLUMNS": "200"}
        return subprocess.run(
            [sys.executable, "-m", "gyrocomp", *map(str, args)],
            capture_output=True,
            text=True,
            cwd=cwd,
            env=env,
            timeout=300,
        )

    runs = root / "runs"
    runs.mkdir()
    for seed in range(3):
        rec = simulate(
            "consumer", profile=get_profile("cycle", set_points_degc=(-10.0, 60.0), cycles=1), rate_hz=1.0, seed=seed
        ).recording
        with open(runs / f"run{seed}.imuz", "wb") as fh:  # a file object: numpy adds no .npz
            np.savez(fh, time_s=rec.time_s, gyro_dps=rec.gyro_dps, temperature_degc=rec.temperature_degc)
    return run, root


def test_the_copy_runs_its_own_package(extended):
    _, root = extended
    done = subprocess.run(
        [sys.executable, "-c", "import gyrocomp; print(gyrocomp.__file__)"],
        capture_output=True,
        text=True,
        env={**os.environ, "PYTHONPATH": str(root)},
    )
    assert done.stdout.strip() == str(root / "gyrocomp" / "__init__.py")


def test_a_reader_is_its_module_and_one_line(extended, tmp_path):
    run, root = extended
    help_text = " ".join(run("fit", "--help").stdout.split())
    assert "imuz (arrays time_s, gyro_dps, temperature_degc)" in help_text
    fitted = run("fit", root / "runs", "-o", tmp_path / "m.json", "--temperature", "poly:2", "--hysteresis", "none")
    assert fitted.returncode == 0, fitted.stderr
    inputs = json.loads((tmp_path / "m.json").read_text())["provenance"]["inputs"]
    assert len(inputs) == 3 and all(".imuz" in json.dumps(i) for i in inputs)  # the folder's three .imuz files
    renamed = tmp_path / "run0.data"
    shutil.copy(root / "runs" / "run0.imuz", renamed)
    refused = run("apply", tmp_path / "m.json", renamed, "-o", tmp_path / "c.csv")
    assert refused.returncode == 2 and "cannot tell the format" in refused.stderr
    for name in ("imuz", "imuzip"):
        done = run("apply", tmp_path / "m.json", renamed, "-o", tmp_path / f"{name}.csv", "--format", name)
        assert done.returncode == 0, done.stderr
        assert "rows" in done.stdout


def test_an_export_is_its_module_and_one_line(extended, tmp_path):
    run, root = extended
    assert "offsets (each axis's mean turn-on constant; .offsets)" in " ".join(run("export", "--help").stdout.split())
    fitted = run("fit", root / "runs", "-o", tmp_path / "m.json", "--temperature", "poly:2", "--hysteresis", "none")
    assert fitted.returncode == 0, fitted.stderr
    by_name = run("export", tmp_path / "m.json", "-o", tmp_path / "m.offsets")
    named = run("export", tmp_path / "m.json", "-o", tmp_path / "other.txt", "--format", "offsets")
    assert by_name.returncode == 0 and named.returncode == 0, by_name.stderr + named.stderr
    lines = (tmp_path / "m.offsets").read_text().splitlines()
    assert [line.split()[0] for line in lines] == ["gyro_x", "gyro_y", "gyro_z"]
    assert (tmp_path / "other.txt").read_text() == (tmp_path / "m.offsets").read_text()


def test_a_curve_is_its_module_and_one_line(extended, tmp_path):
    run, root = extended
    assert "step or step:N (N = 1..64): a step function" in " ".join(run("fit", "--help").stdout.split())
    fitted = run("fit", root / "runs", "-o", tmp_path / "m.json", "--temperature", "step:6")
    assert fitted.returncode == 0, fitted.stderr
    shown = run("show", tmp_path / "m.json")
    assert shown.stdout.count("step function, 7 levels") == 3, shown.stdout
    applied = run("apply", tmp_path / "m.json", root / "runs" / "run1.imuz", "-o", tmp_path / "c.csv")
    assert applied.returncode == 0, applied.stderr
    exported = run("export", tmp_path / "m.json", "-o", tmp_path / "c")
    assert exported.returncode == 0, exported.stderr
    assert "static const double v[7]" in (tmp_path / "c" / "gyrocomp.c").read_text()
    default = run("fit", root / "runs", "-o", tmp_path / "auto.json", "--hysteresis", "none")
    assert default.returncode == 0, default.stderr
    assert "step:6" in (tmp_path / "auto.json").read_text()  # the automatic choice scored it
