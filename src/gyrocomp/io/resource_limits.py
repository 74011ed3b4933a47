"""The memory this process may use, checked before a file is read whole: under an address-space limit
(``ulimit -v``, a container's or a batch system's), pyarrow and OpenBLAS may abort the process or fail to load
rather than raise, so a reading that cannot fit is refused in one line first, naming the file, what it needs and
what is allowed.

The need is estimated from the file's size: a text table read whole takes about :data:`CSV_MEMORY_FACTOR` times
its bytes at its peak (the text, the parsed columns, the float64 channels and the model's design matrices), a
compressed one :data:`COMPRESSED_EXPANSION` times more; a Parquet file its uncompressed size times
:data:`PARQUET_MEMORY_FACTOR`. The estimate errs high: a reading it lets through may still fail, then in the
command line's one line for memory.
"""

from __future__ import annotations

import os
import resource
from pathlib import Path

from ..errors import InputError

#: peak memory of reading a text table whole and fitting it, per byte of the file (measured: a 210 MB CSV of 2e6
#: rows, 1.1 GB resident at its peak, 5.2 bytes a byte, and about 1.8 GB of address space beyond the start)
CSV_MEMORY_FACTOR = 6.0
#: a compressed text table's expansion assumed (sensor CSVs compress 3..5 times)
COMPRESSED_EXPANSION = 5.0
#: peak memory per byte of a Parquet file's uncompressed columns
PARQUET_MEMORY_FACTOR = 4.0


def address_space_left() -> int | None:
    """Bytes of address space this process may still map under its limit (RLIMIT_AS), or None when unlimited."""
    soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    if soft == resource.RLIM_INFINITY:
        return None
    try:
        with open("/proc/self/statm") as fh:
            used = int(fh.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        used = 0
    return max(soft - used, 0)


def require_memory(path: str | os.PathLike, needed_bytes: float, what: str = "reading it whole") -> None:
    """Refuse (one line naming ``path``) when ``needed_bytes`` [bytes] exceed the address space left."""
    left = address_space_left()
    if left is not None and needed_bytes > left:
        raise InputError(
            f"{Path(path)}: {what} takes about {needed_bytes / 1e9:.2g} GB of memory, and this process "
            f"may map {left / 1e9:.2g} GB more under its limit (ulimit -v); read less at once (the "
            "channels needed, a stretch of time; apply streams tables) or raise the limit"
        )


def estimated_table_bytes(path: str | os.PathLike, compressed: bool) -> float:
    """The memory [bytes] reading a text table whole takes at its peak (see the module)."""
    size = Path(path).stat().st_size
    return size * CSV_MEMORY_FACTOR * (COMPRESSED_EXPANSION if compressed else 1.0)


__all__ = ["address_space_left", "estimated_table_bytes", "require_memory"]
