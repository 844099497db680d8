"""Otter USV in surge, sway and yaw: the 3-DOF model of Li et al. 2025.

``M nu_dot + C(nu) nu + D nu = tau`` with ``M = diag(m11, m22, m33)``, ``D = diag(d11, d22, d33)``,
``C = [[0, 0, -m22 v], [0, 0, m11 u], [m22 v, -m11 u, 0]]`` and twin thrusters
``tau = (T_L + T_R, 0, (T_L - T_R) B/2)``. The coefficients are the surge, sway and yaw
diagonal entries of the 6-DOF Otter's M and D (uvsym's choice: the paper gives none), B/2 the
propeller offset y_pont. Inputs are the thrusts T_L, T_R in N, saturated at the bollard pull.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from uvsym.models.actuators import saturate
from uvsym.models.model import Model, VehicleEquations, assemble
from uvsym.models.parameters import load_parameters
from uvsym.models.rigid_body import coriolis_from_mass
from uvsym.models.vehicles.otter import PARAMETER_FILES, derive

NAME = "otter3dof"
DESCRIPTION = "Otter USV, 3 DOF (surge, sway, yaw), twin thrusters as force inputs"
SURGE_SWAY_YAW = [0, 1, 5]


def build(**overrides) -> Model:
    """Build the 3-DOF Otter; overrides replace the 6-DOF Otter's parameters it derives from."""
    p = load_parameters(NAME, PARAMETER_FILES, overrides)
    d = derive(p)
    M3 = np.diag(d.M[SURGE_SWAY_YAW, SURGE_SWAY_YAW])
    D3 = np.diag(d.D[SURGE_SWAY_YAW, SURGE_SWAY_YAW])
    half_spacing = p.v("y_pont")
    thrust_max = p.v("k_pos") * d.n_max**2
    thrust_min = -p.v("k_neg") * d.n_min**2

    def applied(u):
        return [saturate(u[i], thrust_min, thrust_max) for i in range(2)]

    def actuation(eta, nu, nu_r, u):
        T_L, T_R = applied(u)
        return ca.vertcat(T_L + T_R, 0, (T_L - T_R) * half_spacing)

    def actuator_rate(u, u_cmd):
        return ca.vertcat(*[(u_cmd[i] - T) / p.v("T_n") for i, T in enumerate(applied(u))])

    equations = VehicleEquations(
        M=M3,
        hull_terms=lambda eta, nu, nu_r: {
            "coriolis": ca.mtimes(coriolis_from_mass(M3, nu_r), nu_r),
            "damping": ca.mtimes(ca.DM(D3), nu_r),
        },
        actuation=actuation, actuator_rate=actuator_rate,
        input_labels=("T_L", "T_R"), input_units=("N", "N"),
        u_min=(thrust_min, thrust_min), u_max=(thrust_max, thrust_max))
    return assemble(NAME, DESCRIPTION, 3, p, equations)
