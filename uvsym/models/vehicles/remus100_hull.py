"""The REMUS 100 hull shared by remus100, torpedo and docking_auv (Fossen 2021, sec. 8.4.2).

Mass and inertia of a prolate spheroid of water, added mass from Lamb's k-factors, linear
damping from time constants and damping ratios, hull lift/drag, cross-flow drag and restoring
forces, as in Fossen's Python Vehicle Simulator.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import casadi as ca
import numpy as np

from uvsym.errors import ModelError
from uvsym.models.actuators import PropellerCoefficients
from uvsym.models.hydrodynamics import (
    crossflow_drag,
    lift_drag,
    restoring_submerged,
    speed,
    spheroid_added_mass,
    spheroid_rigid_body,
)
from uvsym.models.parameters import ParameterSet
from uvsym.models.rigid_body import coriolis_from_mass, rigid_body_mass

__all__ = ["HULL_FILE", "PROPELLER_FILE", "MUNK_FREE_ENTRIES", "Hull", "hull", "propeller"]

HULL_FILE = Path(__file__).with_name("remus100_hull.toml")
PROPELLER_FILE = Path(__file__).with_name("remus100_propeller.toml")

# Entries of C_A set to zero, in symmetric pairs so C_A stays skew-symmetric: the quadratic
# velocity terms in pitch and the Munk moment in yaw, which destabilise the model when there
# is no quadratic rotational damping (as in the reference simulator).
MUNK_FREE_ENTRIES = ((4, 0), (0, 4), (4, 2), (2, 4), (5, 0), (0, 5), (5, 1), (1, 5))


@dataclass(frozen=True)
class Hull:
    """Derived hull data: masses (kg), matrices about the CO, weight/buoyancy (N), geometry (m)."""

    params: ParameterSet
    m: float
    M_RB: np.ndarray
    M_A: np.ndarray
    W: float
    B: float
    S: float
    CD_0: float
    omega_roll: float
    omega_pitch: float

    @property
    def M(self) -> np.ndarray:
        """M = M_RB + M_A, 6x6."""
        return self.M_RB + self.M_A

    def terms(self, eta, nu_r):
        """Named hull terms (left-hand side of M nu_r_dot + h = tau), each (6,) SX.

        Linear damping in surge and sway is scaled by exp(-damping_decay U_r): it fades at
        speed, where lift, drag and cross-flow drag dominate.
        """
        p = self.params
        C_RB = coriolis_from_mass(self.M_RB, nu_r)
        C_A = coriolis_from_mass(self.M_A, nu_r)
        for i, j in MUNK_FREE_ENTRIES:
            C_A[i, j] = 0
        M = self.M
        U_r = speed(nu_r[0], nu_r[1], nu_r[2])
        d = [M[0, 0] / p.v("T_surge"), M[1, 1] / p.v("T_sway"), M[2, 2] / p.v("T_heave"),
             M[3, 3] * 2 * p.v("zeta_roll") * self.omega_roll,
             M[4, 4] * 2 * p.v("zeta_pitch") * self.omega_pitch, M[5, 5] / p.v("T_yaw")]
        decay = ca.exp(-p.v("damping_decay") * U_r)
        D = ca.diag(ca.vertcat(*[d_i * decay if i in (0, 1) else d_i for i, d_i in enumerate(d)]))
        rho, L, diam = p.v("rho"), p.v("L"), p.v("diam")
        return {
            "coriolis": ca.mtimes(C_RB + C_A, nu_r),
            "damping": ca.mtimes(D, nu_r),
            "restoring": restoring_submerged(self.W, self.B, eta[3], eta[4], p.v("r_bg"), p.v("r_bb")),
            "lift_drag": -lift_drag(diam, self.S, self.CD_0, nu_r, rho),
            "crossflow": -crossflow_drag(L, diam, diam, nu_r, rho),
        }


def hull(p: ParameterSet) -> Hull:
    """Derive the hull's mass matrices and coefficients from its parameters."""
    a, b = p.v("L") / 2.0, p.v("diam") / 2.0
    if b >= a:
        raise ModelError(f"{p.vehicle}: parameter 'diam' = {p.v('diam')} m must be smaller than 'L' = {p.v('L')} m "
                         "(the hull is a prolate spheroid)")
    m, Ix, Iy = spheroid_rigid_body(p.v("rho"), a, b)
    M_RB = rigid_body_mass(m, np.diag([Ix, Iy, Iy]), p.v("r_bg"))
    M_A = spheroid_added_mass(m, a, b, Ix, Iy, p.v("r44"))
    M = M_RB + M_A
    W = m * p.v("g")
    S = p.v("projected_area_ratio") * p.v("L") * p.v("diam")
    BG_z = p.v("r_bg")[2] - p.v("r_bb")[2]
    return Hull(
        params=p, m=m, M_RB=M_RB, M_A=M_A, W=W, B=W, S=S,
        CD_0=p.v("Cd") * math.pi * b**2 / S,
        omega_roll=math.sqrt(W * BG_z / M[3, 3]) if BG_z > 0 else 0.0,
        omega_pitch=math.sqrt(W * BG_z / M[4, 4]) if BG_z > 0 else 0.0,
    )


def propeller(p: ParameterSet) -> PropellerCoefficients:
    """The REMUS 100 propeller's coefficients from its parameters."""
    return PropellerCoefficients(
        diameter=p.v("D_prop"), KT_0=p.v("KT_0"), KQ_0=p.v("KQ_0"), KT_max=p.v("KT_max"),
        KQ_max=p.v("KQ_max"), Ja_max=p.v("Ja_max"), wake=p.v("wake_factor"), thrust_deduction=p.v("t_prop"))
