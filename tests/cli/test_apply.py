"""`gyrocomp apply`, run through the real entry point in a subprocess."""

import json

import numpy as np
import pandas as pd

from ..conftest import run


def test_apply_keeps_columns_rows_and_other_channels(workdir):
    out = workdir / "comp.csv"
    r = run("apply", workdir / "model.json", workdir / "run3.csv", "-o", out)
    assert r.returncode == 0, r.stderr
    raw, comp = pd.read_csv(workdir / "run3.csv"), pd.read_csv(out)
    assert list(comp.columns) == list(raw.columns) and len(comp) == len(raw)
    for col in ("time", "accel_x", "accel_y", "accel_z", "temperature"):
        np.testing.assert_array_equal(comp[col], raw[col])
    assert comp["gyro_z"].rolling(600).mean().dropna().pipe(np.ptp) < raw["gyro_z"].rolling(600).mean().dropna().pipe(
        np.ptp
    )


def test_apply_parquet_and_turn_on_window(workdir):
    out = workdir / "comp.parquet"
    r = run("apply", workdir / "model.json", workdir / "run3.csv", "-o", out, "--turn-on-window", 30)
    assert r.returncode == 0, r.stderr
    comp = pd.read_parquet(out)
    assert abs(comp["gyro_z"][comp["time"] < 30].mean()) < 1e-12
    # evaluate takes the same window and says what it does to its figures (nothing: they ignore a constant)
    with_window = run("evaluate", workdir / "model.json", workdir / "run3.csv", "--turn-on-window", 30)
    plain = run("evaluate", workdir / "model.json", workdir / "run3.csv")
    assert with_window.returncode == 0 and with_window.stdout == plain.stdout
    assert "--turn-on-window 30: each run's constant was taken from its first seconds" in with_window.stderr


def test_apply_unknown_output_suffix_keeps_input_format(workdir, tmp_path):
    r = run("apply", workdir / "model.json", workdir / "run3.csv", "-o", tmp_path / "out.dat")
    assert r.returncode == 0, r.stderr
    assert len(pd.read_csv(tmp_path / "out.dat")) == 12001


def test_apply_refuses_an_axis_the_model_lacks_unless_axes_are_named(workdir, tmp_path):
    d = json.loads((workdir / "model.json").read_text())
    d["axes"] = {"gyro_z": d["axes"]["gyro_z"]}
    (tmp_path / "z.json").write_text(json.dumps(d))
    r = run("apply", tmp_path / "z.json", workdir / "run3.csv", "-o", tmp_path / "out.csv")
    assert r.returncode == 2 and not (tmp_path / "out.csv").exists()
    assert r.stderr.strip() == (
        f"gyrocomp: error: {workdir / 'run3.csv'}: the model has no curve for gyro_x, gyro_y "
        "(it covers gyro_z); give --axes with the axes to compensate, the others are then "
        "left raw"
    )
    r = run("apply", tmp_path / "z.json", workdir / "run3.csv", "-o", tmp_path / "out.csv", "--axes", "gyro_z")
    assert r.returncode == 0, r.stderr
    assert "gyro_x, gyro_y left raw (not among the axes to compensate)" in r.stderr
    assert "gyro_z compensated" in r.stdout
    raw, out = pd.read_csv(workdir / "run3.csv"), pd.read_csv(tmp_path / "out.csv")
    assert (out["gyro_x"] == raw["gyro_x"]).all() and not (out["gyro_z"] == raw["gyro_z"]).all()


def test_apply_drop_nan_leaves_the_dropped_rows_out_and_keeps_the_others(workdir, tmp_path):
    raw = pd.read_csv(workdir / "run3.csv").iloc[:200].copy()
    raw.loc[5, "temperature"] = np.nan  # the gyro values of row 7 (1-based, after the header) are valid
    raw.to_csv(tmp_path / "holes.csv", index=False)
    r = run("apply", workdir / "model.json", tmp_path / "holes.csv", "-o", tmp_path / "out.csv", "--drop-nan")
    assert r.returncode == 0, r.stderr
    assert "dropped 1 of 200 rows" in r.stderr and "wrote" in r.stdout and ": 199 rows," in r.stdout
    out = pd.read_csv(tmp_path / "out.csv")
    assert len(out) == 199 and not out.isna().any().any()
    np.testing.assert_array_equal(out["time"], raw["time"].drop(index=5))


def test_apply_keeps_a_decimal_comma_and_its_separator(workdir, tmp_path):
    """A table written in a decimal-comma locale (semicolons, 0,5) comes out as it went in, streamed or whole, and
    reads back to the same numbers; a text column that holds the separator is quoted, never written ambiguous."""
    import numpy as np

    from gyrocomp import read

    original = (workdir / "run3.csv").read_text().splitlines()
    header, rows = original[0], original[1:]
    lines = [header.replace(",", ";") + ";note"] + [
        r.replace(",", ";").replace(".", ",") + (';"a;b"' if i == 1 else ";x") for i, r in enumerate(rows)
    ]
    (tmp_path / "comma.csv").write_text("\n".join(lines) + "\n")
    for extra in ((), ("--time", "0:100000")):  # streamed, and read whole (rows selected by time)
        done = run("apply", workdir / "model.json", tmp_path / "comma.csv", "-o", tmp_path / "out.csv", *extra)
        assert done.returncode == 0, done.stderr
        out = (tmp_path / "out.csv").read_text().splitlines()
        assert out[0] == lines[0] and out[2].count(";") == lines[2].count(";") and "," in out[2]
        assert '"a;b"' in out[2]  # the one value that holds the separator, quoted
        reference = run("apply", workdir / "model.json", workdir / "run3.csv", "-o", tmp_path / "point.csv")
        assert reference.returncode == 0
        np.testing.assert_allclose(
            read(tmp_path / "out.csv").gyro_dps, read(tmp_path / "point.csv").gyro_dps, rtol=1e-12
        )
