"""Readers and writers: every reader returns a recording in internal units (:mod:`.reading`); the readers' registry
(:mod:`.readers`, :mod:`.read_formats`)."""

from __future__ import annotations

from .reading import (
    atomic_path, detect_format, detect_table_format, file_sha256, format_help, format_names, format_spelling,
    instances, output_format, parse_column_mapping, read, read_input, read_table, Reader, reader_named, READERS,
    ReadOptions, recording_table, refuse_to_overwrite_inputs, register_reader, sniff_format, table_formats,
    TableData, TableLayout, write_gyro_back, write_recording, write_rows, write_text_atomic
)

__all__ = [
    "READERS", "ReadOptions", "Reader", "TableData", "TableLayout", "atomic_path", "detect_format",
    "detect_table_format", "file_sha256", "format_help", "format_names", "format_spelling", "instances",
    "output_format", "parse_column_mapping", "read", "read_input", "read_table", "reader_named",
    "recording_table", "refuse_to_overwrite_inputs", "register_reader", "sniff_format", "table_formats",
    "write_gyro_back", "write_recording", "write_rows", "write_text_atomic"
]
