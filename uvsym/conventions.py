"""Frames, symbols, units and index slices shared by every uvsym module.

Fossen's notation: ``eta`` NED position and zyx Euler angles, ``nu`` body-fixed velocities,
``tau`` generalised forces. SI units inside uvsym; degrees only at the edges (I/O, plots).
"""

from __future__ import annotations

__all__ = ["POSITION_LABELS", "VELOCITY_LABELS", "POSITION_UNITS", "VELOCITY_UNITS", "FORCE_LABELS", "FORCE_UNITS",
           "SYMBOLS"]

POSITION_LABELS = {
    6: ("x", "y", "z", "phi", "theta", "psi"),
    3: ("x", "y", "psi"),
}
VELOCITY_LABELS = {
    6: ("u", "v", "w", "p", "q", "r"),
    3: ("u", "v", "r"),
}
POSITION_UNITS = {6: ("m", "m", "m", "rad", "rad", "rad"), 3: ("m", "m", "rad")}
VELOCITY_UNITS = {6: ("m/s", "m/s", "m/s", "rad/s", "rad/s", "rad/s"), 3: ("m/s", "m/s", "rad/s")}
FORCE_LABELS = {6: ("X", "Y", "Z", "K", "M", "N"), 3: ("X", "Y", "N")}
FORCE_UNITS = {6: ("N", "N", "N", "N m", "N m", "N m"), 3: ("N", "N", "N m")}

# Symbol -> (meaning, frame, unit); the README's conventions table is this table.
SYMBOLS = {
    "eta": ("position (x, y, z) and zyx Euler angles (phi, theta, psi)", "NED", "m, rad"),
    "nu": ("linear (u, v, w) and angular (p, q, r) velocity", "BODY", "m/s, rad/s"),
    "nu_r": ("velocity relative to the water, nu - nu_c", "BODY", "m/s, rad/s"),
    "nu_c": ("ocean current velocity", "BODY", "m/s"),
    "V_c, beta_c": ("current speed and direction (towards, from north)", "NED", "m/s, rad"),
    "tau": ("generalised control force (X, Y, Z, K, M, N)", "BODY", "N, N m"),
    "u": ("actuator values actually applied", "actuator", "per vehicle (rad, rpm, rad/s, N)"),
    "M": ("mass matrix M_RB + M_A about the CO", "BODY", "kg, kg m, kg m^2"),
    "h(eta, nu)": ("all non-control forces: C(nu) nu + D(nu) nu + g(eta) + hull terms", "BODY", "N, N m"),
    "B": ("input matrix d tau / d u", "BODY", "per input"),
}
