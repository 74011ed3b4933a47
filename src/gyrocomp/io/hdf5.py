"""HDF5 and NetCDF-4 reader (optional extra ``[hdf5]``, h5py).

A channel is a one-dimensional dataset (``time``, ``gyro_z``, ``temperature`` ...) or, for
``gyro`` and ``accel``, a two-dimensional dataset of shape (n, 3) (x, y, z columns).
Without a mapping, datasets are looked up under gyrocomp's names and common ones
(``angular_velocity``, ``acceleration``, ``timestamp`` ...). Units come from each dataset's
``units`` attribute when it names a unit gyrocomp knows (CF conventions: ``"mrad/s"``,
``"m/s2"``, ``"seconds since 2021-09-20 08:52:00"``, ``"C"``), else from the options. A file without a time
dataset is timed by the layout's ``rate_hz`` (sample n at n / rate). The same reading of named arrays serves the
formats read whole into memory (MATLAB files, NumPy ``.npz``: :mod:`gyrocomp.io.matlab`) through
:class:`ArrayStore` (:func:`named_arrays_recording`).
"""

from __future__ import annotations

import contextlib
import re
import warnings
from pathlib import Path

import numpy as np

from ..errors import DataQualityWarning, GyrocompError, InputError, LayoutError, printable, user_stacklevel
from ..recording import ACCEL_AXES, GYRO_AXES, TEMPERATURE_COLUMN, Recording
from ..units import unit_factor
from .log_samples import log_recording
from .foreign_libraries import require
from .read_options import ProgressCallback, ReadOptions
from .readers import Reader, check_magic, register_reader
from .layout import TIME_COLUMN, UNMAPPED

HDF5_MAGIC = b"\x89HDF\r\n\x1a\n"
NETCDF3_MAGIC = b"CDF"
#: names tried, in order, for each channel when the mapping does not name it
COMMON_NAMES = {
    TIME_COLUMN: ("time", "time_s", "timestamp", "timestamp_utc", "t"),
    "gyro": ("gyro", "angular_velocity", "gyroscope", "angular_rate"),
    "accel": ("accel", "acceleration", "accelerometer", "linear_acceleration"),
    TEMPERATURE_COLUMN: ("temperature", "temp", "temperature_degc"),
}
_CELSIUS = {"c", "degc", "deg_c", "celsius", "degree_celsius", "degrees_celsius", "°c"}


def _attribute_text(dataset, key: str) -> str | None:
    """A dataset's text attribute ``key`` (bytes, a string, or an array holding one), None where it has none."""
    value = dataset.attrs.get(key)
    if value is None:
        return None
    if isinstance(value, np.ndarray):
        value = value.reshape(-1)[0]
    return value.decode("utf-8", "replace") if isinstance(value, bytes) else str(value)


def _units(dataset) -> str | None:
    return _attribute_text(dataset, "units")


def _stated_rates(name: str, dataset) -> dict[str, float]:
    """A dataset's attributes that state its sample rate as one number (NetCDF files of loggers write
    ``sampling_rate = 10`` with ``sampling_rate_units = "Hz"``), keyed ``NAME@ATTRIBUTE``; one whose units
    attribute says anything but Hz is left out."""
    out = {}
    for key, value in dataset.attrs.items():
        words = set(re.split(r"[^a-z]+", key.lower()))
        if not words & {"rate", "fs", "frequency"} or "units" in words:
            continue
        number = np.asarray(value).reshape(-1)
        if number.size != 1 or number.dtype.kind not in "iuf" or not np.isfinite(number[0]):
            continue
        if (_attribute_text(dataset, f"{key}_units") or "Hz").strip().lower() != "hz":
            continue
        out[f"{name}@{key}"] = float(number[0])
    return out


def _factor(kind: str, dataset, fallback: str, option: str, source: str) -> float:
    """Factor to gyrocomp's units: from the dataset's ``units`` attribute when known, else the option's unit."""
    units = _units(dataset)
    if units is not None:
        unit = units.split(" since ")[0].strip() if kind == "time" else units.strip()
        unit = {"seconds": "s", "second": "s", "milliseconds": "ms", "microseconds": "us"}.get(unit, unit)
        try:
            return unit_factor(kind, unit)
        except InputError:
            warnings.warn(
                f"{source}: dataset {dataset.name} has units {units!r}, which gyrocomp does not know; "
                f"read as {fallback} (set {option}= if that is wrong)",
                DataQualityWarning,
                stacklevel=user_stacklevel(),
            )
    return unit_factor(kind, fallback, option)


