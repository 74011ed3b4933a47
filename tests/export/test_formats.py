"""The export entry point and its registry: every format through export_to, an unknown one refused, a new one
added by one registration."""

import json
import warnings

import pytest

from gyrocomp.calibration import Calibration
from gyrocomp.errors import InputError
from gyrocomp.export import EXPORTERS, ExportOptions, Exported, Exporter, export_to, register
from gyrocomp.models.options import Polynomial
from gyrocomp.models.joint import fit_calibration
from gyrocomp.simulation import get_profile, simulate


@pytest.fixture(scope="module")
def model():
    runs = [
        simulate(
            "consumer", profile=get_profile("cycle", set_points_degc=(0.0, 50.0), cycles=1), rate_hz=0.5, seed=s
        ).recording
        for s in range(2)
    ]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fit_calibration(runs, temperature=Polynomial(2), hysteresis="none")


def test_every_registered_format_writes_and_says_what(tmp_path, model):
    assert set(EXPORTERS) >= {"px4", "ardupilot", "c", "json"}
    assert all(e.description and e.cannot_carry for e in EXPORTERS.values())
    px4 = export_to(model, "px4", tmp_path / "t.params", ExportOptions(device_id=5))
    assert px4.written == (tmp_path / "t.params",) and (tmp_path / "t.params").exists()
    assert any("on the vehicle, in this order" in n for n in px4.notes)
    assert px4.firmware is not None and px4.firmware.target == "px4"
    quiet = export_to(model, "ardupilot", tmp_path / "t.parm", ExportOptions(judge_firmware=False))
    assert quiet.firmware is None and (tmp_path / "t.parm").exists()
    c = export_to(model, "c", tmp_path / "c", ExportOptions(rate_hz=0.5))
    assert {p.name for p in c.written} >= {"gyrocomp.h", "gyrocomp.c"}
    back = export_to(model, "json", tmp_path / "m.json")
    assert Calibration.load(back.written[0]).to_dict()["axes"] == json.loads(json.dumps(model.to_dict()))["axes"]


def test_an_unknown_format_is_refused_and_a_new_one_is_one_registration(tmp_path, model):
    with pytest.raises(InputError, match=rf"format: 'betaflight'; use one of {', '.join(EXPORTERS)}$"):
        export_to(model, "betaflight", tmp_path / "x")

    def axes_csv(calibration, path, options):
        path.write_text(
            "axis,constant\n" + "".join(f"{a},{ax.mean_turn_on_bias}\n" for a, ax in calibration.axes.items())
        )
        return Exported("axes-csv", (path,))

    register(Exporter("axes-csv", "each axis's mean turn-on constant", "everything else", axes_csv))
    try:
        done = export_to(model, "axes-csv", tmp_path / "axes.csv")
        assert done.written == (tmp_path / "axes.csv",) and "gyro_x," in (tmp_path / "axes.csv").read_text()
        with pytest.raises(InputError, match=r"export format 'axes-csv' is registered already"):
            register(Exporter("axes-csv", "again", "-", axes_csv))
    finally:
        EXPORTERS.pop("axes-csv")
