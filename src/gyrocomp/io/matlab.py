"""MATLAB MAT-files and NumPy ``.npz`` archives: named arrays, read whole, whose channels are found as in an HDF5
file (:mod:`gyrocomp.io.hdf5`: under gyrocomp's names or common ones such as ``angular_velocity``, or by a mapping;
``NAME[:, k]`` for column k of a two-dimensional array; the layout's ``rate_hz`` where there is no time array;
the layout's units, these formats having no units of their own).

- A MAT-file of versions 4 to 7 is read by ``scipy.io.loadmat``, in a process of its own: scipy's reader is compiled
  code that a damaged file can crash (found by flipping bytes), which must not take the command with it.
- A MAT-file of version 7.3 is an HDF5 file behind a 512-byte header, read by h5py (extra ``[hdf5]``). MATLAB
  stores arrays by columns, so each two-dimensional array is transposed back to MATLAB's rows and columns.
- An ``.npz`` is read by ``numpy.load`` without pickles: an array of Python objects is left out, not run.
- A ``.mat`` that is text (MATLAB's ``save -ascii``: rows of numbers) is a table without a header line; it is refused
  with how to read it so.

Only numeric arrays of one or two dimensions are channels; a vector stored as one row or one column (MATLAB has no
other kind) is one-dimensional. A structure's fields are arrays named by their path, ``imu/gyro`` (a v7.3 file's
groups are named so by HDF5 already).
"""

from __future__ import annotations

import struct
import subprocess
import sys
import tempfile
import tokenize
import zipfile
import zlib
from pathlib import Path

import numpy as np

from ..errors import InputError, printable
from .foreign_libraries import require
from .read_options import ProgressCallback, ReadOptions
from .hdf5 import ArrayStore, StoredArray, named_arrays_recording, opened_hdf5
from .readers import Reader, register_reader
from .serial import looks_headerless

MAT5_MAGIC = b"MATLAB 5.0 MAT-file"
MAT73_MAGIC = b"MATLAB 7.3 MAT-file"
#: what numpy's .npz reading raises on a damaged or cut-short file (a bad zlib stream, a member running past the
#: end, a garbled .npy header, an array's declared size beyond memory, a flag that says the member is encrypted)
_DAMAGED = (
    ValueError,
    TypeError,
    NotImplementedError,
    OSError,
    EOFError,
    IndexError,
    KeyError,
    OverflowError,
    MemoryError,
    RuntimeError,
    UnicodeDecodeError,
    SyntaxError,
    zlib.error,
    struct.error,
    tokenize.TokenError,
    zipfile.BadZipFile,
)
#: MATLAB classes of numbers (a v7.3 file's ``MATLAB_class`` attribute)
_MATLAB_NUMBERS = {"double", "single", "int8", "int16", "int32", "int64", "uint8", "uint16", "uint32", "uint64"}


def _array(name: str, values, source: str) -> StoredArray | None:
    """A numeric array of one or two dimensions as a stored array (a row or column vector one-dimensional); None
    for anything else (text, structures, cells, scalars, objects)."""
    values = np.asarray(values)
    if values.dtype.kind not in "iuf" or values.ndim not in (1, 2) or values.size < 2:
        return None
    if values.ndim == 2 and 1 in values.shape:
        values = values.reshape(-1)
    return StoredArray(name, values, source)


#: the program that reads a MAT-file of versions 4 to 7 in a process of its own: scipy's reader is compiled code that
#: a damaged file can crash (a flipped byte in a matrix's header made it read past its buffer); its numeric arrays,
#: those in structures named by their path (``imu/gyro``, as in a v7.3 file), with lists of names and single numbers
#: (for guessing a layout), are handed back as an .npz, its error as the last line of its stderr
_LOADMAT = """
import sys
import numpy as np
from scipy.io import loadmat
try:
    contents = loadmat(sys.argv[1], simplify_cells=True)
except Exception as exc:
    sys.stderr.write(str(exc).splitlines()[0] if str(exc) else type(exc).__name__)
    sys.exit(3)
arrays = {}
def walk(prefix, value):
    if isinstance(value, dict):
        for key, inner in value.items():
            if not key.startswith("__"):
                walk(prefix + key if not prefix else prefix + "/" + key, inner)
    elif isinstance(value, np.ndarray) and value.dtype.kind in "iufU":
        arrays[prefix] = value
    elif isinstance(value, (int, float)) and not isinstance(value, bool):
        arrays[prefix] = np.asarray(value, dtype=float)
    elif isinstance(value, list) and value and all(isinstance(v, str) for v in value):
        arrays[prefix] = np.array(value, dtype=str)
walk("", contents)
np.savez(sys.argv[2], **arrays)
"""