@contextlib.contextmanager
def opened_hdf5(h5py, path: Path):
    """The open file; what HDF5 reports about a damaged one (a truncated file, a bad signature or B-tree, a
    failed read) becomes an InputError naming the file. Permission and missing-file errors stay as they are."""
    try:
        with h5py.File(path, "r") as handle:
            yield handle
    except (PermissionError, FileNotFoundError, IsADirectoryError, GyrocompError):
        raise
    except (OSError, KeyError, RuntimeError) as exc:  # h5py's KeyError: an object of a damaged file that won't open
        raise InputError(
            f"{path}: not a readable HDF5 file ({printable(str(exc))[:200]}); is it damaged or cut short?"
        ) from None


def _in_this_file(dataset, source: str) -> None:
    """Refuse, naming the dataset, one whose values would come from another file: HDF5 external storage (raw
    bytes of any file named in the dataset's layout), a virtual dataset (a map onto other files) or an external
    link (the dataset itself in another file). A reader reads the file it was given, nothing beside it."""
    how = (
        "is stored in external files"
        if dataset.external
        else "is a virtual dataset mapped onto other files"
        if dataset.is_virtual
        else f"lies in another file, {dataset.file.filename!r} (an external link)"
        if Path(dataset.file.filename).resolve() != Path(source).resolve()
        else None
    )
    if how is not None:
        raise InputError(
            f"{source}: dataset {dataset.name!r} {how}; gyrocomp reads only the file it is given "
            "(copy the data into the file, e.g. with h5repack)"
        )


#: ``NAME[:, k]``: column k of a two-dimensional dataset, given as a channel's column
_COLUMN_OF = re.compile(r"^(?P<name>.+?)\[\s*:\s*,\s*(?P<k>\d+)\s*\]$")


class _Column:
    """Column ``k`` of a two-dimensional dataset, read as a dataset of its own (``columns=`` ``NAME[:, k]``)."""

    def __init__(self, dataset, k: int, source: str):
        if dataset.ndim != 2 or not 0 <= k < dataset.shape[1]:
            raise InputError(
                f"{source}: columns= {dataset.name}[:, {k}]: the dataset has shape {dataset.shape}; "
                f"[:, k] needs two dimensions and k below {dataset.shape[-1] if dataset.ndim else 0}"
            )
        self.dataset, self.k = dataset, k
        self.name, self.attrs, self.shape = f"{dataset.name}[:, {k}]", dataset.attrs, (dataset.shape[0],)


def _numbers(dataset, source: str) -> np.ndarray:
    """The dataset's values as floats; a dataset of strings, compounds or references is refused by name, and one
    whose values lie in another file (:func:`_in_this_file`)."""
    if isinstance(dataset, _Column):
        return _numbers(dataset.dataset, source)[:, dataset.k]
    _in_this_file(dataset, source)
    if dataset.dtype.kind not in "biuf":
        raise InputError(
            f"{source}: dataset {dataset.name!r} holds {dataset.dtype} values, not numbers; "
            "store numbers, or map another dataset with columns="
        )
    return np.asarray(dataset[()], dtype=float)


def _temperature(dataset, source: str) -> np.ndarray:
    values = _numbers(dataset, source)
    units = (_units(dataset) or "degC").strip().lower()
    if units in _CELSIUS:
        return values
    if units in ("k", "kelvin"):
        return values - 273.15
    raise InputError(f"{source}: dataset {dataset.name!r} has units {units!r}; expected degC or K")


def _find(handle, source: str, channel: str, mapping: dict[str, str]):
    if mapping.get(channel) == UNMAPPED:  # the time left unread: the samples at the layout's rate
        return None
    if channel in mapping:
        name = mapping[channel]
        column = _COLUMN_OF.match(name)
        if column and column["name"] in handle and name not in handle:
            return _Column(handle[column["name"]], int(column["k"]), source)
        if name not in handle:
            raise InputError(
                f"{source}: columns={{{channel!r}: {name!r}}}: no dataset {name!r}; "
                f"the file has {', '.join(_datasets(handle))}"
            )
        return handle[name]
    for name in COMMON_NAMES.get(channel, (channel,)):
        if name in handle and hasattr(handle[name], "shape"):
            return handle[name]
    return None


