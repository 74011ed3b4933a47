"""Every text field of a model file, hostile: the generated C compiles to the same object as with the plain
model, and the parameter files carry the same parameters (text reaches them only inside encoded comments)."""

from __future__ import annotations

import copy
import json
import shutil
import subprocess
import warnings

import pytest

from gyrocomp.calibration import Calibration
from gyrocomp.errors import InputError
from gyrocomp.export.autopilot import ardupilot_params_file, px4_params_file
from gyrocomp.export.c_code import c_sources
from gyrocomp.models.joint import fit_calibration
from gyrocomp.simulation import get_profile, simulate

CC = shutil.which("cc") or shutil.which("gcc")
#: closes a C comment, splices lines, a trigraph, a preprocessor line, a parameter line, control characters
HOSTILE = '*/ int evil(void) { return system("id"); } /* ??/\n#include <stdlib.h>\nTC_G0_X0_0\t1e9\r\x00\x1b[2J \u2028'


def _string_leaves(node, path=()):
    if isinstance(node, dict):
        for key, value in node.items():
            yield from _string_leaves(value, path + (key,))
    elif isinstance(node, list):
        for k, value in enumerate(node):
            yield from _string_leaves(value, path + (k,))
    elif isinstance(node, str):
        yield path


def _set(node, path, value):
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value


def _pattern(path):
    return tuple("*" if isinstance(k, int) else k for k in path)


@pytest.fixture(scope="module")
def model():
    prof = get_profile("cycle", set_points_degc=(-20.0, 60.0), cycles=1)
    runs = [simulate("consumer", profile=prof, rate_hz=0.5, seed=s).recording for s in range(2)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fit_calibration(runs)


def _hostile_model(plain: dict) -> tuple[dict, list, list]:
    """The model with every string field that still loads made hostile (fields of one shape together), and the
    shapes taken and refused."""
    by_shape: dict[tuple, list] = {}
    for path in _string_leaves(plain):
        by_shape.setdefault(_pattern(path), []).append(path)
    taken, refused = [], []
    hostile = copy.deepcopy(plain)
    for shape, paths in by_shape.items():
        trial = copy.deepcopy(hostile)
        for path in paths:
            _set(trial, path, HOSTILE)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                Calibration.from_dict(json.loads(json.dumps(trial)))
        except InputError:
            refused.append(shape)
            continue
        hostile = trial
        taken.append(shape)
    return hostile, taken, refused


def _compile(folder, sources: dict[str, str]) -> bytes:
    folder.mkdir()
    for name, text in sources.items():
        (folder / name).write_text(text)
    subprocess.run(
        [CC, "-std=c99", "-O2", "-Wall", "-Werror", "-c", "-o", str(folder / "gyrocomp.o"), str(folder / "gyrocomp.c")],
        check=True,
        capture_output=True,
        text=True,
        cwd=folder,
    )
    return (folder / "gyrocomp.o").read_bytes()


def _parameters(text: str) -> list[str]:
    lines = text.splitlines()
    assert all(line.replace("\t", " ").isprintable() for line in lines)  # no control character, no stray break
    return [line for line in lines if not line.startswith("#")]


@pytest.mark.skipif(CC is None, reason="no C compiler (cc) on this machine")
def test_every_text_field_of_a_model_hostile_compiles_to_the_same_code(tmp_path, model):
    plain = model.to_dict()
    hostile_dict, taken, refused = _hostile_model(plain)
    # the text fields that load (model name, provenance, the fit's account) are most of them; the refused are
    # the ones the loader checks against a fixed set of words (curve kinds, memories, units)
    assert ("model",) in taken and any(shape[0] == "provenance" for shape in taken)
    assert any(shape[0] == "fit_report" for shape in taken)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        hostile = Calibration.from_dict(hostile_dict)
    assert _compile(tmp_path / "plain", c_sources(model, rate_hz=0.5)) == _compile(
        tmp_path / "hostile", c_sources(hostile, rate_hz=0.5)
    )
    for write in (lambda c: px4_params_file(c, device_id=7), ardupilot_params_file):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            assert _parameters(write(hostile)) == _parameters(write(model))


def test_a_hostile_axis_name_is_refused_on_load(model):
    plain = model.to_dict()
    axes = plain["axes"]
    renamed = copy.deepcopy(plain)
    renamed["axes"] = {HOSTILE if k == "gyro_z" else k: v for k, v in axes.items()}
    with pytest.raises(InputError, match=r"axes"):
        Calibration.from_dict(renamed)


@pytest.mark.skipif(CC is None, reason="no C compiler (cc) on this machine")
@pytest.mark.slow
def test_a_hostile_serial_and_header_reach_no_generated_code(tmp_path):
    """A store row whose serial, and a table whose column names, are hostile: fleet export's C compiles to the same
    object as a unit named plainly from a plainly named table; its PX4 parameter lines are the same."""
    from gyrocomp.io.tables import write_recording

    from ..conftest import run

    rec = simulate(
        "consumer", profile=get_profile("cycle", set_points_degc=(-20.0, 60.0), cycles=1), rate_hz=0.5, seed=1
    ).recording
    plain_csv = tmp_path / "plain.csv"
    write_recording(rec, plain_csv)
    header = "g*/ system(0); /* ??/"
    text = plain_csv.read_text().splitlines()
    hostile_csv = tmp_path / "hostile.csv"
    hostile_csv.write_text("\n".join([text[0].replace("gyro_x", f'"{header}"')] + text[1:]) + "\n")
    objects, parameters = [], []
    for name, (serial, source, extra) in {
        "plain": ("U1", plain_csv, []),
        "hostile": ("*/ int x; /* ??/", hostile_csv, ["--columns", f"gyro_x={header}"]),
    }.items():
        manifest = tmp_path / f"manifest_{name}.csv"
        manifest.write_text(f'path,serial\n{source},"{serial}"\n')
        fitted = run("fleet", "fit", "--manifest", manifest, "-o", tmp_path / name, "--scheduler", "serial", *extra)
        assert fitted.returncode == 0, fitted.stderr
        out = tmp_path / f"{name}_c"
        exported = run("fleet", "export", serial, "--store", tmp_path / name, "--format", "c", "-o", out, "--rate", 0.5)
        assert exported.returncode == 0, exported.stderr
        objects.append(_compile(tmp_path / f"{name}_o", {f.name: f.read_text() for f in out.iterdir()}))
        params = tmp_path / f"{name}.params"
        exported = run(
            "fleet", "export", serial, "--store", tmp_path / name, "--format", "px4", "-o", params, "--device-id", 7
        )
        assert exported.returncode == 0, exported.stderr
        parameters.append(_parameters(params.read_text()))
    assert objects[0] == objects[1] and parameters[0] == parameters[1]
