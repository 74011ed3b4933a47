"""ArduPilot DataFlash ``.bin`` reader (optional extra ``[dataflash]``, pymavlink).

pymavlink indexes the log (message formats and the offset of every message); the fields of the
records read are then unpacked in bulk with numpy from the memory-mapped file, so a long log is
not turned into millions of Python objects.

Records: ``IMU`` (rad/s, m/s^2, ``T`` degC; the instance in the ``I`` field on current firmware,
or ``IMU2``/``IMU3`` records on older firmware), or ``TCLR``, the onboard temperature learner's
records (``SType`` 0 accelerometer, 1 gyro; ``Temp``; ``X,Y,Z``), as ArduPilot's
``Tools/scripts/tempcal_IMU.py --tclr`` reads them. A log cut off mid-message (a truncated
download) is read up to its last whole message, with a warning.
"""

from __future__ import annotations

import functools
import re
import warnings
from pathlib import Path

import numpy as np

from ..errors import DataQualityWarning, InputError, foreign_message, user_stacklevel
from ..recording import Recording
from ..units import unit_factor
from .log_samples import keep_matched, log_recording, match_by_time, order_by_time
from .foreign_libraries import foreign_output, require
from .read_options import ProgressCallback, ReadOptions
from .readers import Reader, check_magic, register_reader

DATAFLASH_MAGIC = b"\xa3\x95"
RECORDS = ("IMU", "TCLR")
_US = unit_factor("time", "us")
_RAD = unit_factor("gyro", "rad/s")
_MS2 = unit_factor("accel", "m/s2")
_STRUCT_TO_NUMPY = {
    "b": "i1",
    "B": "u1",
    "h": "<i2",
    "H": "<u2",
    "i": "<i4",
    "I": "<u4",
    "q": "<i8",
    "Q": "<u8",
    "f": "<f4",
    "d": "<f8",
}
_TCLR_ACCEL, _TCLR_GYRO = 0, 1
#: the fields of an IMU record that are read (``T``, the temperature, where it has one)
_IMU_FIELDS = ("TimeUS", "GyrX", "GyrY", "GyrZ", "AccX", "AccY", "AccZ")


def _dtype(fmt) -> np.dtype:
    """A numpy record type for a message body, from pymavlink's struct string (``<QffffffIIfBBHH``)."""
    names, formats = [], []
    for count, code in re.findall(r"(\d*)([a-zA-Z])", fmt.msg_struct.lstrip("<")):
        n = int(count) if count else 1
        if code == "s":
            formats.append(f"S{n}")
        elif code in _STRUCT_TO_NUMPY:
            formats.append(_STRUCT_TO_NUMPY[code] if n == 1 else (_STRUCT_TO_NUMPY[code], (n,)))
        else:
            raise InputError(f"DataFlash message {fmt.name}: field type {code!r} cannot be read")
        names.append(fmt.columns[len(names)] if len(names) < len(fmt.columns) else f"_{len(names)}")
    return np.dtype({"names": names, "formats": formats})


class _CheckedFormats(dict):
    """pymavlink's table of message formats, keeping out one whose length is under the 3 bytes of a message's
    header: pymavlink steps to the next message by that length, so a corrupt FMT record of length 0 to 2 (a zeroed
    or flipped byte) would have it read the same message again and again, never returning. The first one left out
    is in :attr:`corrupt` (pymavlink catches what its parsing raises, so it is not raised here)."""

    corrupt: str | None = None

    def __setitem__(self, type_id, fmt) -> None:
        if fmt.len < 3:
            self.corrupt = self.corrupt or (
                f"a FMT record defines message type {type_id} ({fmt.name!r}) with a length of {fmt.len} bytes, under "
                "its 3-byte header"
            )
            return
        super().__setitem__(type_id, fmt)


