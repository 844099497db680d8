"""Actuator force models: saturation, propellers and control fins (Fossen 2021, ch. 9).

Each returns forces in N (moments in N m) about the CO in body axes, CasADi expressions of
the actuator value actually applied and of the velocity.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import casadi as ca
import numpy as np

from uvsym.kinematics import Smtrx
from uvsym.symbolic import matvec

__all__ = [
    "saturate",
    "PropellerCoefficients",
    "propeller_thrust_torque",
    "bollard_thrust",
    "control_surface_lift",
    "Fin",
    "fin_force",
]


def saturate(x, lower, upper):
    """Amplitude saturation, elementwise ``min(max(x, lower), upper)``."""
    return ca.fmin(ca.fmax(x, lower), upper)


@dataclass(frozen=True)
class PropellerCoefficients:
    """Linearised open-water propeller data (Allen et al. 2000; Wageningen B-series fit).

    KT = KT_0 + (KT_max - KT_0) Ja / Ja_max, KQ likewise, for Ja >= 0.
    diameter (m); wake (-): advance speed Va = wake * U; thrust_deduction (-).
    """

    diameter: float
    KT_0: float
    KQ_0: float
    KT_max: float
    KQ_max: float
    Ja_max: float
    wake: float
    thrust_deduction: float


def propeller_thrust_torque(n_rpm, U, rho: float, c: PropellerCoefficients):
    """Propeller thrust X_prop (N) and torque K_prop (N m) at n_rpm (rpm) and vehicle speed U (m/s).

    Forward (n > 0): ``X = rho D^4 (KT_0 |n| n + (KT_max - KT_0)/Ja_max (Va/D) |n|)``, n in rps;
    reverse: ``X = rho D^4 KT_0 |n| n``; K likewise with D^5 and KQ. Returns (X_prop, K_prop);
    the thrust delivered to the hull is (1 - t) X_prop.
    """
    n = n_rpm / 60.0
    Va = c.wake * U
    D = c.diameter
    X_fwd = rho * D**4 * (c.KT_0 * ca.fabs(n) * n + (c.KT_max - c.KT_0) / c.Ja_max * (Va / D) * ca.fabs(n))
    K_fwd = rho * D**5 * (c.KQ_0 * ca.fabs(n) * n + (c.KQ_max - c.KQ_0) / c.Ja_max * (Va / D) * ca.fabs(n))
    X_rev = rho * D**4 * c.KT_0 * ca.fabs(n) * n
    K_rev = rho * D**5 * c.KQ_0 * ca.fabs(n) * n
    forward = n > 0
    return ca.if_else(forward, X_fwd, X_rev), ca.if_else(forward, K_fwd, K_rev)


def bollard_thrust(n, k_pos: float, k_neg: float):
    """Fixed-pitch propeller thrust from bollard-pull data: ``k |n| n``, k = k_pos for n > 0 else k_neg (N)."""
    return ca.if_else(n > 0, k_pos, k_neg) * n * ca.fabs(n)


def control_surface_lift(rho: float, area: float, CL_delta: float, delta, U2):
    """Lift of a control surface at deflection delta (rad) in a flow of squared speed U2 (m^2/s^2).

    ``F = -1/2 rho U^2 A CL_delta delta`` (N), the sign making positive rudder turn to port.
    """
    return -0.5 * rho * U2 * area * CL_delta * delta


@dataclass(frozen=True)
class Fin:
    """A control fin at the stern (Fossen 2021, sec. 9.4; the reference simulator's fin class).

    area (m^2); CL (-) lift slope per rad; x (m) longitudinal position of the centre of pressure;
    radius (m) of the centre of pressure from the x axis; angle_deg (deg) position around the x
    axis from +y towards +z (0: starboard-to-port plane at +y, 90: bottom, 180: -y, 270: top).
    """

    area: float
    CL: float
    x: float
    radius: float
    angle_deg: float

    def direction(self) -> tuple[float, float]:
        """(cos, sin) of the fin angle, exact for multiples of 90 deg so B keeps its zeros."""
        quarter = self.angle_deg / 90.0
        if quarter == round(quarter):
            return ((1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0))[int(round(quarter)) % 4]
        rad = math.radians(self.angle_deg)
        return math.cos(rad), math.sin(rad)


def fin_force(fin: Fin, delta, nu_r, rho: float):
    """Generalised force of one fin at deflection delta (rad), (6,).

    Lift ``f = 1/2 rho A CL delta U_p^2`` with ``U_p^2 = u_r^2 + (v_r sin a)^2 + (w_r cos a)^2``,
    force ``F = (0, sin(a) f, -cos(a) f)`` at ``R = (x, c cos a, c sin a)``, moment ``R x F``.
    """
    cos_a, sin_a = fin.direction()
    u_r, v_r, w_r = nu_r[0], nu_r[1], nu_r[2]
    U_plane2 = u_r**2 + (v_r * sin_a) ** 2 + (w_r * cos_a) ** 2
    f = 0.5 * rho * fin.area * fin.CL * delta * U_plane2
    F = ca.vertcat(0.0, sin_a * f, -cos_a * f)
    R = np.array([fin.x, fin.radius * cos_a, fin.radius * sin_a])
    return ca.vertcat(F, matvec(Smtrx(R), F))
