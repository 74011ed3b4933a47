"""Readers and writers. Every reader returns a :class:`gyrocomp.recording.Recording` in internal units.

Formats: CSV and Parquet tables; PX4 ULog (extra ``[ulog]``); ArduPilot DataFlash (``[dataflash]``);
ROS 1 / ROS 2 bags (``[ros]``); HDF5 / NetCDF-4 (``[hdf5]``). The format is told from the file's
first bytes, then its suffix, and can be named instead.
"""

from __future__ import annotations

import dataclasses
import os
import stat
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..recording import Recording
from ..spelling import Spelling
from .atomic import atomic_path, refuse_to_overwrite_inputs, write_text_atomic
from .common import ProgressCallback, ReadOptions, sniff_format
from .project import project_read_options
from .dataflash import dataflash_instances, read_dataflash
from .hdf5 import read_hdf5
from .rosbag import read_rosbag
from .tables import (
    TableData,
    TableLayout,
    detect_table_format,
    file_sha256,
    parse_column_mapping,
    read_table,
    recording_table,
    table_data,
    write_gyro_back,
    write_recording,
    write_rows,
)
from .ulog import read_ulog, ulog_instances

TABLE_FORMATS = ("csv", "parquet")
LOG_FORMATS = ("ulog", "dataflash", "rosbag", "hdf5")
FORMATS = TABLE_FORMATS + LOG_FORMATS
#: the reading functions' ``fmt`` parameter on the command line
FORMAT_SPELLING = Spelling("--format", f"Input format (default: told from the file): {', '.join(FORMATS)}.")
#: aliases accepted by ``--format``
FORMAT_ALIASES = {"ulg": "ulog", "px4": "ulog", "bin": "dataflash", "ardupilot": "dataflash", "bag": "rosbag",
                  "ros": "rosbag", "netcdf": "hdf5", "nc": "hdf5", "h5": "hdf5", "pq": "parquet"}
_SUFFIXES = {".ulg": "ulog", ".bin": "dataflash", ".bag": "rosbag", ".db3": "rosbag", ".mcap": "rosbag",
             ".h5": "hdf5", ".hdf5": "hdf5", ".nc": "hdf5", ".nc4": "hdf5"}
def detect_format(path: str | os.PathLike, fmt: str | None = None) -> str:
    """The format name of ``path``: ``fmt`` if given (checked), else from its first bytes or suffix. A pipe or a
    device (``/dev/stdin``, ``<(...)``) is refused: inputs are read more than once (their first bytes, then in
    chunks, some twice)."""
    _require_a_file(path)
    if fmt is not None:
        name = FORMAT_ALIASES.get(fmt.lower(), fmt.lower())
        if name not in FORMATS:
            raise InputError(f"fmt: unknown format {fmt!r}; use one of {', '.join(FORMATS)}")
        return name
    path = Path(path)
    if path.is_dir():
        if (path / "metadata.yaml").exists():
            return "rosbag"
        raise InputError(f"{path}: is a folder (not a ROS 2 bag: no metadata.yaml in it); name a file")
    if path.is_file():
        with open(path, "rb") as fh:
            found = sniff_format(fh.read(16))
        if found is not None:
            return found
    found = detect_table_format(path) or _SUFFIXES.get(path.suffix.lower())
    if found is None:
        raise InputError(
            f"{path}: cannot tell the format from the file or its suffix {path.suffix!r}; "
            f"name it with fmt= ({', '.join(FORMATS)})"
        )
    return found


def _require_a_file(path: str | os.PathLike) -> None:
    try:
        mode = os.stat(path).st_mode
    except (OSError, ValueError):
        return  # a missing file is said where it is opened, with the same words everywhere
    if stat.S_ISFIFO(mode) or stat.S_ISCHR(mode) or stat.S_ISBLK(mode) or stat.S_ISSOCK(mode):
        kind = "a pipe" if stat.S_ISFIFO(mode) else "a socket" if stat.S_ISSOCK(mode) else "a device"
        raise InputError(f"{path}: is {kind}, not a file; gyrocomp reads an input more than once (its first bytes "
                         "tell the format, then its rows): save it to a file first")