@functools.cache
def _checked_reader(DFReader):
    """pymavlink's binary reader whose format table is :class:`_CheckedFormats` before it indexes the log."""

    class CheckedReader(DFReader.DFReader_binary):
        def init_arrays(self, *args, **kwargs):
            self.formats = _CheckedFormats(self.formats)
            return super().init_arrays(*args, **kwargs)

        def init_arrays_fast(self, *args, **kwargs):
            self.formats = _CheckedFormats(self.formats)
            return super().init_arrays_fast(*args, **kwargs)

    return CheckedReader


class _Log:
    """The indexed log: message types by name and a reader of all records of one type."""

    def __init__(self, path: Path, progress: ProgressCallback | None):
        DFReader = require("pymavlink.DFReader", "dataflash", "reading ArduPilot DataFlash logs")
        self.path = path
        try:
            with foreign_output(str(path), "pymavlink"):
                self.reader = _checked_reader(DFReader)(
                    str(path),
                    zero_time_base=False,
                    progress_callback=(lambda pct: progress(0.8 * pct / 100.0)) if progress else None,
                )
        except Exception as exc:  # pymavlink raises assorted errors on corrupt files
            raise InputError(f"{path}: not a readable DataFlash log ({foreign_message(exc)})") from None
        corrupt = getattr(self.reader.formats, "corrupt", None)
        if corrupt is not None:
            self.reader.close()
            raise InputError(f"{path}: not a readable DataFlash log: {corrupt} (a corrupt log)")
        self.bytes = np.frombuffer(self.reader.data_map, dtype=np.uint8)
        self.types = {fmt.name: type_id for type_id, fmt in self.reader.formats.items()}
        self.cut_bytes = self._truncation()

    def _truncation(self) -> int:
        """Bytes after the last whole message (0 for a complete log)."""
        end = 0
        for type_id, offsets in enumerate(self.reader.offsets):
            if offsets and type_id in self.reader.formats:
                length = self.reader.formats[type_id].len
                whole = [o for o in offsets[-2:] if o + length <= self.bytes.size]
                if whole:
                    end = max(end, whole[-1] + length)
        return int(self.bytes.size - end)

    def close(self) -> None:
        del self.bytes  # the mmap cannot close while a numpy view of it exists
        self.reader.close()

    def has(self, name: str) -> bool:
        type_id = self.types.get(name)
        return type_id is not None and bool(self.reader.offsets[type_id])

    def fields(self, name: str) -> tuple[str, ...]:
        """The field names of a message type, from its format (no record is read)."""
        return _dtype(self.reader.formats[self.types[name]]).names

    def records(self, name: str, needed: tuple[str, ...] = ()) -> np.ndarray:
        """Every whole ``name`` message as a numpy record array (multipliers applied by the caller); refused when
        its format (a FMT record, corrupt in a damaged log) lacks a ``needed`` field or disagrees with its length."""
        type_id = self.types[name]
        fmt = self.reader.formats[type_id]
        dtype = _dtype(fmt)
        missing = [f for f in needed if f not in dtype.names]
        if missing or dtype.itemsize != fmt.len - 3:
            said = (
                f"no field {', '.join(missing)}" if missing else f"{fmt.len} bytes for fields of {dtype.itemsize + 3}"
            )
            raise InputError(
                f"{self.path}: the log's format of {name} messages has {said} (fields {', '.join(dtype.names)}): "
                "its FMT record is corrupt, or the log is no ArduPilot one"
            )
        offsets = np.asarray(self.reader.offsets[type_id], dtype=np.int64)
        offsets = offsets[offsets + fmt.len <= self.bytes.size]
        body = self.bytes[offsets[:, None] + 3 + np.arange(fmt.len - 3)]
        return np.ascontiguousarray(body).view(dtype).reshape(-1)

    def parameters(self) -> dict[str, float]:
        if not self.has("PARM"):
            return {}
        parm = self.records("PARM", ("Name", "Value"))
        return {
            name.split(b"\0")[0].decode("ascii", "replace"): float(value)
            for name, value in zip(parm["Name"], parm["Value"])
        }


