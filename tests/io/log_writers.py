"""Minimal writers of PX4 ULog and ArduPilot DataFlash files, for reader tests (formats as documented by
PX4, https://docs.px4.io/main/en/dev_log/ulog_file_format.html, and ArduPilot's AP_Logger)."""

from __future__ import annotations

import struct

import numpy as np

_ULOG_TYPES = {"uint64_t": "Q", "uint32_t": "I", "float": "f", "uint8_t": "B", "int32_t": "i"}


def write_ulog(path, topics: dict[tuple[str, int], dict[str, tuple[str, np.ndarray]]],
               parameters: dict[str, int | float] | None = None) -> None:
    """Write a ULog with one data series per ``(topic, multi_id)``: ``{field: (c_type, values)}``, and
    ``parameters`` (an int is written as int32_t, a float as float) in the definitions section.

    Every topic must have a ``timestamp`` field (uint64_t, microseconds) first.
    """
    out = bytearray(b"ULog\x01\x12\x35" + bytes([1]) + struct.pack("<Q", 0))

    def message(kind: bytes, payload: bytes) -> None:
        out.extend(struct.pack("<HB", len(payload), kind[0]) + payload)

    message(b"B", bytes(8) + bytes(8) + bytes(24))  # flag bits: no incompat flags, no appended data
    formats_done = set()
    for (name, _), fields in topics.items():
        if name in formats_done:
            continue
        formats_done.add(name)
        spec = "".join(f"{ctype} {field};" for field, (ctype, _) in fields.items())
        message(b"F", f"{name}:{spec}".encode())
    for name, value in (parameters or {}).items():
        key = f"{'int32_t' if isinstance(value, int) else 'float'} {name}".encode()
        message(b"P", bytes([len(key)]) + key + struct.pack("<i" if isinstance(value, int) else "<f", value))
    for msg_id, ((name, multi_id), fields) in enumerate(topics.items()):
        message(b"A", struct.pack("<BH", multi_id, msg_id) + name.encode())
    rows = []
    for msg_id, ((name, multi_id), fields) in enumerate(topics.items()):
        codes = "<" + "".join(_ULOG_TYPES[ctype] for ctype, _ in fields.values())
        columns = [values for _, values in fields.values()]
        stamps = np.asarray(fields["timestamp"][1])
        for i in range(stamps.size):
            payload = struct.pack("<H", msg_id) + struct.pack(codes, *(c[i].item() for c in columns))
            rows.append((int(stamps[i]), payload))
    for _, payload in sorted(rows, key=lambda r: r[0]):
        message(b"D", payload)
    with open(path, "wb") as fh:
        fh.write(bytes(out))


_DF_TYPES = {"Q": "Q", "f": "f", "B": "B", "I": "I", "H": "H", "N": "16s"}


def write_dataflash(path, messages: dict[str, tuple[int, list[tuple[str, str]], list[tuple]]], cut: int = 0) -> None:
    """Write a DataFlash log: ``{name: (type_id, [(column, df_format_char)], rows)}``, rows in time order
    per type (all types interleaved by their first column, TimeUS). ``cut`` drops bytes from the end."""
    out = bytearray()
    fmt_struct = struct.Struct("<BB4s16s64s")
    structs = {}
    for name, (type_id, columns, _) in messages.items():
        body = struct.Struct("<" + "".join(_DF_TYPES[c] for _, c in columns))
        structs[name] = body
        out += b"\xa3\x95\x80" + fmt_struct.pack(type_id, body.size + 3, name.encode(),
                                                 "".join(c for _, c in columns).encode(),
                                                 ",".join(n for n, _ in columns).encode())
    records = []
    for name, (type_id, _, rows) in messages.items():
        for row in rows:
            records.append((row[0], bytes([0xA3, 0x95, type_id]) + structs[name].pack(*row)))
    for _, record in sorted(records, key=lambda r: r[0]):
        out += record
    with open(path, "wb") as fh:
        fh.write(bytes(out[: len(out) - cut]))
