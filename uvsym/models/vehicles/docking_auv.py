"""Docking AUV of Liu et al. 2014 (type 1): thrust X, elevator, split rudders, 6 DOF.

The REMUS 100 hull with the cruciform stern fins of the torpedo. Inputs
u = (X thrust N, delta_e elevator rad, delta_ru upper rudder rad, delta_rd lower rudder rad):
the elevator drives both stern planes together (starboard -delta_e, port +delta_e, so its
force is that of the REMUS stern plane), the lower rudder is mounted mirrored (fin deflection
-delta_rd) so that equal delta_ru and delta_rd turn the vehicle alike. Its input matrix
``B = d tau / d u`` has the structure of the paper's eq. 27.
"""

from __future__ import annotations

from pathlib import Path

import casadi as ca

from uvsym.models.actuators import fin_force, saturate
from uvsym.models.model import Model, VehicleEquations, assemble
from uvsym.models.parameters import load_parameters
from uvsym.models.vehicles.cruciform_fins import FINS_FILE, stern_fins
from uvsym.models.vehicles.remus100_hull import HULL_FILE, hull

NAME = "docking_auv"
DESCRIPTION = "Docking AUV of Liu et al. 2014: REMUS 100 hull, thrust X, elevator, upper and lower rudders"
PARAMETER_FILES = [HULL_FILE, FINS_FILE, Path(__file__).with_name("docking_auv.toml")]


def build(**overrides) -> Model:
    """Build the docking AUV model; keyword overrides replace parameters."""
    p = load_parameters(NAME, PARAMETER_FILES, overrides)
    body = hull(p)
    top, bottom, starboard, port = stern_fins(p)
    rho, delta_max = p.v("rho"), p.v("deltaMax_fin")
    u_min = (p.v("X_min"), -delta_max, -delta_max, -delta_max)
    u_max = (p.v("X_max"), delta_max, delta_max, delta_max)

    def applied(u):
        return [saturate(u[i], u_min[i], u_max[i]) for i in range(4)]

    def actuation(eta, nu, nu_r, u):
        X, delta_e, delta_ru, delta_rd = applied(u)
        return (ca.vertcat(X, 0, 0, 0, 0, 0)
                + fin_force(starboard, -delta_e, nu_r, rho) + fin_force(port, delta_e, nu_r, rho)
                + fin_force(top, delta_ru, nu_r, rho) + fin_force(bottom, -delta_rd, nu_r, rho))

    def actuator_rate(u, u_cmd):
        T = (p.v("T_thrust"),) + (p.v("T_delta"),) * 3
        return ca.vertcat(*[(u_cmd[i] - a) / T[i] for i, a in enumerate(applied(u))])

    equations = VehicleEquations(
        M=body.M,
        hull_terms=lambda eta, nu, nu_r: body.terms(eta, nu_r),
        actuation=actuation, actuator_rate=actuator_rate,
        input_labels=("X", "delta_e", "delta_ru", "delta_rd"), input_units=("N", "rad", "rad", "rad"),
        u_min=u_min, u_max=u_max)
    return assemble(NAME, DESCRIPTION, 6, p, equations)
