"""Options defined once (gyrocomp.option_spelling): the reading options are fields of ReadOptions and TableLayout, each
spelled once; the spelling builds the object and its parse errors name the field."""

import dataclasses

import pytest

from gyrocomp.errors import InputError
from gyrocomp.io import ReadOptions, TableLayout
from gyrocomp.option_spelling import Spelling, from_values, spelled, spelled_fields


def test_every_reading_field_is_spelled_once_and_flags_do_not_repeat():
    spelled_names = [field.name for field, _ in spelled_fields(ReadOptions)]
    own = [f.name for f in dataclasses.fields(TableLayout)] + [
        f.name for f in dataclasses.fields(ReadOptions) if f.name not in ("layout", "channels")
    ]
    assert sorted(spelled_names) == sorted(own)  # layout is spelled through its fields; channels by each command
    flags = [spelling.flag for _, spelling in spelled_fields(ReadOptions)]
    assert len(set(flags)) == len(flags) and all(f.startswith("--") for f in flags)


def test_values_build_the_options_and_nested_layout():
    parsed = {field.name: spelling.parse for field, spelling in spelled_fields(ReadOptions)}
    options = from_values(
        ReadOptions,
        {
            "columns": parsed["columns"]("gyro_z=GyrZ,temperature=T"),
            "gyro_unit": "rad/s",
            "delimiter": parsed["delimiter"]("tab"),
            "drop_nonfinite": True,
            "instance": parsed["instance"]("2"),
            "time_range_s": parsed["time_range_s"]("10:"),
            "imu_topic": None,
        },
    )
    assert options == ReadOptions(
        layout=TableLayout({"gyro_z": "GyrZ", "temperature": "T"}, "rad/s", delimiter="\t"),
        drop_nonfinite=True,
        instance=2,
        time_range_s=(10.0, None),
    )
    assert from_values(ReadOptions, {}) == ReadOptions()


@pytest.mark.parametrize(
    "name, text, match",
    [
        ("time_range_s", "1:x", r"time_range_s: '1:x': give A:B in seconds"),
        ("time_range_s", ":", r"time_range_s: ':': give finite seconds on at least one side"),
        ("time_range_s", "1:inf", r"time_range_s: '1:inf': give finite seconds"),
        ("instance", "-1", r"instance: -1: give a whole number >= 0"),
        ("device_id", "abc", r"device_id: 'abc': give a whole number >= 0"),
        ("columns", "gyro_z", r"columns: 'gyro_z' is not CHANNEL=COLUMN"),
    ],
)
def test_parse_errors_name_the_field(name, text, match):
    parse = {field.name: spelling.parse for field, spelling in spelled_fields(ReadOptions)}[name]
    with pytest.raises(InputError, match=match):
        parse(text)


def test_the_options_object_checks_what_the_command_line_does_not():
    with pytest.raises(InputError, match=r"instance: all is for gyrocomp fit"):
        ReadOptions(instance="all")
    with pytest.raises(InputError, match=r"device_id: -2: give a whole number >= 0"):
        ReadOptions(device_id=-2)


def test_a_spelled_field_of_any_dataclass():
    @dataclasses.dataclass(frozen=True)
    class Settings:
        rate_hz: float = spelled(Spelling("--rate", "Rate [Hz].", parse=float), default=100.0)
        plain: int = 3

    assert [(f.name, s.flag) for f, s in spelled_fields(Settings)] == [("rate_hz", "--rate")]
    assert from_values(Settings, {"rate_hz": 50.0, "plain": 9}) == Settings(50.0)  # only spelled fields are taken
