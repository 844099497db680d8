"""Four stern fins in a cruciform arrangement on the REMUS 100 hull (torpedo, docking_auv)."""

from __future__ import annotations

from pathlib import Path

from uvsym.models.actuators import Fin
from uvsym.models.parameters import ParameterSet

__all__ = ["FINS_FILE", "stern_fins"]

FINS_FILE = Path(__file__).with_name("cruciform_fins.toml")


def stern_fins(p: ParameterSet) -> tuple[Fin, Fin, Fin, Fin]:
    """(top rudder, bottom rudder, starboard stern plane, port stern plane) at x = -L/2."""
    x = -p.v("L") / 2.0
    area, radius = p.v("S_fin"), p.v("fin_radius")
    rudder, plane = p.v("CL_delta_r"), p.v("CL_delta_s")
    return (Fin(area, rudder, x, radius, 270.0), Fin(area, rudder, x, radius, 90.0),
            Fin(area, plane, x, radius, 180.0), Fin(area, plane, x, radius, 0.0))
