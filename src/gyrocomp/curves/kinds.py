"""Every temperature model there is: importing this module registers each curve and curve family
(:mod:`gyrocomp.curves.protocol`), and its names are the complete registries. A new model's module is named
here, once."""

from __future__ import annotations

from . import lookup, network, polynomial
from .protocol import BASES, CURVES, curve_from_dict

#: the modules that register a curve (and a basis, when the curve is linear in its parameters)
CURVE_MODULES = (polynomial, network, lookup)

__all__ = ["BASES", "CURVES", "CURVE_MODULES", "curve_from_dict"]
