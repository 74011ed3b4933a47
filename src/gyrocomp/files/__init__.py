"""Files of any length, read in chunks where they can be: the one place apply, convert, evaluate and the noise
analysis work on files (:mod:`.chunks` says how a file is read, the other modules what is done with it).

The names below are imported from their modules when first used (PEP 562), so a command that applies a model
does not load what evaluating or the noise analysis needs.
"""

from __future__ import annotations

import importlib

#: public name -> its module in this package
_EXPORTS = {"FileResult": "apply", "apply_file": "apply", "ChunkSettings": "chunks", "reads_in_chunks": "chunks",
            "ConvertResult": "convert", "convert_file": "convert", "evaluate_file": "evaluate",
            "analyse_noise_file": "noise"}


def __getattr__(name: str):
    if name not in _EXPORTS:
        raise AttributeError(f"module 'gyrocomp.files' has no attribute {name!r}")
    return getattr(importlib.import_module(f"{__name__}.{_EXPORTS[name]}"), name)


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_EXPORTS))


__all__ = sorted(_EXPORTS)
