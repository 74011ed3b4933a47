"""CSV and Parquet tables as input formats (``csv``, ``parquet``): read with the table layout's options
(:class:`gyrocomp.io.tables.TableLayout`), keeping the file's own columns for writing results back."""

from __future__ import annotations

from pathlib import Path

from .read_options import ProgressCallback, ReadOptions
from .readers import Reader, register_reader
from .tables import PARQUET_MAGIC, PARQUET_SUFFIXES, TableData, read_table
from .text_format import COMPRESSED_SUFFIXES, TEXT_TABLE_SUFFIXES


def _table_reader(fmt: str):
    def read(path: Path, options: ReadOptions, progress: ProgressCallback | None) -> TableData:
        data = read_table(
            path, options.layout, fmt=fmt, drop_nonfinite=options.drop_nonfinite, channels=options.channels
        )
        if progress:
            progress(1.0)
        return data

    return read


register_reader(
    Reader(
        "csv",
        "a delimited text table, gzip/bz2/xz/zstd compressed too",
        _table_reader("csv"),
        suffixes=TEXT_TABLE_SUFFIXES + tuple(s + c for s in TEXT_TABLE_SUFFIXES for c in COMPRESSED_SUFFIXES),
        aliases=("tsv", "txt"),
        table=True,
    )
)
register_reader(
    Reader(
        "parquet",
        "an Apache Parquet table",
        _table_reader("parquet"),
        suffixes=PARQUET_SUFFIXES,
        magic=(PARQUET_MAGIC,),
        aliases=("pq",),
        table=True,
    )
)

__all__: list[str] = []
