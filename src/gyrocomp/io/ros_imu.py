"""``sensor_msgs/Imu`` messages decoded and re-encoded a batch at a time, without a ROS installation.

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

#: float64 values after the header: orientation (4), its covariance (9), angular velocity (3), its covariance (9),
#: linear acceleration (3), its covariance (9)
_VALUES = 37
#: where each field starts among the values
ANGULAR_VELOCITY = 13
ANGULAR_VELOCITY_COVARIANCE = 16
LINEAR_ACCELERATION = 25
LINEAR_ACCELERATION_COVARIANCE = 28


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
        return sec.astype(float) + nsec.astype(float) * 1e-9

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
    if data.shape[0] == 0 or data.shape[1] < 16 + 8 * _VALUES:
        return None
    length = data.shape[1]
    text = np.ascontiguousarray(data[:, 12:16]).view("<u4")[:, 0]
    if np.any(text != text[0]):
        return None
    if cdr:
        if np.any(data[:, 0] != 0) or np.any(data[:, 1] != 1):  # little-endian plain CDR only
            return None
        end = 16 + int(text[0])
        values_at = end + (-(end - 4)) % 8
    else:
        values_at = 16 + int(text[0])
    if values_at + 8 * _VALUES != length:
        return None
    return ImuBatch(data, values_at)


__all__ = [
    "ANGULAR_VELOCITY",
    "ANGULAR_VELOCITY_COVARIANCE",
    "ImuBatch",
    "LINEAR_ACCELERATION",
    "LINEAR_ACCELERATION_COVARIANCE",
    "imu_batch",
    "imu_batch_of",
]
