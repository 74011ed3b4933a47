"""Every temperature model there is: importing this module registers each curve and curve family
(:mod:`gyrocomp.curves.protocol`), and its names are the complete registries. A new model is its module plus one
line here."""

from __future__ import annotations

from . import polynomial  # noqa: F401
from . import network  # noqa: F401
from . import lookup  # noqa: F401
from . import hysteresis  # noqa: F401  (memory curves)
from . import turning_table  # noqa: F401
from . import play_bank  # noqa: F401
from .protocol import BASES, CURVES, MEMORY_CURVES, curve_from_dict

__all__ = ["BASES", "CURVES", "MEMORY_CURVES", "curve_from_dict"]
