"""Otter USV, 6 DOF: two pontoons, two fixed propellers and a payload (Fossen 2021, sec. 6.x).

As the Python Vehicle Simulator's otter.py. Inputs u = (n1 left, n2 right) propeller shaft
speeds in rad/s, saturated at the bollard-pull limits. Rigid-body Coriolis uses the absolute
velocity nu, added-mass Coriolis the relative velocity nu_r; linear damping plus quadratic yaw
damping, cross-flow drag, linear hydrostatics G eta about the CF, and the payload weight as an
external force g_0 (so the hull settles a little deeper with payload).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import casadi as ca
import numpy as np

from uvsym.kinematics import Hmtrx, Rzyx, Smtrx
from uvsym.models.actuators import bollard_thrust, saturate
from uvsym.models.hydrodynamics import crossflow_drag
from uvsym.models.model import Model, VehicleEquations, assemble
from uvsym.models.parameters import ParameterSet, load_parameters
from uvsym.models.rigid_body import coriolis_from_mass, coriolis_rigid_body_cg, rigid_body_mass

NAME = "otter"
DESCRIPTION = "Otter USV (L = 2.0 m): two pontoons, two propellers, payload"
PARAMETER_FILES = [Path(__file__).with_name("otter.toml")]


@dataclass(frozen=True)
class OtterData:
    """Derived data: total mass (kg), CG (m), I_g (kg m^2), M_RB, M_A, G, D (6x6), draft T (m),
    propeller speed limits (rad/s)."""

    m_total: float
    r_g: np.ndarray
    I_g: np.ndarray
    M_RB: np.ndarray
    M_A: np.ndarray
    G: np.ndarray
    D: np.ndarray
    T: float
    n_max: float
    n_min: float

    @property
    def M(self) -> np.ndarray:
        """M = M_RB + M_A, 6x6."""
        return self.M_RB + self.M_A


def derive(p: ParameterSet) -> OtterData:
    """Mass, hydrostatics and damping of the Otter from its parameters (Fossen 2021, ch. 3-4, 6)."""
    m, mp, g, rho = p.v("m"), p.v("mp"), p.v("g"), p.v("rho")
    L, B = p.v("L"), p.v("B")
    rp = p.v("rp")
    m_total = m + mp
    r_g = (m * p.v("rg_hull") + mp * rp) / m_total
    nabla = m_total / rho
    B_pont, y_pont, Cw, Cb = p.v("B_pont"), p.v("y_pont"), p.v("Cw_pont"), p.v("Cb_pont")
    T = nabla / (2 * Cb * B_pont * L)
    radii = np.array([p.v("R44_ratio") * B, p.v("R55_ratio") * L, p.v("R66_ratio") * L])
    S_rg, S_rp = Smtrx(r_g), Smtrx(rp)
    I_g = m * np.diag(radii**2) - m * S_rg @ S_rg - mp * S_rp @ S_rp
    M_RB = rigid_body_mass(m_total, I_g, r_g)
    ratios = p.v("added_mass_ratios")
    M_A = np.diag(np.r_[ratios[:3] * m, ratios[3:] * np.diag(I_g)])
    M = M_RB + M_A

    Aw_pont = Cw * L * B_pont
    I_T = 2 * (1 / 12) * L * B_pont**3 * (6 * Cw**3 / ((1 + Cw) * (1 + 2 * Cw))) + 2 * Aw_pont * y_pont**2
    I_L = 0.8 * 2 * (1 / 12) * B_pont * L**3
    KB = (1 / 3) * (5 * T / 2 - 0.5 * nabla / (L * B_pont))
    KG = T - r_g[2]
    GM_T, GM_L = KB + I_T / nabla - KG, KB + I_L / nabla - KG
    G33, G44, G55 = rho * g * 2 * Aw_pont, rho * g * nabla * GM_T, rho * g * nabla * GM_L
    H = Hmtrx([p.v("LCF"), 0.0, 0.0])
    G = H.T @ np.diag([0, 0, G33, G44, G55, 0]) @ H

    w3, w4, w5 = math.sqrt(G33 / M[2, 2]), math.sqrt(G44 / M[3, 3]), math.sqrt(G55 / M[4, 4])
    D = np.diag([
        p.v("bollard_forward") * g / p.v("U_max"),
        M[1, 1] / p.v("T_sway"),
        2 * p.v("zeta_heave") * w3 * M[2, 2],
        2 * p.v("zeta_roll") * w4 * M[3, 3],
        2 * p.v("zeta_pitch") * w5 * M[4, 4],
        M[5, 5] / p.v("T_yaw"),
    ])
    n_max = math.sqrt(0.5 * p.v("bollard_forward") * g / p.v("k_pos"))
    n_min = -math.sqrt(0.5 * p.v("bollard_reverse") * g / p.v("k_neg"))
    return OtterData(m_total, r_g, I_g, M_RB, M_A, G, D, T, n_max, n_min)


def build(**overrides) -> Model:
    """Build the 6-DOF Otter model; keyword overrides replace parameters (see otter.toml)."""
    p = load_parameters(NAME, PARAMETER_FILES, overrides)
    d = derive(p)
    y = p.v("y_pont")
    u_min, u_max = (d.n_min, d.n_min), (d.n_max, d.n_max)

    def hull_terms(eta, nu, nu_r):
        C = coriolis_rigid_body_cg(d.m_total, d.I_g, d.r_g, nu) + coriolis_from_mass(d.M_A, nu_r)
        yaw_quadratic = p.v("yaw_quadratic_damping") * d.D[5, 5] * ca.fabs(nu_r[5]) * nu_r[5]
        f_payload = ca.mtimes(Rzyx(eta[3], eta[4], eta[5]).T, ca.DM([0.0, 0.0, p.v("mp") * p.v("g")]))
        return {
            "coriolis": ca.mtimes(C, nu_r),
            "damping": ca.mtimes(ca.DM(d.D), nu_r) + ca.vertcat(0, 0, 0, 0, 0, yaw_quadratic),
            "crossflow": -crossflow_drag(p.v("L"), p.v("B_pont"), d.T, nu_r, p.v("rho_crossflow")),
            "restoring": ca.mtimes(ca.DM(d.G), eta),
            "payload": -ca.vertcat(f_payload, ca.mtimes(ca.DM(Smtrx(p.v("rp"))), f_payload)),
        }

    def applied(u):
        return [saturate(u[i], u_min[i], u_max[i]) for i in range(2)]

    def actuation(eta, nu, nu_r, u):
        t1, t2 = (bollard_thrust(n, p.v("k_pos"), p.v("k_neg")) for n in applied(u))
        return ca.vertcat(t1 + t2, 0, 0, 0, 0, y * t1 - y * t2)

    def actuator_rate(u, u_cmd):
        return ca.vertcat(*[(u_cmd[i] - n) / p.v("T_n") for i, n in enumerate(applied(u))])

    equations = VehicleEquations(
        M=d.M, hull_terms=hull_terms, actuation=actuation, actuator_rate=actuator_rate,
        input_labels=("n1", "n2"), input_units=("rad/s", "rad/s"), u_min=u_min, u_max=u_max)
    return assemble(NAME, DESCRIPTION, 6, p, equations)
