"""Torpedo: REMUS 100 hull with four independent stern fins and a propeller, 6 DOF.

As the Python Vehicle Simulator's torpedo.py. Inputs u = (top rudder, bottom rudder,
starboard stern plane, port stern plane) in rad and propeller speed n in rpm, saturated.
"""

from __future__ import annotations

from pathlib import Path

import casadi as ca

from uvsym.models.actuators import fin_force, propeller_thrust_torque, saturate
from uvsym.models.hydrodynamics import speed
from uvsym.models.model import Model, VehicleEquations, assemble
from uvsym.models.parameters import load_parameters
from uvsym.models.vehicles.cruciform_fins import FINS_FILE, stern_fins
from uvsym.models.vehicles.remus100_hull import HULL_FILE, PROPELLER_FILE, hull, propeller

NAME = "torpedo"
DESCRIPTION = "Torpedo-shaped AUV on the REMUS 100 hull: four independent stern fins, propeller"
PARAMETER_FILES = [HULL_FILE, PROPELLER_FILE, FINS_FILE, Path(__file__).with_name("torpedo.toml")]


def build(**overrides) -> Model:
    """Build the torpedo model; keyword overrides replace parameters."""
    p = load_parameters(NAME, PARAMETER_FILES, overrides)
    body = hull(p)
    prop = propeller(p)
    fins = stern_fins(p)
    rho = p.v("rho")
    u_max = (p.v("deltaMax_fin"),) * 4 + (p.v("nMax"),)

    def applied(u):
        return [saturate(u[i], -u_max[i], u_max[i]) for i in range(5)]

    def actuation(eta, nu, nu_r, u):
        *deltas, n = applied(u)
        X_prop, K_prop = propeller_thrust_torque(n, speed(nu[0], nu[1], nu[2]), rho, prop)
        thrust = ca.vertcat((1 - prop.thrust_deduction) * X_prop, 0, 0, p.v("torque_scale") * K_prop, 0, 0)
        return thrust + sum(fin_force(fin, delta, nu_r, rho) for fin, delta in zip(fins, deltas))

    def actuator_rate(u, u_cmd):
        T = (p.v("T_delta"),) * 4 + (p.v("T_n"),)
        return ca.vertcat(*[(u_cmd[i] - u[i]) / T[i] for i in range(5)])

    equations = VehicleEquations(
        M=body.M,
        hull_terms=lambda eta, nu, nu_r: body.terms(eta, nu_r),
        actuation=actuation,
        actuator_rate=actuator_rate,
        input_labels=("delta_top", "delta_bottom", "delta_starboard", "delta_port", "n"),
        input_units=("rad", "rad", "rad", "rad", "rpm"),
        u_min=tuple(-x for x in u_max),
        u_max=u_max,
    )
    return assemble(NAME, DESCRIPTION, 6, p, equations)