def _datasets(handle) -> list[str]:
    names: list[str] = []
    handle.visititems(lambda name, obj: names.append(name) if hasattr(obj, "shape") else None)
    return names


def _vector(handle, source: str, kind: str, axes: tuple[str, ...], mapping: dict[str, str]):
    """The (n, k) channels of ``kind`` (gyro or accel) and their axis names, from one 2-D or several 1-D datasets
    (an axis mapped alone, ``gyro_x = "NAME[:, 0]"``, wins over a dataset found by its name for the whole)."""
    whole = None if any(axis in mapping for axis in axes) else _find(handle, source, kind, mapping)
    if whole is not None:
        values = _numbers(whole, source)
        if values.ndim == 1:
            values = values[:, None]
        if values.ndim != 2 or values.shape[1] not in (1, 3):
            raise InputError(f"{source}: dataset {whole.name!r} has shape {whole.shape}; expected (n,) or (n, 3)")
        names = axes if values.shape[1] == 3 else (axes[2],)
        return values, names, whole
    columns, names, first = [], [], None
    for axis in axes:
        dataset = _find(handle, source, axis, mapping) if axis in mapping or axis in handle else None
        if dataset is not None:
            columns.append(_numbers(dataset, source).reshape(-1))
            names.append(axis)
            first = first or dataset
    if not columns:
        return None, (), None
    return np.column_stack(columns), tuple(names), first


def _channels(handle, layout, path: Path, progress: ProgressCallback | None):
    """(time [s], gyro [deg/s], gyro axes, accel [g] or None, accel axes, temperature [degC] or None)."""
    source, mapping = str(path), dict(layout.columns)
    time_ds = _find(handle, source, TIME_COLUMN, mapping)
    if time_ds is None and layout.rate_hz is None:
        raise LayoutError(
            f"{path}: no time dataset (the file has {', '.join(_datasets(handle))}); "
            "map one with columns={'time': 'NAME'}, or give the samples' rate (rate_hz=100)",
            path,
        )
    if time_ds is not None and layout.rate_hz is not None:
        raise InputError(
            f"{path}: rate_hz={layout.rate_hz:g} is for a file without time, and this one has {time_ds.name!r}; "
            "to read the samples at it instead, leave the time unread (columns={'time': ''})"
        )
    time_s = None
    if time_ds is not None:
        time_s = _numbers(time_ds, source).reshape(-1) * _factor("time", time_ds, layout.time_unit, "time_unit", source)
    gyro, gyro_axes, gyro_ds = _vector(handle, source, "gyro", GYRO_AXES, mapping)
    if gyro is None:
        raise LayoutError(
            f"{path}: no gyro dataset (the file has {', '.join(_datasets(handle))}); "
            "map one with columns={'gyro': 'NAME'} (an (n, 3) array) or columns={'gyro_z': 'NAME'}",
            path,
        )
    if time_s is None:  # no time in the file: sample n at n / rate
        time_s = np.arange(gyro.shape[0]) / layout.rate_hz
    gyro = gyro * _factor("gyro", gyro_ds, layout.gyro_unit, "gyro_unit", source)
    if progress:
        progress(0.5)
    accel, accel_axes, accel_ds = _vector(handle, source, "accel", ACCEL_AXES, mapping)
    if accel is not None:
        accel = accel * _factor("accel", accel_ds, layout.accel_unit, "accel_unit", source)
    temp_ds = _find(handle, source, TEMPERATURE_COLUMN, mapping)
    temperature = _temperature(temp_ds, source) if temp_ds is not None else None
    return time_s, gyro, gyro_axes, accel, accel_axes, temperature


def named_arrays_recording(
    handle, path: Path, options: ReadOptions, progress: ProgressCallback | None, fmt: str
) -> Recording:
    """The recording [s, deg/s, g, degC] of a file of named arrays: an open HDF5 file, or an :class:`ArrayStore`
    (another format's arrays, in memory). Channels are found as the module says; ``fmt`` names the format in the
    recording's metadata."""
    time_s, gyro, gyro_axes, accel, accel_axes, temperature = _channels(handle, options.layout, path, progress)
    n = time_s.size
    for name, values in (("gyro", gyro), ("accel", accel), ("temperature", temperature)):
        if values is not None and values.shape[0] != n:
            raise InputError(
                f"{path}: {name} has {values.shape[0]} samples but time has {n}; "
                "map datasets of the same length with columns="
            )
    if progress:
        progress(1.0)
    return log_recording(
        path, options, time_s, gyro, accel, temperature, {"path": str(path), "format": fmt}, gyro_axes=gyro_axes
    )