def _instances(log: _Log) -> list[int]:
    """The IMU instances of a log: the ``I`` field's values, or which of IMU, IMU2, IMU3 it has (older firmware)."""
    if log.has("IMU") and "I" in log.fields("IMU"):
        return sorted(set(int(i) for i in np.unique(log.records("IMU", ("I",))["I"])))
    return [i for i, name in enumerate(("IMU", "IMU2", "IMU3")) if log.has(name)]


def dataflash_instances(path) -> tuple[int, ...]:
    """The IMU instances (from 0) of an ArduPilot DataFlash log, sorted."""
    path = Path(path)
    check_magic(path, DATAFLASH_MAGIC, "ArduPilot DataFlash", "name its real format with fmt=")
    log = _Log(path, None)
    try:
        return tuple(_instances(log))
    finally:
        log.close()


def _instance_records(log: _Log, instance: int) -> np.ndarray:
    if log.has("IMU") and "I" in log.fields("IMU"):
        imu = log.records("IMU", _IMU_FIELDS)
        found = _instances(log)
        if instance not in found:
            raise InputError(
                f"{log.path}: instance={instance}: no IMU instance {instance}; the log has {', '.join(map(str, found))}"
            )
        return imu[imu["I"] == instance], found
    names = ["IMU", "IMU2", "IMU3"]
    found = _instances(log)
    if instance not in found:
        raise InputError(
            f"{log.path}: instance={instance}: no {names[instance] if instance < 3 else 'IMU'} "
            f"records; the log has instance(s) {', '.join(map(str, found))}"
        )
    return log.records(names[instance], _IMU_FIELDS), found


def _from_imu(log: _Log, instance: int, explicit: bool):
    if not (log.has("IMU") or log.has("IMU2")):
        present = sorted(name for name in log.types if log.has(name))
        raise InputError(f"{log.path}: no IMU records in this log; it has {', '.join(present) or 'none'}")
    imu, found = _instance_records(log, instance)
    if not explicit and len(found) > 1:
        warnings.warn(
            f"{log.path}: {len(found)} IMU instances ({', '.join(map(str, found))}); read instance "
            f"{instance}, choose another with instance=",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )
    time_s = imu["TimeUS"].astype(float) * _US
    gyro = np.column_stack([imu[f"Gyr{a}"] for a in "XYZ"]).astype(float) * _RAD
    accel = np.column_stack([imu[f"Acc{a}"] for a in "XYZ"]).astype(float) * _MS2
    temperature = imu["T"].astype(float) if "T" in imu.dtype.names else None
    return order_by_time(str(log.path), time_s, gyro, accel, temperature)


def _from_tclr(log: _Log, instance: int):
    if not log.has("TCLR"):
        raise InputError(
            f"{log.path}: record=TCLR: no TCLR records in this log "
            "(the onboard learner writes them while INS_TCALn_ENABLE = 2)"
        )
    tclr = log.records("TCLR", ("TimeUS", "I", "SType", "X", "Y", "Z", "Temp"))
    tclr = tclr[tclr["I"] == instance]
    gyro_rows, accel_rows = tclr[tclr["SType"] == _TCLR_GYRO], tclr[tclr["SType"] == _TCLR_ACCEL]
    if gyro_rows.size < 2:
        raise InputError(
            f"{log.path}: record=TCLR: {gyro_rows.size} gyro record(s) for instance {instance}; at least 2 are needed"
        )
    time_s, gyro, temperature = order_by_time(
        str(log.path),
        gyro_rows["TimeUS"].astype(float) * _US,
        np.column_stack([gyro_rows[a] for a in "XYZ"]).astype(float) * _RAD,
        gyro_rows["Temp"].astype(float),
    )
    accel = None
    if accel_rows.size >= 2:
        a_time, a_values = order_by_time(
            str(log.path),
            accel_rows["TimeUS"].astype(float) * _US,
            np.column_stack([accel_rows[a] for a in "XYZ"]).astype(float) * _MS2,
        )
        accel, ok = match_by_time(str(log.path), "the TCLR accelerometer records", time_s, a_time, a_values)
        keep = keep_matched(str(log.path), "the TCLR accelerometer records", ok)
        time_s, gyro, accel, temperature = time_s[keep], gyro[keep], accel[keep], temperature[keep]
    return time_s, gyro, accel, temperature


