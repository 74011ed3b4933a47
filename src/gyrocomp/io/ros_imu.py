"""``sensor_msgs/Imu`` messages decoded and re-encoded a batch at a time, without a ROS installation (and
``sensor_msgs/Temperature`` messages decoded, the same way: a header, then the temperature and its variance).

A bag holds its IMU messages serialized one by one (ROS 1: the ROS serialization; ROS 2: CDR). rosbags decodes one
message in about 20 us, which is most of the time of reading a long bag (3.6e7 messages in ten hours at 1 kHz).
Messages of one topic usually have one length (the same ``frame_id``), and then every field sits at the same
offset in each: a batch of them is one (n, length) byte array whose fields numpy reads and writes at once.

The layouts (the messages' definitions, ``std_msgs/Header`` then ``geometry_msgs/Quaternion``, nine covariances,
``geometry_msgs/Vector3``, nine, ``Vector3``, nine; float64 throughout):

- ROS 1: ``seq`` uint32, ``stamp`` (sec uint32, nsec uint32), ``frame_id`` (uint32 length, bytes), then the 37
  float64 values, all little-endian and unaligned.
- ROS 2 CDR: a 4-byte encapsulation header (``00 01``: little-endian CDR), ``stamp`` (sec int32, nanosec uint32),
  ``frame_id`` (uint32 length counting its terminating NUL, bytes), padding to a multiple of 8 counted from the end
  of the encapsulation header, then the 37 float64 values.

A batch whose messages differ in length or in layout (another ``frame_id`` length, big-endian CDR) gives None:
the caller decodes it message by message with rosbags. Tests compare both ways on bags rosbags writes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .byte_fields import Places
from .stamps import stamp_s

#: float64 values after the header: orientation (4), its covariance (9), angular velocity (3), its covariance (9),
#: linear acceleration (3), its covariance (9)
_VALUES = 37
#: where each field starts among the values
ANGULAR_VELOCITY = 13
ANGULAR_VELOCITY_COVARIANCE = 16
LINEAR_ACCELERATION = 25
LINEAR_ACCELERATION_COVARIANCE = 28
#: float64 values after a ``sensor_msgs/Temperature`` header: temperature, variance
_TEMPERATURE_VALUES = 2


@dataclass(frozen=True)
class ImuBatch:
    """IMU messages of one layout as a byte array (n, length) and where their float64 values start [bytes]."""

    data: np.ndarray
    values_at: int

    @property
    def values(self) -> np.ndarray:
        """The 37 float64 values of each message (n, 37), a copy."""
        raw = np.ascontiguousarray(self.data[:, self.values_at : self.values_at + 8 * _VALUES])
        return raw.view("<f8").reshape(-1, _VALUES)

    def stamp_s(self, cdr: bool) -> np.ndarray:
        """The header stamps [s] as :func:`gyrocomp.io.rosbag` computes them (sec + nanosec 1e-9); the stamp
        follows the first four bytes in both layouts (ROS 1's ``seq``, ROS 2's encapsulation header)."""
        sec = np.ascontiguousarray(self.data[:, 4:8]).view("<i4" if cdr else "<u4")[:, 0]
        nsec = np.ascontiguousarray(self.data[:, 8:12]).view("<u4")[:, 0]
        return stamp_s(sec, nsec)

    def with_values(self, start: int, rows: np.ndarray, values: np.ndarray) -> "ImuBatch":
        """A copy whose messages ``rows`` (indices) have their float64 values from index ``start`` (e.g.
        :data:`ANGULAR_VELOCITY`) replaced by the columns of ``values`` (len(rows), m)."""
        data = self.data.copy()
        at = self.values_at + 8 * start
        width = 8 * values.shape[1]
        data[rows, at : at + width] = np.ascontiguousarray(values, dtype="<f8").view(np.uint8).reshape(-1, width)
        return ImuBatch(data, self.values_at)

    def message(self, i: int) -> bytes:
        """Message ``i`` serialized."""
        return self.data[i].tobytes()


def imu_batch(raws: list, cdr: bool) -> ImuBatch | None:
    """The messages ``raws`` (serialized ``sensor_msgs/Imu``, ROS 2 CDR when ``cdr``) as one :class:`ImuBatch`,
    or None when they do not share one layout (see the module)."""
    if not raws:
        return None
    length = len(raws[0])
    if length < 16 + 8 * _VALUES or any(len(r) != length for r in raws):
        return None
    return imu_batch_of(np.frombuffer(b"".join(raws), dtype=np.uint8).reshape(len(raws), length), cdr)


def imu_batch_of(data: np.ndarray, cdr: bool) -> ImuBatch | None:
    """Messages of one length as a byte array (n, length) as one :class:`ImuBatch`, or None when they do not share
    one layout (see the module)."""
    if data.shape[0] == 0 or data.shape[1] < 16:
        return None
    text = np.ascontiguousarray(data[:, 12:16]).view("<u4")[:, 0]
    values_at = _values_at(text, data[:, :2] if cdr else None, data.shape[1])
    return None if values_at is None else ImuBatch(data, values_at)


def _values_at(text: np.ndarray, encapsulation: np.ndarray | None, length: int, values: int = _VALUES) -> int | None:
    """Where the ``values`` float64 values of messages of ``length`` bytes start [bytes], from each one's
    ``frame_id`` length ``text`` and, for CDR, its first two bytes ``encapsulation`` (n, 2) (None: ROS 1); None when
    the messages do not share one layout (see the module)."""
    if length < 16 + 8 * values or text.size == 0 or np.any(text != text[0]):
        return None
    if encapsulation is not None:
        if np.any(encapsulation[:, 0] != 0) or np.any(encapsulation[:, 1] != 1):  # little-endian plain CDR only
            return None
        end = 16 + int(text[0])
        values_at = end + (-(end - 4)) % 8
    else:
        values_at = 16 + int(text[0])
    return values_at if values_at + 8 * values == length else None


def _stamps_s(places: Places, cdr: bool) -> np.ndarray:
    """The header stamps [s] of messages at ``places`` as :func:`gyrocomp.io.rosbag.header_stamp_s` computes them
    (sec + nanosec 1e-9); the stamp follows the first four bytes in both layouts."""
    sec = places.read(4, "<i4" if cdr else "<u4")
    return stamp_s(sec, places.read(8, "<u4"))


def temperature_fields(raws: list, cdr: bool) -> tuple[np.ndarray, np.ndarray] | None:
    """The header stamps [s] and temperatures [degC] of serialized ``sensor_msgs/Temperature`` messages ``raws``
    (a header, then ``temperature`` and ``variance``, float64), read at once; None when they do not share one
    layout (the caller then decodes them one by one)."""
    if not raws or any(len(r) != len(raws[0]) for r in raws):
        return None
    length = len(raws[0])
    if length < 16 + 8 * _TEMPERATURE_VALUES:
        return None
    places = Places(np.frombuffer(b"".join(raws), dtype=np.uint8), length * np.arange(len(raws)))
    encapsulation = places.read(0, np.uint8, 2) if cdr else None
    values_at = _values_at(places.read(12, "<u4"), encapsulation, length, _TEMPERATURE_VALUES)
    if values_at is None:
        return None
    return _stamps_s(places, cdr), places.read(values_at, "<f8")


@dataclass(frozen=True)
class ImuFields:
    """What a reader and a compensator take of IMU messages of one layout lying in a byte array: where their float64
    values start in each [bytes], their header stamps [s], angular velocities [rad/s] (n, 3) and linear
    accelerations [m/s^2] (n, 3)."""

    values_at: int
    stamp_s: np.ndarray
    angular_velocity: np.ndarray
    linear_acceleration: np.ndarray


def imu_fields(data: np.ndarray, at: np.ndarray, length: int, cdr: bool) -> ImuFields | None:
    """The fields of the IMU messages of ``length`` bytes that start at offsets ``at`` of ``data`` (uint8, 1-D),
    read where they lie (only the bytes used are copied, not whole messages); None when they do not share one
    layout (see the module).

    Parameters
    ----------
    data : array of uint8
        Bytes holding the messages (a bag's chunk, say).
    at : array of int
        Where each message starts in ``data`` [bytes].
    length : int
        Their length [bytes].
    cdr : bool
        ROS 2 CDR (else ROS 1 serialization).
    """
    at = np.asarray(at, dtype=np.int64)
    if at.size == 0 or length < 16 + 8 * _VALUES or at.max() + length > data.size or at.min() < 0:
        return None
    places = Places(data, at)
    values_at = _values_at(places.read(12, "<u4"), places.read(0, np.uint8, 2) if cdr else None, length)
    if values_at is None:
        return None
    return ImuFields(
        values_at,
        _stamps_s(places, cdr),
        places.read(values_at + 8 * ANGULAR_VELOCITY, "<f8", 3),
        places.read(values_at + 8 * LINEAR_ACCELERATION, "<f8", 3),
    )


__all__ = [
    "ANGULAR_VELOCITY",
    "ANGULAR_VELOCITY_COVARIANCE",
    "ImuBatch",
    "ImuFields",
    "LINEAR_ACCELERATION",
    "LINEAR_ACCELERATION_COVARIANCE",
    "imu_batch",
    "imu_batch_of",
    "imu_fields",
    "temperature_fields",
]
