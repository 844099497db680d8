"""Heading of a differential-thrust micro-ROV: one yaw degree of freedom with the compass as output.

For the LMS compass-fault paper (Zhu Daqi et al.: adaptive FIR filter on an Outland 1000 ROV),
whose vehicle numbers are not published; the proxy is the VideoRay Pro III (Wang 2006)::

    psi' = r
    m66 r' = N_r r + N_r|r| |r| r + tau_max u + tau_d
    y = psi

u in [-1, 1] is the normalised differential thrust command (tau_max = 0.2 N m at u = 1 is uvsym's
choice: a steady full-thrust turn of ``(-|N_r| + sqrt(N_r^2 + 4 |N_r|r|| tau_max)) / (2 |N_r|r||)``
= 0.642 rad/s, 37 deg/s); tau_d a yaw disturbance torque. Every heading is an equilibrium at
r = 0, u = 0; the operating point is the paper's heading set-point, 150 deg.
"""

from __future__ import annotations

import math
from pathlib import Path

import casadi as ca

from uvsym.models.parameters import load_parameters
from uvsym.systems.signals import signals
from uvsym.systems.system import System, system

NAME = "rov_yaw"
DESCRIPTION = "Micro-ROV heading (VideoRay Pro III yaw, Wang 2006), normalised thrust command, compass output"
PARAMETER_FILES = [Path(__file__).with_suffix(".toml")]
HEADING_SET_POINT = math.radians(150.0)

STATES = signals(("psi", "rad", "heading (yaw angle)"), ("r", "rad/s", "yaw rate"), group="state")
INPUTS = signals(("u", "-", "differential thrust command, normalised to [-1, 1]"), group="input")
DISTURBANCES = signals(("tau_d", "N m", "yaw disturbance torque"), group="disturbance")
OUTPUTS = signals(("psi", "rad", "compass heading"), group="output")


def build(**overrides) -> System:
    """The heading model as a System; overrides replace m66, N_r, N_rr (N_r|r|) or tau_max.

    Raises
    ------
    ModelError
        For an unknown, non-finite or out-of-bounds override (damping must be <= 0).
    """
    p = load_parameters(NAME, PARAMETER_FILES, overrides)
    m66, N_r, N_rr, tau_max = (p.v(k) for k in ("m66", "N_r", "N_rr", "tau_max"))

    def rhs(x, u, d, _p):
        r = x[1]
        return ca.vertcat(r, (N_r * r + N_rr * ca.fabs(r) * r + tau_max * u[0] + d[0]) / m66)

    return system(NAME, DESCRIPTION, x=STATES, u=INPUTS, d=DISTURBANCES, y=OUTPUTS, rhs=rhs,
                  output=lambda x, u, _p: x[0], x_op=[HEADING_SET_POINT, 0.0], u_op=[0.0],
                  u_min=[-1.0], u_max=[1.0], constants=p,
                  source="VideoRay Pro III yaw coefficients (Wang 2006, p. 19) as a proxy for the Outland 1000; "
                         "tau_max = 0.2 N m is uvsym's choice")