def output_format(path: str | os.PathLike, option: str = "-o", default: str | None = None) -> str:
    """The table format an output path asks for by its suffix (``default`` when it names none)."""
    found = detect_table_format(Path(path)) or default
    if found not in TABLE_FORMATS:
        raise InputError(f"{option} {path}: gyrocomp writes CSV or Parquet; name the file .csv or .parquet")
    return found


#: the reader of each format that is not a table (tables: io.tables): format name -> read(path, options, progress)
LOG_READERS = {"ulog": read_ulog, "dataflash": read_dataflash, "rosbag": read_rosbag, "hdf5": read_hdf5}


def _log_reader(fmt: str):
    """The registered reader of ``fmt``; a name no reader has is refused (no fall-through to another reader)."""
    if fmt not in LOG_READERS:
        raise InputError(f"fmt: no reader for {fmt!r}; the formats are {', '.join(FORMATS)}")
    return LOG_READERS[fmt]


def read_input(
    path: str | os.PathLike,
    options: ReadOptions | None = None,
    *,
    fmt: str | None = None,
    progress: ProgressCallback | None = None,
) -> TableData:
    """Read any supported file, keeping what is needed to write results back.

    Tables keep their own columns and units; logs become a table in the default layout
    ([s], [deg/s], [g], [degC]).
    """
    if not isinstance(path, (str, os.PathLike)):
        raise InputError(f"path: expected a file name or path, got {type(path).__name__}")
    options = options or ReadOptions()
    fmt = detect_format(path, fmt)
    if not Path(path).exists():
        raise InputError(f"{path}: no such file")
    if fmt in TABLE_FORMATS:
        data = read_table(path, options.layout, fmt=fmt, drop_nonfinite=options.drop_nonfinite,
                          channels=options.channels)
        if progress:
            progress(1.0)
    else:
        data = table_data(_log_reader(fmt)(path, options, progress))
    return data if options.time_range_s is None else select_time(data, options.time_range_s)


def select_time(data: TableData, time_range_s: tuple[float | None, float | None]) -> TableData:
    """The rows of ``data`` from A to B seconds after its first sample, [A, B) [s] (None: an open end); refuses a
    range that holds no sample, naming the file's length."""
    start, stop = time_range_s
    if start is not None and stop is not None and not start < stop:
        raise InputError(f"time_range_s: {start:g}:{stop:g} is empty; give A:B with A < B [s from the file's start]")
    rec = data.recording
    since = rec.time_s - rec.time_s[0]
    keep = np.ones(rec.n_samples, dtype=bool)
    if start is not None:
        keep &= since >= start
    if stop is not None:
        keep &= since < stop
    if not keep.any():
        raise InputError(f"{rec.source}: time_range_s={'' if start is None else f'{start:g}'}:"
                         f"{'' if stop is None else f'{stop:g}'} holds no sample; the file lasts {since[-1]:.6g} s "
                         "from its first sample")
    return dataclasses.replace(data, recording=rec.take(keep), kept_rows=data.kept_rows[keep])


def instances(path: str | os.PathLike, fmt: str | None = None) -> tuple[int, ...]:
    """The sensor instances a log holds (PX4 uORB ``multi_id``, ArduPilot IMU number from 0), sorted; ``(0,)`` for
    a table, a ROS bag or an HDF5 file (one sensor each)."""
    fmt = detect_format(path, fmt)
    if not Path(path).exists():
        raise InputError(f"{path}: no such file")
    if fmt == "ulog":
        return ulog_instances(path)
    if fmt == "dataflash":
        return dataflash_instances(path)
    return (0,)


