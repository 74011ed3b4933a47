"""A ROS bag rewritten as another kind of bag (``gyrocomp convert in.bag out.mcap``; extra ``[ros]``): ROS 1
``.bag``, ROS 2 folder (sqlite3), or a bare ``.mcap`` file, every message kept, through rosbags' own converter
(``rosbags.convert``: ROS 1 and ROS 2 serializations and message definitions translated, a ROS 1 header's ``seq``
dropped as ROS 2 has none). Written beside the output and moved there when complete; the input never touched."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError, printable
from ..io.foreign_libraries import require
from ..io.rosbag import KIND_WORDS, bag_kind, bag_path
from .apply_bag import refuse_output, staged_bag


@dataclass(frozen=True)
class ConvertedBag:
    """What :func:`convert_bag` wrote: the output and its kind (``ros1``, ``ros2``, ``mcap``) and the input's."""

    path: Path
    kind: str
    from_kind: str


def convert_bag(path, output) -> ConvertedBag:
    """Rewrite the bag at ``path`` as the kind of bag ``output`` names (see the module).

    Parameters
    ----------
    path : path
        A ROS 1 ``.bag``, a ROS 2 bag folder (or a file in it), or a bare ``.mcap`` file.
    output : path
        ``*.bag`` (ROS 1), ``*.mcap`` (a bare MCAP file) or a name without suffix (a ROS 2 folder, sqlite3).

    Returns
    -------
    ConvertedBag
    """
    converter = require("rosbags.convert", "ros", "converting ROS bags")
    path, output = Path(path), Path(output)
    bag = bag_path(path)
    source, target = bag_kind(bag), bag_kind(output)
    if source == target:
        others = " or ".join(words for kind, words in KIND_WORDS.items() if kind != source)
        raise InputError(f"output: {output}: the input is already {KIND_WORDS[source]}; name {others}")
    refuse_output(output)
    with staged_bag(output, target) as written:
        try:
            converter.convert(
                [bag],
                written,
                dst_storage="mcap" if target == "mcap" else "sqlite3",
                dst_version=None if target == "ros1" else 9,
                compress=None,
                compress_mode="file",
                default_typestore=None,
                typestore=None,
                exclude_topics=[],
                include_topics=[],
                exclude_msgtypes=[],
                include_msgtypes=[],
            )
        except converter.ConverterError as exc:
            raise InputError(
                f"{path}: cannot be converted to {KIND_WORDS[target]}: {printable(str(exc))[:200]}"
            ) from None
    return ConvertedBag(output, target, source)


__all__ = ["ConvertedBag", "convert_bag"]
