"""Every input format there is: importing this module registers each reader (:mod:`gyrocomp.io.readers`), in
this order. A new format's module is named here, once."""

from __future__ import annotations

from . import table_formats, ulog, dataflash, rosbag, hdf5
from .readers import READERS

#: the modules that register a reader
READER_MODULES = (table_formats, ulog, dataflash, rosbag, hdf5)

__all__ = ["READERS", "READER_MODULES"]
