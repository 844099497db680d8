"""Fault-tolerant loops by machine: ``V = nu^T M nu`` decreases on a box of body velocities.

:func:`damping_injection_loop` builds a concrete loop from uvsym's own parts: a model without
restoring forces (so ``nu = 0`` is the equilibrium and V needs no position terms) under
damping-injection feedback ``u_d = -k B^T nu`` at ``eta = 0``, the model's ``nu_dot``
(saturation included), ``apply_actuator_faults`` for the faults and ``linear_correction`` for
the correction from estimates of their values. With ``P = M``, ``nu^T C(nu) nu = 0``, and the
healthy loop keeps ``V' <= -2 nu^T D nu``, D the damping at rest: gamma, the rate claimed, is
the smallest eigenvalue of D's symmetric part. :func:`kinetic_energy_decrease` checks
``V' <= -gamma nu^T nu`` on the box by interval branch-and-bound
(:func:`uvsym.verify.region.region_decrease`); an uncorrected fault, or a correction from
inexact estimates, makes V' positive near the equilibrium (refuted, with a counterexample).
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from uvsym.faults import ActuatorFault, apply_actuator_faults
from uvsym.models.model import Model
from uvsym.observers.ftc import linear_correction
from uvsym.observers.identification import ActuatorFaultEstimate
from uvsym.verify.certificate import Certificate
from uvsym.verify.region import region_decrease

__all__ = ["VelocityLoop", "damping_injection_loop", "kinetic_energy_decrease"]


@dataclass(frozen=True)
class VelocityLoop:
    """``nu' = nu_dot`` (SX in the symbol ``nu``) of a closed loop on ``model``, the rate ``gamma``
    that V should keep, and its control law in words (``control``)."""

    model: Model
    nu: ca.SX
    nu_dot: ca.SX
    gamma: float
    control: str


def damping_injection_loop(model: Model, gain: float, faults: tuple[ActuatorFault, ...] = (),
                           estimates: tuple[float, ...] | None = None, fault_time: float = 0.0) -> VelocityLoop:
    """``u_d = -gain B^T nu`` (gain in the input's unit per m/s), ``faults`` at ``fault_time`` (s), and,
    given ``estimates`` (one value per fault, of its kind), the correction computed from them."""
    nu, eta = ca.SX.sym("nu", model.dof), ca.DM.zeros(model.dof)
    B = np.asarray(model.B(eta, np.zeros(model.dof), np.zeros(model.n_inputs), 0.0, 0.0))
    u_d = -gain * ca.mtimes(B.T, nu)
    u_cmd = u_d
    if estimates is not None:
        labels = [model.input_labels[f.actuator] for f in faults]
        identified = {label: ActuatorFaultEstimate(label, f.kind, value, 0.0)
                      for label, f, value in zip(labels, faults, estimates)}
        correction = linear_correction(identified, model.input_labels, B)
        u_cmd = ca.mtimes(correction.S, u_d) + correction.o
    u = apply_actuator_faults(u_cmd, ca.DM(fault_time), faults)
    damping = np.asarray(ca.Function("dh", [nu], [ca.jacobian(model.h(eta, nu), nu)])(np.zeros(model.dof)))
    gamma = float(np.min(np.linalg.eigvalsh(0.5 * (damping + damping.T))))
    return VelocityLoop(model, nu, model.nu_dot(eta, nu, u, 0.0, 0.0), gamma, f"u_d = -{gain:g} B' nu")


def kinetic_energy_decrease(label: str, loop: VelocityLoop, box, cube: float, expected: str = "proved") -> Certificate:
    """``label: V = nu'M nu, V' <= -gamma nu'nu with <control>`` on ``|nu_i| <= box_i``; the cube of
    half-side ``cube`` around ``nu = 0`` is covered by the Hessian argument."""
    model, box = loop.model, np.asarray(box, dtype=float)
    V = ca.bilin(ca.DM(model.M), loop.nu, loop.nu)
    labels = tuple(f"{name} ({unit})" for name, unit in zip(model.state_labels[model.dof:],
                                                           model.state_units[model.dof:]))
    claim = f"{label}: V = nu'M nu, V' <= -{loop.gamma:.4g} nu'nu with {loop.control}"
    where = ", ".join(f"|{name}| <= {bound:g}" for name, bound in zip(labels, box))
    return region_decrease(claim, V, loop.nu_dot, loop.nu, loop.gamma, -box, box, cube, labels=labels,
                           set_description=where, expected=expected)
