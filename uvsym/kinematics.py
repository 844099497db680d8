"""Rigid-body kinematics in Fossen's notation (Fossen 2021, chapter 2), generic over types.

Every function accepts Python floats, numpy arrays, or CasADi ``SX``/``MX``/``DM`` and
returns the matching kind: a numpy array for numeric input, a CasADi matrix when any
argument is symbolic or a ``DM``. Angles are in radians, positions in metres.
"""

from __future__ import annotations

import math

import casadi as ca
import numpy as np

from uvsym.errors import KinematicsError
from uvsym.symbolic import entries, is_casadi, stack

__all__ = ["Smtrx", "Hmtrx", "Rzyx", "Tzyx", "J", "ssa"]

# |cos(theta)| below this is treated as the Euler-angle singularity theta = +-90 deg.
_COS_THETA_MIN = 1e-9


def _entries(vector, n: int):
    try:
        return entries(vector, n)
    except ValueError as exc:
        raise KinematicsError(str(exc)) from None


def Smtrx(a):
    """Skew-symmetric matrix S(a), 3x3, with S(a) b = a x b (Fossen 2021, eq. 2.10).

    Parameters
    ----------
    a : (3,) array
        The vector a.
    """
    a1, a2, a3 = _entries(a, 3)
    return stack([[0.0, -a3, a2], [a3, 0.0, -a1], [-a2, a1, 0.0]])


def Hmtrx(r):
    """System transformation matrix H(r) = [[I3, S(r)^T], [0, I3]], 6x6 (Fossen 2021, eq. 3.29).

    With r = r_bg (CO to CG, m): M_CO = H^T M_CG H, and H(r)^-1 = H(-r).
    """
    S_T = Smtrx(r).T
    rows = [[1.0 if i == j else 0.0 for j in range(3)] + [S_T[i, j] for j in range(3)] for i in range(3)]
    rows += [[0.0] * 3 + [1.0 if i == j else 0.0 for j in range(3)] for i in range(3)]
    return stack(rows)


def Rzyx(phi, theta, psi):
    """Rotation matrix BODY -> NED for zyx Euler angles, 3x3 (Fossen 2021, eq. 2.18)."""
    cphi, sphi = ca.cos(phi), ca.sin(phi)
    cth, sth = ca.cos(theta), ca.sin(theta)
    cpsi, spsi = ca.cos(psi), ca.sin(psi)
    return stack(
        [
            [cpsi * cth, -spsi * cphi + cpsi * sth * sphi, spsi * sphi + cpsi * cphi * sth],
            [spsi * cth, cpsi * cphi + sphi * sth * spsi, -cpsi * sphi + sth * spsi * cphi],
            [-sth, cth * sphi, cth * cphi],
        ]
    )


def Tzyx(phi, theta):
    """Euler-angle rate transformation T(phi, theta), 3x3 (Fossen 2021, eq. 2.28).

    Raises
    ------
    KinematicsError
        For a numeric theta within 1e-9 of cos(theta) = 0 (theta = +-90 deg), where
        T is singular. A symbolic theta cannot be checked; that is the caller's domain.
    """
    cphi, sphi = ca.cos(phi), ca.sin(phi)
    cth, sth = ca.cos(theta), ca.sin(theta)
    if not is_casadi(theta) and abs(float(cth)) < _COS_THETA_MIN:
        raise KinematicsError(
            f"Tzyx is singular at theta = {math.degrees(float(theta)):.6g} deg "
            "(pitch of +-90 deg); use quaternions or keep |theta| < 90 deg"
        )
    return stack(
        [
            [1.0, sphi * sth / cth, cphi * sth / cth],
            [0.0, cphi, -sphi],
            [0.0, sphi / cth, cphi / cth],
        ]
    )


def J(eta):
    """Kinematic transformation J(eta) = diag(R(Theta), T(Theta)), 6x6: eta_dot = J(eta) nu."""
    _, _, _, phi, theta, psi = _entries(eta, 6)
    R = Rzyx(phi, theta, psi)
    T = Tzyx(phi, theta)
    rows = [[R[i, j] for j in range(3)] + [0.0] * 3 for i in range(3)]
    rows += [[0.0] * 3 + [T[i, j] for j in range(3)] for i in range(3)]
    return stack(rows)


def ssa(angle):
    """Smallest signed angle, mapped to [-pi, pi) (rad): angle - 2 pi floor((angle + pi) / 2 pi)."""
    if isinstance(angle, np.ndarray):
        return angle - 2.0 * np.pi * np.floor((angle + np.pi) / (2.0 * np.pi))
    return angle - 2.0 * math.pi * ca.floor((angle + math.pi) / (2.0 * math.pi))
