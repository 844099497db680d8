"""Quadrotor attitude and altitude: nonlinear rigid body with the Quanser 3-DOF Hover's numbers.

For the quadrotor actuator-fault paper (Yang, Hu & Zhang: unknown input observers and zonotope
thresholds), which gives no plant numbers. NED axes: body x towards the front rotor, y towards
the right rotor, z down; zyx Euler angles Theta = (phi, theta, psi), body rates omega = (p, q, r)
(what gyros measure), T(Theta) of Fossen 2021, eq. 2.28; Euler's rigid-body equations::

    Theta' = T(Theta) omega
    J omega' = -omega x (J omega) + tau,   J = diag(Jr, Jp, Jy)
    tau = (l Kf (Vl - Vr), l Kf (Vf - Vb), Kt (Vf + Vb - Vr - Vl) + tau_d)
    z' = w,   m w' = m g - cos(phi) cos(theta) (m g + Kf (Vf + Vb + Vr + Vl))

with u = (Vf, Vb, Vr, Vl) the motor voltages' deviations from the hover trim ``m g / (4 Kf)``
(about 58.8 V each), so the trim thrust m g is carried by the rotors and u = 0 is an equilibrium
at any altitude and heading. Each rotor's thrust is Kf V and reaction torque Kt V; the front and
back propellers spin counter-clockwise seen from above (Quanser: "front/back motor are
counter-clockwise (negative torque)" about its upward z), which is positive yaw about NED's
downward z. Quanser's linear model has the same pitch row, the yaw row with the opposite sign
(z up) and ``l Kf (Vr - Vl) / Jr`` for roll: its roll angle is positive with the right side up.
Inertias as in Quanser's config_hover.m: ``Jp = Jr = 2 (Jm + m l^2 / 4)``, ``Jy = 4 (Jm + m l^2 / 4)``
(four point masses m/4 at l plus the motor rotors). Rotor gyroscopic torques are neglected.

No input bounds: the Quanser amplifier's +-24 V cannot carry the trim (the 3-DOF Hover sits on a
pivot); a free-flying vehicle with these numbers needs about 59 V per rotor. Outputs: all eight
states (with angles only, the paper's unknown-input-observer conditions fail).
"""

from __future__ import annotations

from pathlib import Path

import casadi as ca

from uvsym.kinematics import Tzyx
from uvsym.models.parameters import ParameterSet, load_parameters
from uvsym.systems.signals import signals
from uvsym.systems.system import System, system

NAME = "quadrotor"
DESCRIPTION = "Quadrotor attitude and altitude (Quanser 3-DOF Hover numbers), rotor voltages about hover trim"
PARAMETER_FILES = [Path(__file__).with_suffix(".toml")]

STATES = signals(("phi", "rad", "roll angle (zyx Euler)"), ("theta", "rad", "pitch angle (zyx Euler)"),
                 ("psi", "rad", "yaw angle (zyx Euler)"), ("p", "rad/s", "roll rate (body x)"),
                 ("q", "rad/s", "pitch rate (body y)"), ("r", "rad/s", "yaw rate (body z)"),
                 ("z", "m", "vertical position, NED (down positive; altitude is -z)"),
                 ("w", "m/s", "vertical speed z' (down positive)"), group="state")
INPUTS = signals(*((f"V{side[0]}", "V", f"{side} motor voltage minus hover trim m g / (4 Kf)")
                   for side in ("front", "back", "right", "left")), group="input")
DISTURBANCES = signals(("tau_d", "N m", "yaw disturbance torque about body z"), group="disturbance")


def inertias(p: ParameterSet) -> dict[str, float]:
    """Jr, Jp, Jy (kg m^2): ``2, 2, 4`` times ``Jm + (m/4) l^2`` (Quanser config_hover.m)."""
    section = p.v("Jm") + p.v("m") / 4 * p.v("l") ** 2
    return {"Jr": 2 * section, "Jp": 2 * section, "Jy": 4 * section}


def build(**overrides) -> System:
    """The quadrotor as a System at hover (x = 0, u = 0); overrides replace the Quanser numbers.

    Raises
    ------
    ModelError
        For an unknown, non-finite or out-of-bounds override.
    """
    p = load_parameters(NAME, PARAMETER_FILES, overrides)
    J = inertias(p)
    inertia = ca.DM([J["Jr"], J["Jp"], J["Jy"]])
    m, g, arm, Kf, Kt = (p.v(k) for k in ("m", "g", "l", "Kf", "Kt"))

    def rhs(x, u, d, _p):
        phi, theta = x[0], x[1]
        omega = x[3:6]
        Vf, Vb, Vr, Vl = (u[i] for i in range(4))
        tau = ca.vertcat(arm * Kf * (Vl - Vr), arm * Kf * (Vf - Vb), Kt * (Vf + Vb - Vr - Vl) + d[0])
        omega_dot = (tau - ca.cross(omega, inertia * omega)) / inertia
        w_dot = g - ca.cos(phi) * ca.cos(theta) * (m * g + Kf * (Vf + Vb + Vr + Vl)) / m
        return ca.vertcat(ca.mtimes(Tzyx(phi, theta), omega), omega_dot, x[7], w_dot)

    return system(NAME, DESCRIPTION, x=STATES, u=INPUTS, d=DISTURBANCES, rhs=rhs, constants=p,
                  extras={"inertias": J, "trim_voltage": m * g / (4 * Kf)},
                  source="Quanser 3-DOF Hover config_hover.m (Kf, Kt, l, m, Jm; Jp, Jr, Jy derived as there); "
                         "rigid-body equations and zyx Euler kinematics, Fossen 2021")