def read(
    path: str | os.PathLike,
    layout: TableLayout | None = None,
    *,
    config: str | os.PathLike | None = None,
    columns: dict[str, str] | None = None,
    gyro_unit: str | None = None,
    accel_unit: str | None = None,
    time_unit: str | None = None,
    delimiter: str | None = None,
    decimal: str | None = None,
    fmt: str | None = None,
    drop_nonfinite: bool | None = None,
    instance: int | None = None,
    device_id: int | None = None,
    imu_topic: str | None = None,
    temperature_topic: str | None = None,
    record: str | None = None,
    channels: tuple[str, ...] | None = None,
    time_range_s: tuple[float | None, float | None] | None = None,
    progress: ProgressCallback | None = None,
) -> Recording:
    """Read any supported file into a :class:`Recording` [s, deg/s, g, degC].

    Parameters
    ----------
    path : path
        A CSV or Parquet table, PX4 ULog, ArduPilot DataFlash log, ROS bag, or HDF5/NetCDF-4 file.
    layout : TableLayout, optional
        Column mapping and units (tables, HDF5); or give its fields one by one (``columns``, ``gyro_unit``, ...).
    config : path, optional
        A project file (``gyrocomp.toml``, which ``gyrocomp init`` writes): its ``[read]`` section's options, as
        every command run beside it reads files (:func:`gyrocomp.io.project.project_read_options`); an option
        given here as well wins.
    columns : dict, optional
        Canonical channel (``time``, ``gyro_z``, ``temperature`` ...) to the file's column name.
    gyro_unit, accel_unit, time_unit : str, optional
        The columns' units: ``deg/s``, ``rad/s`` or ``mdps``; ``g``, ``mg`` or ``m/s2``; ``s``, ``ms``, ``us``
        or ``ns`` (default deg/s, g, s).
    delimiter, decimal : str, optional
        A text table's field separator and decimal point (default: told from the file).
    fmt : str, optional
        The format (default: told from the file).
    drop_nonfinite : bool, optional
        Drop rows with NaN or infinite values instead of refusing the file (default False).
    instance, device_id : int, optional
        Autopilot logs: the sensor instance (PX4 ``multi_id``, ArduPilot ``I``), or the PX4 device id.
    imu_topic, temperature_topic : str, optional
        ROS bags: the topics of the ``sensor_msgs/Imu`` and ``sensor_msgs/Temperature`` messages.
    record : str, optional
        ArduPilot DataFlash: ``"IMU"`` (default) or ``"TCLR"``.
    channels : tuple of str, optional
        Tables: read only these channels' columns (``time`` always).
    time_range_s : (float or None, float or None), optional
        Only the samples from A to B seconds after the file's first, [A, B) [s] (None: an open end).
    progress : callable, optional
        Called with the fraction done.

    Notes
    -----
    The same options as :class:`ReadOptions` (its doc says more of each).
    """
    layout_fields = {"columns": columns, "gyro_unit": gyro_unit, "accel_unit": accel_unit, "time_unit": time_unit,
                     "delimiter": delimiter, "decimal": decimal}
    others = {"drop_nonfinite": drop_nonfinite, "instance": instance, "device_id": device_id, "imu_topic": imu_topic,
              "temperature_topic": temperature_topic, "record": record, "channels": channels,
              "time_range_s": time_range_s}
    options, project_fmt = _merged_options(config, layout, layout_fields, others)
    return read_input(path, options, fmt=fmt or project_fmt, progress=progress).recording


def _merged_options(config, layout: TableLayout | None, layout_fields: dict, others: dict
                    ) -> tuple[ReadOptions, str | None]:
    """The reading options of :func:`read`: the project file's (``config``), then what was given (not None)."""
    base, fmt = project_read_options(config) if config is not None else (ReadOptions(), None)
    given_layout = {k: v for k, v in layout_fields.items() if v is not None}
    if layout is not None and given_layout:
        raise InputError(f"layout: give a TableLayout or its fields ({', '.join(given_layout)}), not both")
    layout = layout or dataclasses.replace(base.layout, **given_layout)
    return dataclasses.replace(base, layout=layout, **{k: v for k, v in others.items() if v is not None}), fmt


__all__ = [
    "FORMATS",
    "FORMAT_SPELLING",
    "LOG_FORMATS",
    "LOG_READERS",
    "ReadOptions",
    "TableData",
    "TableLayout",
    "atomic_path",
    "detect_format",
    "detect_table_format",
    "file_sha256",
    "instances",
    "output_format",
    "parse_column_mapping",
    "read",
    "read_input",
    "read_table",
    "recording_table",
    "refuse_to_overwrite_inputs",
    "sniff_format",
    "write_gyro_back",
    "write_recording",
    "write_rows",
    "write_text_atomic",
]