def _warn_of_parameters(path: Path, params: dict, instance: int, corrected: bool) -> None:
    """Warn where the log's parameters say its IMU axes are rotated, or its data already corrected onboard."""
    orientation = params.get("AHRS_ORIENTATION", 0.0)
    if orientation:
        warnings.warn(
            f"{path}: AHRS_ORIENTATION = {orientation:g}: the logged IMU axes are the board's, rotated "
            "from the sensor's; INS_TCAL parameters apply in the sensor frame",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )
    if corrected:
        warnings.warn(
            f"{path}: INS_TCAL{instance + 1}_ENABLE = 1: the logged IMU data are already corrected by "
            "the onboard temperature calibration",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )


def read_dataflash(path, options: ReadOptions | None = None, progress: ProgressCallback | None = None) -> Recording:
    """Read an ArduPilot DataFlash log into a :class:`Recording` [s, deg/s, g, degC].

    Parameters
    ----------
    path : path
        The ``.bin`` log.
    options : ReadOptions, optional
        ``instance`` (IMU number from 0, default 0) and ``record`` (``"IMU"`` or ``"TCLR"``).
    progress : callable, optional
        Called with the fraction done.
    """
    options = options or ReadOptions()
    path = Path(path)
    check_magic(
        path,
        DATAFLASH_MAGIC,
        "ArduPilot DataFlash",
        "name its real format with fmt=, or leave fmt= out to have it told from the file",
    )
    record = (options.record or "IMU").upper()
    if record not in RECORDS:
        raise InputError(f"record: unknown DataFlash record {options.record!r}; use IMU or TCLR")
    log = _Log(path, progress)
    try:
        if log.cut_bytes >= 3:
            warnings.warn(
                f"{path}: the log ends mid-message ({log.cut_bytes} bytes after the last whole message, "
                "a truncated download?); read up to there",
                DataQualityWarning,
                stacklevel=user_stacklevel(),
            )
        instance = 0 if options.instance is None else options.instance
        if record == "TCLR":
            time_s, gyro, accel, temperature = _from_tclr(log, instance)
        else:
            time_s, gyro, accel, temperature = _from_imu(log, instance, options.instance is not None)
        params = log.parameters()
    finally:
        log.close()
    corrected = params.get(f"INS_TCAL{instance + 1}_ENABLE") == 1.0 and record == "IMU"
    _warn_of_parameters(path, params, instance, corrected)
    if progress:
        progress(1.0)
    metadata = {"path": str(path), "format": "dataflash", "autopilot": "ardupilot", "record": record}
    metadata.update(instance=instance, corrected_onboard=corrected)
    # the installed thermal calibration and the temperatures its gyro offsets were taken at
    metadata["autopilot_parameters"] = {
        k: v for k, v in params.items() if k.startswith("INS_TCAL") or k.endswith("_CALTEMP")
    }
    metadata["truncated_bytes"] = log.cut_bytes if log.cut_bytes >= 3 else 0
    return log_recording(path, options, time_s, gyro, accel, temperature, metadata)


register_reader(
    Reader(
        "dataflash",
        "ArduPilot DataFlash, extra [dataflash]",
        read_dataflash,
        suffixes=(".bin",),
        magic=(DATAFLASH_MAGIC,),
        aliases=("bin", "ardupilot"),
        instances=dataflash_instances,
    )
)
