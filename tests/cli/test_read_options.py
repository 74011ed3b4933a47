"""The reading options every command shares (columns, units, delimiters), run through the real entry point in a
subprocess."""

import numpy as np
import pandas as pd

from ..conftest import run


def test_mapping_and_units_through_cli(workdir, tmp_path):
    df = pd.read_csv(workdir / "run3.csv")
    vendor = pd.DataFrame({"Stamp": df["time"] * 1000, "GyrZ": np.deg2rad(df["gyro_z"]), "T": df["temperature"]})
    vendor.to_csv(tmp_path / "vendor.csv", index=False)
    r = run("apply", workdir / "model.json", tmp_path / "vendor.csv", "-o", tmp_path / "v_out.csv",
            "--columns", "time=Stamp,gyro_z=GyrZ,temperature=T", "--gyro-unit", "rad/s", "--time-unit", "ms")
    assert r.returncode == 0, r.stderr
    ours = pd.read_csv(tmp_path / "v_out.csv")
    theirs = run("apply", workdir / "model.json", workdir / "run3.csv", "-o", tmp_path / "d_out.csv")
    assert theirs.returncode == 0
    np.testing.assert_allclose(np.rad2deg(ours["GyrZ"]), pd.read_csv(tmp_path / "d_out.csv")["gyro_z"], atol=1e-12)


def test_a_tab_separated_export_with_decimal_commas_reads_with_or_without_options(tmp_path):
    (tmp_path / "v.txt").write_text("Time\tGyro_Z\tTemperature\n0\t1,5\t20,5\n1\t2,5\t21\n2\t3\t22\n")
    for extra in ([], ["--delimiter", "tab", "--decimal", ","]):
        r = run("convert", tmp_path / "v.txt", tmp_path / "o.csv", *extra)
        assert r.returncode == 0, r.stderr
        out = pd.read_csv(tmp_path / "o.csv")
        assert list(out["gyro_z"]) == [1.5, 2.5, 3.0] and list(out["temperature"]) == [20.5, 21.0, 22.0]
    r = run("convert", tmp_path / "v.txt", tmp_path / "o.csv", "--decimal", ":")
    assert r.returncode == 2 and r.stderr.strip() == "gyrocomp: error: --decimal: ':'; use '.' or ','"
