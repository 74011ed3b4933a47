"""The readers' registry: what a registered reader gets (its name, aliases, suffixes, first bytes, folders,
instances) and what is refused, checked with a reader registered for the test, never against the list of
formats gyrocomp ships."""

import numpy as np
import pytest

from gyrocomp.errors import InputError
from gyrocomp.io import READERS, Reader, detect_format, format_help, format_names, instances, read, register_reader
from gyrocomp.io.inputs import expand_inputs
from gyrocomp.io.readers import reader_named, run_suffixes, sniff_format
from gyrocomp.recording import Recording

MAGIC = b"GYRTEST\x00"


def _read(path, options, progress=None):
    t = np.arange(50.0)
    return Recording(
        time_s=t, gyro_dps=np.full((50, 1), 0.25), gyro_axes=("gyro_z",), temperature_degc=20 + 0 * t, source=str(path)
    )


@pytest.fixture
def probe():
    reader = register_reader(
        Reader(
            "probe",
            "a test format",
            _read,
            suffixes=(".prb", ".prb.gz"),
            magic=(MAGIC,),
            aliases=("prb",),
            folder_marker="probe.marker",
            instances=lambda path: (0, 2),
        )
    )
    yield reader
    READERS.pop("probe")


def test_a_registered_reader_is_found_by_name_alias_suffix_and_first_bytes(probe, tmp_path):
    assert "probe" in format_names() and "probe (a test format)" in format_help()
    assert {".prb", ".prb.gz"} <= set(run_suffixes())
    named = tmp_path / "x.prb"
    named.write_bytes(b"anything")
    assert detect_format(named) == "probe"
    compressed = tmp_path / "x.prb.gz"
    compressed.write_bytes(b"anything")
    assert detect_format(compressed) == "probe"  # the longest ending that is registered wins
    signed = tmp_path / "x.csv"
    signed.write_bytes(MAGIC + b"rest")
    assert detect_format(signed) == "probe" and sniff_format(MAGIC) == "probe"
    other = tmp_path / "x.csv2"
    other.write_bytes(b"t,gyro_z\n")
    assert detect_format(other, "PRB") == "probe" and reader_named("Probe") is probe
    assert read(other, fmt="prb").gyro_dps[0, 0] == 0.25
    assert instances(named) == (0, 2)


def test_folders_are_searched_for_registered_suffixes_and_marked_folders_are_one_input(probe, tmp_path):
    (tmp_path / "a.prb").write_bytes(b"x")
    (tmp_path / "notes.md").write_text("not a run")
    bundle = tmp_path / "sub" / "bundle"
    bundle.mkdir(parents=True)
    (bundle / "probe.marker").write_text("")
    (bundle / "inner.prb").write_bytes(b"x")
    assert expand_inputs([tmp_path]) == [tmp_path / "a.prb", bundle]
    assert detect_format(bundle) == "probe"


def test_a_name_alias_or_suffix_taken_is_refused_and_an_unknown_name_lists_the_registered(probe):
    with pytest.raises(InputError, match=r"reader 'probe': the name 'probe' is registered already"):
        register_reader(Reader("probe", "again", _read))
    with pytest.raises(InputError, match=r"reader 'other': the name 'prb' is registered already"):
        register_reader(Reader("other", "x", _read, aliases=("prb",)))
    with pytest.raises(InputError, match=r"reader 'other': the suffix '.prb' is registered already"):
        register_reader(Reader("other", "x", _read, suffixes=(".prb",)))
    assert "other" not in READERS
    with pytest.raises(InputError, match=r"fmt: unknown format 'nope'; use one of .*\bprobe\b"):
        detect_format("x", "nope")


def test_a_folder_without_a_marker_and_a_name_without_a_format_are_refused(tmp_path):
    with pytest.raises(InputError, match=r"is a folder \(not one input: no .*metadata.yaml.* in it\); name a file"):
        detect_format(tmp_path)
    odd = tmp_path / "x.weird"
    odd.write_bytes(b"\x00\x01")
    with pytest.raises(InputError, match=r"x.weird: cannot tell the format from the file or its suffix '.weird'"):
        detect_format(odd)


def test_every_registered_reader_is_described_and_reads_into_the_internal_units():
    for reader in READERS.values():
        assert reader.name and reader.description and callable(reader.read)
        assert all(s == s.lower() and s.startswith(".") for s in reader.suffixes)
