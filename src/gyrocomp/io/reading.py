"""Readers and writers. Every reader returns a :class:`gyrocomp.recording.Recording` in internal units.

Formats: the readers registered in :mod:`gyrocomp.io.read_formats` (CSV and Parquet tables; PX4 ULog, extra
``[ulog]``; ArduPilot DataFlash, ``[dataflash]``; ROS 1 / ROS 2 bags, ``[ros]``; HDF5 / NetCDF-4, ``[hdf5]``). The
format is told from the file's first bytes, then its name, and can be named instead
(:func:`gyrocomp.io.readers.detect_format`).
"""

from __future__ import annotations

import dataclasses
import os
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..recording import Recording
from ..option_spelling import Spelling
from .atomic import atomic_path, refuse_to_overwrite_inputs, write_text_atomic
from .read_options import ProgressCallback, ReadOptions
from .project import project_read_options
from . import read_formats  # noqa: F401  registers every reader
from .readers import (
    READERS,
    Reader,
    detect_format,
    format_help,
    format_names,
    instances,
    reader_named,
    register_reader,
    sniff_format,
    table_formats,
)
from .tables import (
    TableData,
    TableLayout,
    detect_table_format,
    file_sha256,
    parse_column_mapping,
    read_table,
    recording_table,
    write_gyro_back,
    write_recording,
    write_rows,
)


def format_spelling() -> Spelling:
    """The reading functions' ``fmt`` parameter on the command line, its help listing the registered formats."""
    return Spelling("--format", format_help())


def output_format(path: str | os.PathLike, option: str = "-o", default: str | None = None) -> str:
    """The table format an output path asks for by its suffix (``default`` when it names none)."""
    found = detect_table_format(Path(path)) or default
    if found not in table_formats():
        raise InputError(f"{option} {path}: gyrocomp writes CSV or Parquet; name the file .csv or .parquet")
    return found


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
    data = READERS[fmt].read_table_data(Path(path), options, progress)
    return data if options.time_range_s is None else select_time(data, options.time_range_s)


#: the recording's metadata key of the window ``--time`` read from its file ((A, B) [s from the file's start], None
#: for an open end): a model's provenance keeps it, so that only those rows of the file are called in-sample
TIME_RANGE_KEY = "time_range_s"


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
        raise InputError(
            f"{rec.source}: time_range_s={'' if start is None else f'{start:g}'}:"
            f"{'' if stop is None else f'{stop:g}'} holds no sample; the file lasts {since[-1]:.6g} s "
            "from its first sample"
        )
    kept = rec.take(keep)
    kept = dataclasses.replace(kept, metadata={**kept.metadata, TIME_RANGE_KEY: (start, stop)})
    return dataclasses.replace(data, recording=kept, kept_rows=data.kept_rows[keep])


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
    layout_fields = {
        "columns": columns,
        "gyro_unit": gyro_unit,
        "accel_unit": accel_unit,
        "time_unit": time_unit,
        "delimiter": delimiter,
        "decimal": decimal,
    }
    others = {
        "drop_nonfinite": drop_nonfinite,
        "instance": instance,
        "device_id": device_id,
        "imu_topic": imu_topic,
        "temperature_topic": temperature_topic,
        "record": record,
        "channels": channels,
        "time_range_s": time_range_s,
    }
    options, project_fmt = _merged_options(config, layout, layout_fields, others)
    return read_input(path, options, fmt=fmt or project_fmt, progress=progress).recording


def _merged_options(
    config, layout: TableLayout | None, layout_fields: dict, others: dict
) -> tuple[ReadOptions, str | None]:
    """The reading options of :func:`read`: the project file's (``config``), then what was given (not None)."""
    base, fmt = project_read_options(config) if config is not None else (ReadOptions(), None)
    given_layout = {k: v for k, v in layout_fields.items() if v is not None}
    if layout is not None and given_layout:
        raise InputError(f"layout: give a TableLayout or its fields ({', '.join(given_layout)}), not both")
    layout = layout or dataclasses.replace(base.layout, **given_layout)
    return dataclasses.replace(base, layout=layout, **{k: v for k, v in others.items() if v is not None}), fmt


__all__ = [
    "TIME_RANGE_KEY",
    "READERS",
    "ReadOptions",
    "Reader",
    "TableData",
    "TableLayout",
    "atomic_path",
    "detect_format",
    "detect_table_format",
    "file_sha256",
    "format_help",
    "format_names",
    "format_spelling",
    "instances",
    "output_format",
    "parse_column_mapping",
    "read",
    "read_input",
    "read_table",
    "reader_named",
    "register_reader",
    "recording_table",
    "refuse_to_overwrite_inputs",
    "sniff_format",
    "table_formats",
    "write_gyro_back",
    "write_recording",
    "write_rows",
    "write_text_atomic",
]
