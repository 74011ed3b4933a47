"""Benchmark: ``gyrocomp allan``, ``apply`` (a bag into a bag) and ``fit`` on a long ROS bag, time and peak memory,
against the same commands on a Parquet table of the same samples (issue #48).

The bag: ``--hours`` (10) at ``--rate-hz`` (1000) of a simulated consumer part's hour in the chamber, repeated with
the time running on (three axes on ``/imu/data``, ``sensor_msgs/Imu``, and its temperature at 1 Hz on
``/imu/temperature``), in ROS 1 (``.bag``), ROS 2 sqlite3 or MCAP storage (``--kind``). Its IMU messages are
serialized from one template message whose stamp and values are written in place (:mod:`gyrocomp.io.ros_imu`,
whose tests check that against rosbags' serializer), so that writing 3.6e7 messages takes minutes, not hours. The
Parquet table holds the samples reading the bag gives (:class:`gyrocomp.io.rosbag.BagStream`'s chunks: the header
stamps, the temperature interpolated from the 1 Hz topic), so that each command reads the same recording from both.

Each command runs in a fresh process (the wrapper of ``bench_apply_stream.py``): wall time, peak resident memory
(``ru_maxrss``, which counts the pages of memory-mapped temporary files too) and peak anonymous memory (sampled
every 20 ms: the working memory); then each bag command's ratio to the same command on the table. The files are
written by a process of their own, so that the commands' processes start from a small one.

Usage: python benchmarks/bench_bag.py [--hours 10] [--rate-hz 1000] [--kind ros1|ros2|mcap]
       [--commands allan,apply,fit] [--scratch DIR]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq

from bench_apply_stream import PROGRAMS, measure
from gyrocomp.io.ros_imu import ANGULAR_VELOCITY, LINEAR_ACCELERATION, ImuBatch, imu_batch
from gyrocomp.io.rosbag import BagStream
from gyrocomp.models.fit import fit_channels
from gyrocomp.simulation import simulate

BLOCK_S = 3600.0
G = 9.80665

PROGRAMS.update(
    {
        "gyrocomp apply bag": (
            "import sys\nfrom gyrocomp.cli import main\n"
            "sys.exit(main(['--quiet', 'apply', sys.argv[3], sys.argv[1], '-o', sys.argv[2]]))\n"
        ),
        "gyrocomp fit": (
            "import sys\nfrom gyrocomp.cli import main\n"
            "sys.exit(main(['--quiet', 'fit', sys.argv[1], '-o', sys.argv[2] + '.json']))\n"
        ),
    }
)
#: each command's program, on the bag and on the table
COMMANDS = {"allan": "gyrocomp allan", "apply": "gyrocomp apply bag", "fit": "gyrocomp fit"}


def _stamped(batch, time_s: np.ndarray, cdr: bool) -> None:
    """Header stamps ``time_s`` [s] written into the messages of ``batch`` (sec, nanosec after the first 4 bytes)."""
    sec = np.floor(time_s)
    nsec = np.round((time_s - sec) * 1e9)
    carry = nsec >= 1e9
    sec, nsec = sec + carry, np.where(carry, 0, nsec)
    batch.data[:, 4:8] = sec.astype("<i4" if cdr else "<u4").view(np.uint8).reshape(-1, 4)
    batch.data[:, 8:12] = nsec.astype("<u4").view(np.uint8).reshape(-1, 4)


def make_files(bag, table, hours: float, rate_hz: float, kind: str) -> int:
    """The bag and the table of the same samples; returns the samples."""
    bag, table = Path(bag), Path(table)
    from rosbags.typesys import Stores, get_typestore

    ros2 = kind != "ros1"
    store = get_typestore(Stores.ROS2_HUMBLE if ros2 else Stores.ROS1_NOETIC)
    types = store.types
    imu_type, temperature_type = "sensor_msgs/msg/Imu", "sensor_msgs/msg/Temperature"
    stamp0 = types["builtin_interfaces/msg/Time"](sec=0, nanosec=0)
    header = (
        types["std_msgs/msg/Header"](stamp=stamp0, frame_id="imu_link")
        if ros2
        else types["std_msgs/msg/Header"](seq=0, stamp=stamp0, frame_id="imu_link")
    )
    zero, vector = np.zeros(9), types["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0)
    template = types[imu_type](
        header=header,
        orientation=types["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
        orientation_covariance=zero,
        angular_velocity=vector,
        angular_velocity_covariance=zero,
        linear_acceleration=vector,
        linear_acceleration_covariance=zero,
    )
    serialize = store.serialize_cdr if ros2 else store.serialize_ros1
    raw = bytes(serialize(template, imu_type))
    block = simulate(
        "consumer", profile="chamber", rate_hz=rate_hz, duration_s=BLOCK_S - 1 / rate_hz, seed=1, unit=3
    ).recording
    if ros2:
        from rosbags.rosbag2 import StoragePlugin, Writer

        writer = Writer(bag, version=9, storage_plugin=StoragePlugin.MCAP if kind == "mcap" else StoragePlugin.SQLITE3)
    else:
        from rosbags.rosbag1 import Writer

        writer = Writer(bag)
    blocks = int(np.ceil(hours * 3600.0 / BLOCK_S))
    samples = 0
    with writer:
        imu = writer.add_connection("/imu/data", imu_type, typestore=store)
        thermo = writer.add_connection("/imu/temperature", temperature_type, typestore=store)
        for k in range(blocks):
            n = min(block.n_samples, int(round(hours * 3600.0 * rate_hz)) - samples)
            time_s = 1000.0 + k * BLOCK_S + block.time_s[:n] - block.time_s[0]
            batch = imu_batch([raw] * n, cdr=ros2)
            batch = ImuBatch(batch.data.copy(), batch.values_at)  # writable
            _stamped(batch, time_s, ros2)
            rows = np.arange(n)
            batch = batch.with_values(ANGULAR_VELOCITY, rows, np.radians(block.gyro_dps[:n]))
            batch = batch.with_values(LINEAR_ACCELERATION, rows, block.accel_g[:n] * G)
            stamps = (time_s * 1e9).round().astype(np.int64)
            each = int(round(rate_hz))  # a temperature message every second
            for i in range(n):
                writer.write(imu, int(stamps[i]), batch.data[i].tobytes())
                if i % each == 0:
                    sec = int(time_s[i])
                    stamp = types["builtin_interfaces/msg/Time"](sec=sec, nanosec=int(round((time_s[i] - sec) * 1e9)))
                    head = (
                        types["std_msgs/msg/Header"](stamp=stamp, frame_id="imu_link")
                        if ros2
                        else types["std_msgs/msg/Header"](seq=0, stamp=stamp, frame_id="imu_link")
                    )
                    message = types[temperature_type](
                        header=head, temperature=float(block.temperature_degc[i]), variance=0.0
                    )
                    writer.write(thermo, int(stamps[i]), bytes(serialize(message, temperature_type)))
            samples += n
    # the table: the samples reading the bag gives (its stamps, the temperature interpolated from the 1 Hz topic), a
    # chunk at a time, so that every command reads the same recording from both
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        chunks = BagStream(bag).chunks()
        first = next(chunks)
        with pq.ParquetWriter(table, first.table.schema) as parquet:
            parquet.write_table(first.table)
            for chunk in chunks:
                parquet.write_table(chunk.table)
    return samples


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--hours", type=float, default=10.0)
    parser.add_argument("--rate-hz", type=float, default=1000.0)
    parser.add_argument("--kind", choices=("ros1", "ros2", "mcap"), default="ros1")
    parser.add_argument("--commands", default="allan,apply,fit", help="comma-separated: allan, apply, fit")
    parser.add_argument("--scratch", default=None, help="where the files go (default: the system's temporary folder)")
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    with tempfile.TemporaryDirectory(dir=args.scratch) as tmp:
        tmp = Path(tmp)
        bag, table = tmp / ("in.bag" if args.kind == "ros1" else "in"), tmp / "in.parquet"
        # written by a process of its own: rosbags' writer holds an index entry of every message until it closes
        # the bag, and a child process started from a large one reports that one's peak as its own ru_maxrss
        made = subprocess.run(
            [
                sys.executable,
                "-c",
                "import sys; from bench_bag import make_files; "
                "print(make_files(*sys.argv[1:3], float(sys.argv[3]), float(sys.argv[4]), sys.argv[5]))",
                str(bag),
                str(table),
                str(args.hours),
                str(args.rate_hz),
                args.kind,
            ],
            capture_output=True,
            text=True,
            check=True,
            cwd=Path(__file__).parent,
        )
        samples = int(made.stdout.split()[-1])
        model = tmp / "model.json"
        fit_channels(
            [
                simulate("consumer", profile="chamber", rate_hz=5, duration_s=3600, seed=s, unit=3).recording
                for s in (2, 3)
            ]
        ).save(model)
        size = sum(f.stat().st_size for f in ([bag] if bag.is_file() else bag.iterdir())) / 2**20
        print(
            f"{samples:,} samples ({args.hours:g} h at {args.rate_hz:g} Hz): {args.kind} bag {size:,.0f} MB, "
            f"Parquet {table.stat().st_size / 2**20:,.0f} MB"
        )
        for command in (c.strip() for c in args.commands.split(",")):
            program = COMMANDS[command]
            results = {}
            for name, source in (("bag", bag), ("table", table)):
                out = tmp / ("out.bag" if args.kind == "ros1" else "out") if name == "bag" else tmp / "out.parquet"
                results[name] = measure(
                    program if name == "bag" or command != "apply" else "gyrocomp apply", source, out, model
                )
                print(
                    f"  {command:6s} {name:6s} {results[name][0]:8.1f} s  {results[name][1]:8.0f} MB peak RSS  "
                    f"{results[name][2]:8.0f} MB peak anonymous",
                    flush=True,
                )
                for leftover in tmp.glob("out*"):
                    if leftover.is_dir():
                        for f in leftover.iterdir():
                            f.unlink()
                        leftover.rmdir()
                    else:
                        leftover.unlink()
            bag_result, table_result = results["bag"], results["table"]
            print(
                f"  {command}: the bag {bag_result[0] / table_result[0]:.2f}x the table's time, peak anonymous "
                f"{bag_result[2]:.0f} MB (the table's {table_result[2]:.0f} MB)",
                flush=True,
            )


if __name__ == "__main__":
    main()
