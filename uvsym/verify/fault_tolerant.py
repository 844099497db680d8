"""The core paper's section 3.2 by machine: the fault-tolerant loop decreases ``V = nu^T P nu``.

The paper argues with a generic feedback. uvsym makes it concrete (its choice, stated in every
claim): the 3-DOF Otter (no restoring forces, so ``nu = 0`` is the equilibrium and V needs no
position terms) under damping-injection feedback ``u_d = -k B^T nu`` on its twin thrusters, with
``P = M`` (then ``nu^T C(nu) nu = 0``). The loop is built from uvsym's own parts: the model's
``nu_dot`` (thrust saturation included), ``apply_actuator_faults`` for the faults and
``linear_correction`` for the correction, and V' is derived along it by CasADi. The faults are
the experiment's pair: a bias of 13 N on one thruster, a factor 0.8 on the other.

- healthy: ``V' <= -gamma nu^T nu`` on the box (proved);
- faulty with the correction from exact estimates: the same (proved);
- faulty without correction: ``V'_f = V' + 2 nu^T P M^-1 B (u - u_d)`` is positive near the
  equilibrium along ``B f_a`` (refuted, a negative control);
- corrected with the paper's estimates (13.0043, 0.8001): the residual bias of 0.0043 N still
  makes V' positive close to the equilibrium (refuted): the paper's ``V'_FTC = V' < 0`` needs
  exact estimates; otherwise only a neighbourhood of nu = 0 is reached.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from uvsym.faults import ActuatorFault, apply_actuator_faults
from uvsym.models.registry import vehicle
from uvsym.observers.ftc import linear_correction
from uvsym.observers.identification import ActuatorFaultEstimate
from uvsym.verify.certificate import Certificate
from uvsym.verify.region import region_decrease

__all__ = ["fault_tolerant_loop_claims", "FEEDBACK_GAIN", "VELOCITY_BOX", "CUBE"]

VEHICLE = "otter3dof"
FEEDBACK_GAIN = 50.0  # k of u_d = -k B^T nu, N s/m
VELOCITY_BOX = np.array([3.0, 1.0, 1.0])  # |u| m/s, |v| m/s, |r| rad/s
CUBE = 0.05  # half-side of the cube around nu = 0 covered by the Hessian argument
FAULTS = (ActuatorFault(0, "bias", 13.0), ActuatorFault(1, "proportional", 0.8))
PAPER_ESTIMATES = (13.0043, 0.8001)  # the paper's f_bar_a and f_bar_p (section 4)


def _loop(faulty: bool, estimates: tuple[float, ...] | None):
    """(model, nu, nu_dot, gamma) of the loop, corrected with ``estimates`` of FAULTS' values when given."""
    model = vehicle(VEHICLE)
    nu, eta = ca.SX.sym("nu", model.dof), ca.DM.zeros(model.dof)
    B = np.asarray(model.B(eta, np.zeros(model.dof), np.zeros(model.n_inputs), 0.0, 0.0))
    u_d = -FEEDBACK_GAIN * ca.mtimes(B.T, nu)
    u_cmd = u_d
    if estimates is not None:
        labels = [model.input_labels[f.actuator] for f in FAULTS]
        identified = {label: ActuatorFaultEstimate(label, f.kind, value, 0.0)
                      for label, f, value in zip(labels, FAULTS, estimates)}
        correction = linear_correction(identified, model.input_labels, B)
        u_cmd = ca.mtimes(correction.S, u_d) + correction.o
    u = apply_actuator_faults(u_cmd, ca.DM(1.0), FAULTS) if faulty else u_cmd
    nu_dot = model.nu_dot(eta, nu, u, 0.0, 0.0)
    # D = dh/dnu at rest (C(0) = 0): the healthy loop keeps V' <= -2 nu^T D nu even when saturated
    damping = np.asarray(ca.Function("dh", [nu], [ca.jacobian(model.h(eta, nu), nu)])(np.zeros(model.dof)))
    gamma = float(np.min(np.linalg.eigvalsh(0.5 * (damping + damping.T))))
    return model, nu, nu_dot, gamma


def fault_tolerant_loop_claims() -> list[Certificate]:
    """Section 3.2: healthy and corrected loops proved; uncorrected, or corrected with the paper's
    slightly-off estimates, refuted near the equilibrium."""
    exact = tuple(f.value for f in FAULTS)
    certificates = []
    for faulty, estimates, name, expected in (
            (False, None, "healthy", "proved"),
            (True, exact, "faults corrected with exact estimates", "proved"),
            (True, None, "faults, no correction", "refuted"),
            (True, PAPER_ESTIMATES, "faults corrected with the paper's estimates", "refuted")):
        model, nu, nu_dot, gamma = _loop(faulty, estimates)
        V = ca.bilin(ca.DM(model.M), nu, nu)
        labels = tuple(f"{label} ({unit})" for label, unit in zip(model.state_labels[model.dof:],
                                                                    model.state_units[model.dof:]))
        claim = (f"Section 3.2 ({VEHICLE}, {name}): V = nu'M nu, V' <= -{gamma:.4g} nu'nu "
                 f"with u_d = -{FEEDBACK_GAIN:g} B' nu")
        where = ", ".join(f"|{label}| <= {bound:g}" for label, bound in zip(labels, VELOCITY_BOX))
        certificates.append(region_decrease(claim, V, nu_dot, nu, gamma, -VELOCITY_BOX, VELOCITY_BOX, CUBE,
                                            labels=labels, set_description=where, expected=expected))
    return certificates