def _mat5(path: Path) -> ArrayStore:
    """A MAT-file of versions 4 to 7, read by ``scipy.io.loadmat`` in a process of its own (see ``_LOADMAT``)."""
    with tempfile.TemporaryDirectory(prefix="gyrocomp-mat-") as scratch:
        out = Path(scratch) / "arrays.npz"
        done = subprocess.run(
            [sys.executable, "-c", _LOADMAT, str(path), str(out)], capture_output=True, text=True, check=False
        )
        if done.returncode != 0:
            said = done.stderr.strip().splitlines()[-1] if done.stderr.strip() else ""
            why = printable(said)[:200] if done.returncode == 3 and said else "its reader stopped on it"
            raise InputError(f"{path}: not a readable MAT-file ({why}); is it damaged or cut short?")
        return _npz(out, source=str(path))


def _mat73(path: Path) -> ArrayStore:
    h5py = require("h5py", "hdf5", "reading MATLAB v7.3 files")
    store = ArrayStore()

    def visit(name, obj) -> None:
        kind = obj.attrs.get("MATLAB_class") if isinstance(obj, h5py.Dataset) else None
        kind = kind.decode("ascii", "replace") if isinstance(kind, bytes) else kind
        if kind in _MATLAB_NUMBERS:
            values = obj[()]
            array = _array(name, values.T if values.ndim == 2 else values, str(path))
            if array is not None:
                store[name] = array

    with opened_hdf5(h5py, path) as handle:
        handle.visititems(visit)
    return store


def _npz(path: Path, source: str | None = None) -> ArrayStore:
    """The numeric arrays of an .npz (``source``: the file they came from, for the arrays' names in messages)."""
    source = source or str(path)
    store = ArrayStore()
    try:
        with np.load(path, allow_pickle=False) as archive:
            for name in archive.files:
                try:
                    values = archive[name]
                except ValueError as exc:
                    if "allow_pickle" in str(exc):  # an array of Python objects: loading it would unpickle
                        continue
                    raise
                array = _array(name, values, source)
                if array is not None:
                    store[name] = array
                elif values.dtype.kind in "US" and values.ndim == 1:  # names, of a matrix's columns say
                    store.labels[name] = tuple(str(v) for v in values)
                elif values.dtype.kind in "iuf" and values.size == 1:  # a number, a sample rate say
                    store.scalars[name] = float(values.reshape(-1)[0])
    except _DAMAGED as exc:
        raise InputError(f"{path}: not a readable .npz archive ({printable(str(exc))[:200]})") from None
    return store


def read_arrays(path, options: ReadOptions | None = None, progress: ProgressCallback | None = None):
    """Read a MATLAB MAT-file (v4 to v7.3) or a NumPy ``.npz`` into a :class:`~gyrocomp.recording.Recording`
    [s, deg/s, g, degC] (see the module).

    Parameters
    ----------
    path : path
        The ``.mat`` or ``.npz`` file.
    options : ReadOptions, optional
        ``layout.columns`` maps channels to arrays (``time=t,gyro=omega`` or ``gyro_x=imu[:, 1]``); ``layout``'s
        units and ``rate_hz`` (for a file without a time array) apply.
    progress : callable, optional
        Called with the fraction done.
    """
    options = options or ReadOptions()
    store, fmt = load_arrays(path)
    return named_arrays_recording(store, Path(path), options, progress, fmt)


def load_arrays(path) -> tuple[ArrayStore, str]:
    """The numeric arrays of a MAT-file or an ``.npz`` (see the module) and the format's name (``mat`` or ``npz``);
    a file that holds none, or is a text matrix, is refused in one line."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: no such file" if not path.exists() else f"{path}: is a folder, not a file")
    with open(path, "rb") as fh:
        head = fh.read(128)
    if head.startswith(MAT73_MAGIC):
        store, fmt = _mat73(path), "mat"
    elif head.startswith(b"PK\x03\x04"):
        store, fmt = _npz(path), "npz"
    elif head.strip() and looks_headerless(head.split(b"\n", 1)[0].decode("ascii", "replace")):
        raise InputError(
            f"{path}: a text matrix (MATLAB's save -ascii), not a binary MAT-file: read it as a table without a "
            "header line, fmt=csv with the columns' names in order (names=time,gyro_x,gyro_y,gyro_z)"
        )
    else:
        store, fmt = _mat5(path), "mat"
    if not store:
        raise InputError(f"{path}: no numeric array of one or two dimensions in the file")
    return store, fmt


register_reader(
    Reader(
        "mat",
        "MATLAB MAT-file (v7.3 with extra [hdf5]) or NumPy .npz",
        read_arrays,
        suffixes=(".mat", ".npz"),
        magic=(MAT5_MAGIC, MAT73_MAGIC),
        aliases=("matlab", "npz"),
        layout=True,
    )
)

__all__ = ["MAT5_MAGIC", "MAT73_MAGIC", "load_arrays", "read_arrays"]
