"""Rigid-body mass and Coriolis-centripetal matrices (Fossen 2021, ch. 3 and 6).

Numeric inputs give numpy arrays; a symbolic velocity gives a CasADi matrix.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from uvsym.kinematics import Hmtrx, Smtrx
from uvsym.symbolic import block, is_casadi, matvec, stack

__all__ = ["rigid_body_mass", "coriolis_from_mass", "coriolis_rigid_body_cg"]


def rigid_body_mass(m: float, I_g, r_bg) -> np.ndarray:
    """M_RB = H(r_bg)^T diag(m I3, I_g) H(r_bg), 6x6, about the CO (Fossen 2021, eq. 3.37).

    Parameters
    ----------
    m : float
        Mass (kg).
    I_g : (3, 3) array
        Inertia dyadic about the CG (kg m^2).
    r_bg : (3,) array
        CG relative to the CO, body axes (m).
    """
    M_cg = np.zeros((6, 6))
    M_cg[:3, :3] = m * np.eye(3)
    M_cg[3:, 3:] = np.asarray(I_g, dtype=float)
    H = Hmtrx(r_bg)
    return H.T @ M_cg @ H


def coriolis_from_mass(M, nu):
    """C(nu) from a mass matrix by the skew-symmetric parametrisation (Fossen 2021, eq. 3.46).

    6-DOF: ``C = [[0, -S(M11 nu1 + M12 nu2)], [-S(M11 nu1 + M12 nu2), -S(M21 nu1 + M22 nu2)]]``;
    3-DOF (surge, sway, yaw): ``C = [[0, 0, -M22 v - M23 r], [0, 0, M11 u], [M22 v + M23 r, -M11 u, 0]]``.
    Only the symmetric part of M is used, so ``nu^T C(nu) nu = 0`` for every nu.

    Parameters
    ----------
    M : (n, n) array
        Mass matrix, n = 6 or 3 (kg, kg m, kg m^2).
    nu : (n,) array or CasADi vector
        Velocity (m/s, rad/s).
    """
    M = np.asarray(M, dtype=float)
    M = 0.5 * (M + M.T)
    if M.shape[0] == 6:
        a = -Smtrx(matvec(M[:3, :], nu))
        b = -Smtrx(matvec(M[3:, :], nu))
        return block([[np.zeros((3, 3)), a], [a, b]])
    c13 = -M[1, 1] * nu[1] - M[1, 2] * nu[2]
    c23 = M[0, 0] * nu[0]
    return stack([[0.0, 0.0, c13], [0.0, 0.0, c23], [-c13, -c23, 0.0]])


def coriolis_rigid_body_cg(m: float, I_g, r_bg, nu):
    """C_RB = H^T [[m S(nu2), 0], [0, -S(I_g nu2)]] H, 6x6 (Fossen 2021, eq. 3.57, moved to the CO).

    A skew-symmetric C_RB whose translational block depends on the angular rates only.

    Parameters
    ----------
    m : float
        Mass (kg).
    I_g : (3, 3) array
        Inertia about the CG (kg m^2).
    r_bg : (3,) array
        CG from the CO (m).
    nu : (6,) array or CasADi vector
        Body velocity (m/s, rad/s).
    """
    H = Hmtrx(r_bg)
    nu2 = nu[3:6]
    C_cg = block([[m * Smtrx(nu2), np.zeros((3, 3))],
                  [np.zeros((3, 3)), -Smtrx(matvec(np.asarray(I_g, dtype=float), nu2))]])
    if is_casadi(C_cg):
        return ca.mtimes([ca.DM(H.T), C_cg, ca.DM(H)])
    return H.T @ C_cg @ H
