"""REMUS 100 nu_dot written the way the field's reference simulator writes it: plain numpy.

The baseline of ``benchmarks/rhs.py``; same formulas and constants as uvsym's model (checked
against it there), evaluated per call with numpy arrays.
"""

from __future__ import annotations

import math

import numpy as np

from uvsym.models.hydrodynamics import hoerner_cd
from uvsym.models.vehicles.remus100_hull import MUNK_FREE_ENTRIES, hull


def _skew(a):
    return np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])


def _m2c(M, nu):
    a = M[:3, :3] @ nu[:3] + M[:3, 3:] @ nu[3:]
    b = M[3:, :3] @ nu[:3] + M[3:, 3:] @ nu[3:]
    C = np.zeros((6, 6))
    C[:3, 3:] = -_skew(a)
    C[3:, :3] = -_skew(a)
    C[3:, 3:] = -_skew(b)
    return C


class Remus100Numpy:
    """nu_dot(eta, nu, u) at zero current for the REMUS 100, numpy only."""

    def __init__(self, model):
        body = hull(model.parameters)  # constants only; every per-call formula is below
        self.p = model.parameters.v
        self.M, self.Minv = body.M, np.linalg.inv(body.M)
        self.MRB, self.MA = body.M_RB, body.M_A
        self.W, self.S, self.CD_0 = body.W, body.S, body.CD_0
        self.w_roll, self.w_pitch = body.omega_roll, body.omega_pitch
        self.cd_2d = hoerner_cd(self.p("diam"), self.p("diam"))

    def nu_dot(self, eta, nu, u):
        """Accelerations (6,) for actuator values u = (delta_r, delta_s, n)."""
        return self.Minv @ (self.actuation(nu, u) + self.hull(eta, nu))

    def actuation(self, nu, u):
        """tau (6,) of the rudder, stern plane and propeller."""
        p, L, rho = self.p, self.p("L"), self.p("rho")
        delta_r = np.clip(u[0], -p("deltaMax_r"), p("deltaMax_r"))
        delta_s = np.clip(u[1], -p("deltaMax_s"), p("deltaMax_s"))
        n = np.clip(u[2], -p("nMax"), p("nMax"))
        U = math.sqrt(nu[0] ** 2 + nu[1] ** 2 + nu[2] ** 2)
        n_rps, D = n / 60, p("D_prop")
        Va = p("wake_factor") * U
        if n_rps > 0:
            X_prop = rho * D**4 * (p("KT_0") * abs(n_rps) * n_rps
                                   + (p("KT_max") - p("KT_0")) / p("Ja_max") * (Va / D) * abs(n_rps))
            K_prop = rho * D**5 * (p("KQ_0") * abs(n_rps) * n_rps
                                   + (p("KQ_max") - p("KQ_0")) / p("Ja_max") * (Va / D) * abs(n_rps))
        else:
            X_prop = rho * D**4 * p("KT_0") * abs(n_rps) * n_rps
            K_prop = rho * D**5 * p("KQ_0") * abs(n_rps) * n_rps
        U_rh2, U_rv2 = nu[0] ** 2 + nu[1] ** 2, nu[0] ** 2 + nu[2] ** 2
        Y_r = -0.5 * rho * U_rh2 * p("A_r") * p("CL_delta_r") * delta_r
        Z_s = -0.5 * rho * U_rv2 * p("A_s") * p("CL_delta_s") * delta_s
        return np.array([(1 - p("t_prop")) * X_prop + Y_r * delta_r + Z_s * delta_s, Y_r, Z_s,
                         p("torque_scale") * K_prop, L / 2 * Z_s, -L / 2 * Y_r])

    def hull(self, eta, nu):
        """Every hull force (6,) on the right-hand side: lift, drag, cross-flow, -(C + D) nu - g."""
        p, M = self.p, self.M
        rho, L, diam = p("rho"), p("L"), p("diam")
        U = math.sqrt(nu[0] ** 2 + nu[1] ** 2 + nu[2] ** 2)
        alpha = math.atan2(nu[2], nu[0])
        CA = _m2c(self.MA, nu)
        for i, j in MUNK_FREE_ENTRIES:
            CA[i, j] = 0
        C = _m2c(self.MRB, nu) + CA
        decay = math.exp(-p("damping_decay") * U)
        D_mat = np.diag([M[0, 0] / p("T_surge") * decay, M[1, 1] / p("T_sway") * decay, M[2, 2] / p("T_heave"),
                         M[3, 3] * 2 * p("zeta_roll") * self.w_roll, M[4, 4] * 2 * p("zeta_pitch") * self.w_pitch,
                         M[5, 5] / p("T_yaw")])
        AR = diam**2 / self.S
        CL = math.pi * AR / (1 + math.sqrt(1 + (AR / 2) ** 2)) * alpha
        CD = self.CD_0 + CL**2 / (math.pi * 0.7 * AR)
        F_drag, F_lift = 0.5 * rho * U**2 * self.S * CD, 0.5 * rho * U**2 * self.S * CL
        tau_ld = np.array([math.cos(alpha) * -F_drag + math.sin(alpha) * F_lift, 0,
                           math.sin(alpha) * -F_drag - math.cos(alpha) * F_lift, 0, 0, 0])
        Yh = Nh = 0.0
        dx, x = L / 20, -L / 2
        for _ in range(21):
            ucf = abs(nu[1] + x * nu[5]) * (nu[1] + x * nu[5])
            Yh -= 0.5 * rho * diam * self.cd_2d * ucf * dx
            Nh -= 0.5 * rho * diam * self.cd_2d * x * ucf * dx
            x += dx
        tau_cf = np.array([0, Yh, 0, 0, 0, Nh])
        phi, theta = eta[3], eta[4]
        zgW = p("r_bg")[2] * self.W
        g = np.array([0, 0, 0, zgW * math.cos(theta) * math.sin(phi), zgW * math.sin(theta), 0])
        return tau_ld + tau_cf - (C + D_mat) @ nu - g
