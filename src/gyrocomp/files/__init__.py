"""Files of any length, read in chunks where they can be: the one place apply, convert, evaluate and the noise
analysis work on files (:mod:`.chunks` says how a file is read, the other modules what is done with it).

The names below are imported from their modules when first used (PEP 562), so a command that applies a model
does not load what evaluating or the noise analysis needs.
"""

from __future__ import annotations

from ..lazy import lazy_exports

#: public name -> (its module in this package, its name there)
_EXPORTS = {
    name: (module, name)
    for module, names in (
        ("apply", ("FileResult", "apply_file")),
        ("chunks", ("ChunkSettings", "reads_in_chunks")),
        ("convert", ("ConvertResult", "convert_file")),
        ("evaluate", ("evaluate_file",)),
        ("noise_file", ("analyse_noise_file",)),
    )
    for name in names
}

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)

__all__ = sorted(_EXPORTS)
