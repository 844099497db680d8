"""REMUS 100 AUV, 6 DOF: tail rudder, stern planes and propeller (Fossen's Python Vehicle Simulator).

Inputs u = (delta_r rad, delta_s rad, n rpm), saturated at the deflection and speed limits.
Forces: propeller thrust and torque (Allen et al. 2000), rudder and stern-plane lift and
induced drag at the stern (x = -L/2), hull lift/drag, cross-flow drag, linear damping that
fades with speed in surge and sway, restoring forces, Coriolis from M_RB and M_A with the
Munk moments in pitch and yaw removed (in pairs, so C stays skew-symmetric).
"""

from __future__ import annotations

from pathlib import Path

import casadi as ca

from uvsym.kinematics import Smtrx
from uvsym.models.actuators import control_surface_lift, propeller_thrust_torque, saturate
from uvsym.models.hydrodynamics import speed
from uvsym.models.model import Model, VehicleEquations, assemble
from uvsym.models.parameters import load_parameters
from uvsym.models.vehicles.remus100_hull import HULL_FILE, PROPELLER_FILE, hull, propeller

NAME = "remus100"
DESCRIPTION = "REMUS 100 AUV (L = 1.6 m): tail rudder, stern planes, propeller"
PARAMETER_FILES = [HULL_FILE, PROPELLER_FILE, Path(__file__).with_name("remus100.toml")]



def build(**overrides) -> Model:
    """Build the REMUS 100 model; keyword overrides replace parameters (see remus100*.toml)."""
    p = load_parameters(NAME, PARAMETER_FILES, overrides)
    body = hull(p)
    prop = propeller(p)
    rho, x_stern = p.v("rho"), -p.v("L") / 2.0
    u_max = (p.v("deltaMax_r"), p.v("deltaMax_s"), p.v("nMax"))

    def applied(u):
        return [saturate(u[i], -u_max[i], u_max[i]) for i in range(3)]

    def actuation(eta, nu, nu_r, u):
        delta_r, delta_s, n = applied(u)
        U = speed(nu[0], nu[1], nu[2])
        U_rh2 = nu_r[0] ** 2 + nu_r[1] ** 2
        U_rv2 = nu_r[0] ** 2 + nu_r[2] ** 2
        Y_r = control_surface_lift(rho, p.v("A_r"), p.v("CL_delta_r"), delta_r, U_rh2)
        Z_s = control_surface_lift(rho, p.v("A_s"), p.v("CL_delta_s"), delta_s, U_rv2)
        X_prop, K_prop = propeller_thrust_torque(n, U, rho, prop)
        X = (1 - prop.thrust_deduction) * X_prop + Y_r * delta_r + Z_s * delta_s
        F_surfaces = ca.vertcat(0.0, Y_r, Z_s)
        moment = ca.mtimes(Smtrx([x_stern, 0.0, 0.0]), F_surfaces) + ca.vertcat(p.v("torque_scale") * K_prop, 0, 0)
        return ca.vertcat(X, Y_r, Z_s, moment)

    def actuator_rate(u, u_cmd):
        T = (p.v("T_delta"), p.v("T_delta"), p.v("T_n"))
        return ca.vertcat(*[(u_cmd[i] - a) / T[i] for i, a in enumerate(applied(u))])

    equations = VehicleEquations(
        M=body.M,
        hull_terms=lambda eta, nu, nu_r: body.terms(eta, nu_r),
        actuation=actuation,
        actuator_rate=actuator_rate,
        input_labels=("delta_r", "delta_s", "n"),
        input_units=("rad", "rad", "rpm"),
        u_min=tuple(-x for x in u_max),
        u_max=u_max,
    )
    return assemble(NAME, DESCRIPTION, 6, p, equations)
