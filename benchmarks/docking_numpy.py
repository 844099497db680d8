"""The docking closed loop written the way the field's reference simulator runs: plain numpy.

Baseline of ``benchmarks/sim.py``: the docking AUV (REMUS 100 hull of ``remus100_numpy`` with
the thruster, elevator and split rudders), semi-implicit Euler at the sample period, a PID
autopilot (speed, heading, depth) and the bias and proportional observers in momentum form
(forward Euler), one Python step per sample.
"""

from __future__ import annotations

import math

import numpy as np
from remus100_numpy import Remus100Numpy

from uvsym.models.vehicles.cruciform_fins import stern_fins


class DockingNumpy(Remus100Numpy):
    """nu_dot of the docking AUV for u = (X, delta_e, delta_ru, delta_rd), numpy only."""

    def __init__(self, model):
        super().__init__(model)
        self.u_min, self.u_max = model.u_min, model.u_max
        rho = self.p("rho")
        # per fin (top, bottom, starboard, port): lift coefficient, direction, position
        self.fins = [(0.5 * rho * fin.area * fin.CL, *_direction(fin.angle_deg), fin.x, fin.radius)
                     for fin in stern_fins(model.parameters)]

    def actuation(self, nu, u):
        X, delta_e, delta_ru, delta_rd = np.clip(u, self.u_min, self.u_max)
        tau = [X, 0.0, 0.0, 0.0, 0.0, 0.0]
        for (gain, c, s, x, radius), delta in zip(self.fins, (delta_ru, -delta_rd, -delta_e, delta_e)):
            f = gain * delta * (nu[0] ** 2 + (nu[1] * s) ** 2 + (nu[2] * c) ** 2)
            Fy, Fz = s * f, -c * f
            ry, rz = radius * c, radius * s
            tau[1] += Fy
            tau[2] += Fz
            tau[3] += ry * Fz - rz * Fy  # r x F with F = (0, Fy, Fz)
            tau[4] += -x * Fz
            tau[5] += x * Fy
        return np.array(tau)


def _direction(angle_deg: float) -> tuple[float, float]:
    quarter = angle_deg / 90.0
    if quarter == round(quarter):
        return ((1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0))[int(round(quarter)) % 4]
    return math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))


def _J(eta):
    phi, theta, psi = eta[3:]
    cphi, sphi, cth, sth, cpsi, spsi = (math.cos(phi), math.sin(phi), math.cos(theta), math.sin(theta),
                                        math.cos(psi), math.sin(psi))
    R = np.array([[cpsi * cth, -spsi * cphi + cpsi * sth * sphi, spsi * sphi + cpsi * cphi * sth],
                  [spsi * cth, cpsi * cphi + sphi * sth * spsi, -cpsi * sphi + sth * spsi * cphi],
                  [-sth, cth * sphi, cth * cphi]])
    T = np.array([[1, sphi * sth / cth, cphi * sth / cth], [0, cphi, -sphi], [0, sphi / cth, cphi / cth]])
    return R, T


def run(model, duration: float, dt: float, K_bias, K_prop) -> np.ndarray:
    """Simulate the closed loop; returns the (N + 1, 12) states. Faults: thrust + 13 N, rudders x 0.8."""
    plant = DockingNumpy(model)
    M, Minv = plant.M, plant.Minv
    N = int(round(duration / dt))
    eta, nu = np.array([-40.0, 0.0, 5.0, 0.0, 0.0, 0.0]), np.array([1.5, 0.0, 0.0, 0.0, 0.0, 0.0])
    x_bias, x_prop = K_bias * (M @ nu), np.zeros(6)
    states = np.empty((N + 1, 12))
    for k in range(N + 1):
        states[k] = np.r_[eta, nu]
        psi_error = math.remainder(0.5 - eta[5], 2 * math.pi)
        theta_ref = np.clip(-0.1 * (5.0 - eta[2]), -0.35, 0.35)
        u_d = np.array([8.0 + 40.0 * (1.5 - nu[0]), -(theta_ref - eta[4] - 0.5 * nu[4]),
                        psi_error - nu[5], psi_error - nu[5]])
        hull = plant.hull(eta, nu)
        tau_d = plant.actuation(nu, u_d)
        # bias and proportional observers, momentum form: R = -K M nu and R = -K T_d M nu
        h = -hull
        x_bias = x_bias + dt * (-K_bias * (x_bias + K_bias * (M @ nu) - h + tau_d))
        R_prop = -K_prop * tau_d * (M @ nu)
        x_prop = x_prop + dt * (-K_prop * tau_d * (tau_d * (x_prop - R_prop) - h))
        u_faulty = u_d * np.array([1.0, 1.0, 0.8, 0.8]) + np.array([13.0, 0.0, 0.0, 0.0])
        nu = nu + dt * (Minv @ (plant.actuation(nu, u_faulty) + hull))
        R, T = _J(eta)
        eta = eta + dt * np.r_[R @ nu[:3], T @ nu[3:]]
    return states
