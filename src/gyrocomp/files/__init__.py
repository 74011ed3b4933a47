"""Files of any length, read in chunks where they can be: the one place apply, convert, evaluate and the noise
analysis work on files (:mod:`.chunks` says how a file is read, the other modules what is done with it)."""

from .apply import FileResult, apply_file
from .chunks import ChunkSettings, reads_in_chunks
from .convert import ConvertResult, convert_file
from .evaluate import evaluate_file
from .noise import analyse_noise_file

__all__ = ["ChunkSettings", "ConvertResult", "FileResult", "analyse_noise_file", "apply_file", "convert_file",
           "evaluate_file", "reads_in_chunks"]
