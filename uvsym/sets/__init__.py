"""Sets for set-valued thresholds: zonotopes, their order reduction and step-by-step propagation."""

from uvsym.sets.propagation import Propagation, carry_coefficients, propagate
from uvsym.sets.reduction import METHODS, Reduction, reduce
from uvsym.sets.zonotope import Zonotope, box

__all__ = ["METHODS", "Propagation", "Reduction", "Zonotope", "box", "carry_coefficients", "propagate", "reduce"]
