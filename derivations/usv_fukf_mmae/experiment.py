"""The Otter with the paper's random force, and where the shipped scenario's tuning comes from.

Plant: ``uvsym.plant("otter3dof")`` plus the paper's random force ``tau_d = alpha_d rand(t)``
(eq. 6) as disturbances, ``nu' += M^-1 tau_d``; the scenario draws them (``[noise]``,
``{ uniform = alpha }`` per axis, one draw per sample). Loop (the scenario file): line-of-sight guidance with
speed and heading PID (the ``autopilot`` block), thrust commands saturated at the thrusters'
limits, thruster faults ``T_i = eta_i T_bar_i`` on their windows, every state measured with
Gaussian noise; the UKF and EKF banks (``mmae`` blocks) read the measurements and the saturated
commands ``T_bar`` (what the thruster was told), in the loop.

The scenario's numbers that follow from the model are derived here and checked against the file
by the tests: the speed loop's feed-forward ``d11 U`` (:func:`surge_damping`) and the banks' Q
(:func:`process_noise`).
"""

from __future__ import annotations

import casadi as ca
import numpy as np

import uvsym
from uvsym.sim.result import SimResult
from uvsym.sim.system_scenario import SystemScenario, simulate_system_scenario
from uvsym.symbolic import rk4
from uvsym.systems.signals import signals
from uvsym.systems.system import System, system

__all__ = ["disturbed_plant", "surge_damping", "process_noise", "run"]


def disturbed_plant() -> System:
    """``otter3dof`` with the force disturbance ``tau_d = (tau_u, tau_v, tau_r)`` (N, N, N m)."""
    base, M = uvsym.plant("otter3dof"), uvsym.vehicle("otter3dof").M
    d = signals(("tau_u", "N", "surge force disturbance"), ("tau_v", "N", "sway force disturbance"),
                ("tau_r", "N m", "yaw moment disturbance"), group="disturbance")
    return system("otter3dof_disturbed", f"{base.description}; random force disturbance tau_d", x=base.x, u=base.u,
                  d=d, p=base.p, p0=base.p0,
                  rhs=lambda x, u, dd, p: base.f(x, u, [], p) + ca.vertcat(ca.DM.zeros(3), ca.solve(ca.DM(M), dd)),
                  u_min=base.u_min, u_max=base.u_max, constants=base.constants,
                  source=f"{base.source}; tau_d as in the FUKF-MMAE paper's eq. 6")


def surge_damping(vehicle: str = "otter3dof") -> float:
    """d11 (N s/m): d h_surge / d u at rest, by casadi.jacobian."""
    model = uvsym.vehicle(vehicle)
    nu = ca.SX.sym("nu", model.dof)
    slope = ca.Function("d11", [nu], [ca.jacobian(model.h(ca.DM.zeros(model.dof), nu)[0], nu)])
    return float(slope(ca.DM.zeros(model.dof))[0])


def process_noise(alpha_d, dt: float, speed: float, heading: float) -> np.ndarray:
    """Q (6, 6) of the kinematic states: the disturbance's covariance ``alpha_d^2 / 3`` (uniform
    draws, amplitudes alpha_d (3,) in N, N, N m) through the sampled plant, ``G diag(alpha_d^2 / 3)
    G^T`` with ``G = dx_{k+1} / dtau_d`` (casadi.jacobian of the RK4 step over dt s) at surge
    ``speed`` (m/s) and ``heading`` (rad). The position block rotates with the heading: both
    positions get the largest variance over headings, their correlations with the other states
    are dropped; ``1e-12 I`` keeps Q positive definite."""
    plant = disturbed_plant()
    x, d = ca.SX.sym("x", 6), ca.SX.sym("d", 3)
    u = ca.DM.zeros(plant.u.size)
    step = rk4(lambda s, _t: plant.f(s, u, d, plant.p0), x, dt, 1)
    jac = ca.Function("G", [x, d], [ca.jacobian(step, d)])
    spread = np.diag(np.asarray(alpha_d, dtype=float) ** 2 / 3.0)

    def at(psi):
        G = np.asarray(jac([0.0, 0.0, psi, speed, 0.0, 0.0], np.zeros(3)))
        return G @ spread @ G.T

    Q = at(heading)
    Q[:2, :] = Q[:, :2] = 0.0
    Q[0, 0] = Q[1, 1] = max(float(np.max(np.diag(at(psi))[:2])) for psi in np.linspace(0.0, np.pi, 9))
    return Q + 1e-12 * np.eye(6)


def run(scenario: SystemScenario, progress=None) -> SimResult:
    """The scenario's loop with both banks, on CasADi's virtual machine (not compiled), so that the
    numbers do not depend on C compiler flags; ``events`` hold the detectors' decisions."""
    return simulate_system_scenario(scenario, compiled=False, progress=progress)
