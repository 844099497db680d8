"""Fault identification: actuator values from generalised forces, and severity (Liu et al. 2014, sec. 2.3).

Near the values ``u_e`` the actuators are expected to deliver, ``tau = tau(u_e) + B (u - u_e)``
with ``B = d tau / d u`` at (state, u_e) -- exact for actuation affine in u (fins), first order
for propellers -- so the actuator values that produce a generalised force are
``u = u_e + B^+ (tau - tau(u_e))`` (eq. 26) when B has full column rank. The fault's value
per actuator compares them with the desired values u_d as its kind says
(:meth:`uvsym.faults.ActuatorKind.identify`): proportional ``f_p = u / u_d``, bias
``f_a = u - u_d``, constant ``f_c = u``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from uvsym.errors import IdentifiabilityError
from uvsym.models.configurations import ActuatorConfiguration, identifiability
from uvsym.models.model import Model

__all__ = ["ActuatorFaultEstimate", "configuration_at", "actuator_values"]


@dataclass(frozen=True)
class ActuatorFaultEstimate:
    """One actuator's identified fault: kind, severity (f_p, f_a in the input's unit, or f_c) and time (s)."""

    actuator: str
    kind: str
    value: float
    time_s: float


def configuration_at(model: Model, eta, nu, u) -> ActuatorConfiguration:
    """The model's actuator configuration, B = d tau / d u at (eta, nu, u), as 6 rows."""
    B = np.asarray(model.B(eta, nu, u, 0.0, 0.0))
    if model.dof != 6:
        B = np.insert(B, [2, 2, 2], 0.0, axis=0)  # (X, Y, N) -> (X, Y, 0, 0, 0, N)
    return ActuatorConfiguration(model.name, B, model.input_labels, (("all", tuple(range(model.n_inputs))),))


def actuator_values(config: ActuatorConfiguration, tau, tau_e=None, u_e=None, rows=None) -> np.ndarray:
    """``u = u_e + B^+ (tau - tau_e)`` (eq. 26) from the force rows ``rows`` (default all six).

    tau, tau_e: (6,) in N and N m (tau_e = tau(u_e), default 0); u_e: (m,) default 0.
    Raises IdentifiabilityError unless those rows of B have full column rank (names the
    actuators that trade against each other).
    """
    rows = list(range(6)) if rows is None else list(rows)
    sub = ActuatorConfiguration(config.name, np.asarray(config.B)[rows], config.labels, config.groups)
    check = identifiability(sub)
    if not check.all_identifiable:
        reasons = "; ".join(r for r in check.reasons if r)
        raise IdentifiabilityError(f"{config.name}: actuator values cannot be recovered from tau: {reasons}")
    tau = np.asarray(tau, dtype=float).ravel()
    tau_e = np.zeros_like(tau) if tau_e is None else np.asarray(tau_e, dtype=float).ravel()
    u_e = np.zeros(len(config.labels)) if u_e is None else np.asarray(u_e, dtype=float).ravel()
    return u_e + np.linalg.pinv(sub.B) @ (tau - tau_e)[rows]

