"""A file's digest (SHA-256), light to import: model files record their inputs' (provenance), and a model is asked
whether it was fitted on a file (:meth:`gyrocomp.calibration.Calibration.fitted_on`)."""

from __future__ import annotations

import hashlib
import os


def file_sha256(path: str | os.PathLike) -> str:
    """SHA-256 of a file's bytes, hex."""
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


__all__ = ["file_sha256"]
