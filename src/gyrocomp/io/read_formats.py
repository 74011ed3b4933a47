"""Every input format there is: importing this module registers each reader (:mod:`gyrocomp.io.readers`), in
the order of the lines below. A new format is its module plus one line here."""

from __future__ import annotations

from . import table_formats  # noqa: F401  csv, parquet
from . import ulog  # noqa: F401
from . import dataflash  # noqa: F401
from . import rosbag  # noqa: F401
from . import hdf5  # noqa: F401
from . import matlab  # noqa: F401
from .readers import READERS

__all__ = ["READERS"]