class StoredArray:
    """An array in memory with what the reading of named arrays asks of an HDF5 dataset (its name, shape, dtype,
    ``units`` in ``attrs``, its values by ``[()]``), for formats read whole (NumPy's ``.npz``, MATLAB files)."""

    external = None
    is_virtual = False

    def __init__(self, name: str, values: np.ndarray, source: str, units: str | None = None):
        self.name, self._values = name, values
        self.shape, self.ndim, self.dtype = values.shape, values.ndim, values.dtype
        self.attrs = {} if units is None else {"units": units}
        self.file = _StoreFile(source)

    def __getitem__(self, key):
        return self._values[key]


class _StoreFile:
    def __init__(self, filename: str):
        self.filename = filename


class ArrayStore(dict):
    """Named :class:`StoredArray` s (name -> array), read as an HDF5 file's datasets are; beside them, what a file
    may say of them for guessing a layout: lists of names (``labels``, e.g. a matrix's column names) and numbers
    (``scalars``, e.g. its sample rate)."""

    def __init__(self):
        super().__init__()
        self.labels: dict[str, tuple[str, ...]] = {}
        self.scalars: dict[str, float] = {}

    def visititems(self, func) -> None:
        for name, value in self.items():
            func(name, value)


def sample_hdf5(path, rows: int) -> ArrayStore:
    """The first ``rows`` samples of each numeric dataset of one or two dimensions in an HDF5 file, with its
    ``units`` attribute (for guessing a layout: nothing else is read)."""
    path = Path(path)
    h5py = require("h5py", "hdf5", "reading HDF5/NetCDF files")
    store = ArrayStore()

    def visit(name, obj) -> None:
        if isinstance(obj, h5py.Dataset) and obj.dtype.kind in "iuf" and obj.ndim in (1, 2) and obj.shape[0] > 1:
            _in_this_file(obj, str(path))
            store[name] = StoredArray(name, np.asarray(obj[:rows]), str(path), _units(obj))
            store.scalars.update(_stated_rates(name, obj))

    with opened_hdf5(h5py, path) as handle:
        handle.visititems(visit)
    return store


def read_hdf5(path, options: ReadOptions | None = None, progress: ProgressCallback | None = None) -> Recording:
    """Read an HDF5 or NetCDF-4 file into a :class:`Recording` [s, deg/s, g, degC].

    Parameters
    ----------
    path : path
        The ``.h5`` / ``.hdf5`` / ``.nc`` file.
    options : ReadOptions, optional
        ``layout.columns`` maps channels to dataset paths (``time=timestamp_utc,gyro=angular_velocity``);
        ``layout``'s units apply where a dataset has no ``units`` attribute; ``layout.rate_hz`` times the samples
        of a file without a time dataset.
    progress : callable, optional
        Called with the fraction done.
    """
    options = options or ReadOptions()
    path = Path(path)
    if not path.exists():
        raise InputError(f"{path}: no such file")
    with open(path, "rb") as fh:
        head = fh.read(8)
    if head.startswith(NETCDF3_MAGIC):
        raise InputError(
            f"{path}: a NetCDF-3 (classic) file; gyrocomp reads NetCDF-4, convert it with 'nccopy -k nc4 IN OUT'"
        )
    if not head.startswith(HDF5_MAGIC):
        check_magic(
            path,
            HDF5_MAGIC,
            "HDF5/NetCDF-4",
            "name its real format with fmt=, or leave fmt= out to have it told from the file",
        )
    h5py = require("h5py", "hdf5", "reading HDF5/NetCDF files")
    with opened_hdf5(h5py, path) as handle:
        return named_arrays_recording(handle, path, options, progress, "hdf5")


register_reader(
    Reader(
        "hdf5",
        "HDF5 or NetCDF-4, extra [hdf5]",
        read_hdf5,
        suffixes=(".h5", ".hdf5", ".nc", ".nc4"),
        magic=(HDF5_MAGIC,),
        aliases=("h5", "netcdf", "nc"),
        layout=True,
    )
)

__all__ = ["ArrayStore", "StoredArray", "named_arrays_recording", "opened_hdf5", "read_hdf5", "sample_hdf5"]
