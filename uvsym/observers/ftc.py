"""Fault-tolerant correction of the commands, not the controller (Liu et al. 2014, sec. 3).

For identified faults the corrected command undoes each fault's kind (its
:meth:`~uvsym.faults.ActuatorKind.correction`): ``u*_i = u_d,i / f_p,i`` (proportional),
``u*_i = u_d,i - f_a,i`` (bias), and an actuator whose delivered value ignores its command
(constant, stuck) is stopped and its share of ``tau_d`` handed to the others. Commands are
then kept within ``[u_min, u_max]``: what one actuator cannot deliver goes to the redundant
ones by bounded least squares (``scipy.optimize.lsq_linear``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from uvsym.errors import IdentifiabilityError
from uvsym.faults import actuator_kind
from uvsym.observers.identification import ActuatorFaultEstimate

__all__ = ["Correction", "linear_correction", "corrected_commands"]


@dataclass(frozen=True)
class Correction:
    """Command correction ``u_cmd = sat(S u_d + o)``: S (m, m), o (m,) in the inputs' units."""

    S: np.ndarray
    o: np.ndarray


def linear_correction(faults: dict[str, ActuatorFaultEstimate], labels: tuple[str, ...], B: np.ndarray) -> Correction:
    """The correction as a linear map ``u* = S u_d + o`` (before bounds).

    A stopped actuator i (one that delivers a constant ``c_i`` whatever its command, B (n, m) the
    linearised ``d tau / d u``) hands the rest of its share of tau, ``B_i (u_d,i - c_i)``, to the
    others through the pseudo-inverse of their B: what it still delivers is not asked of them again.
    """
    m = len(labels)
    S, o = np.eye(m), np.zeros(m)
    B = np.asarray(B, dtype=float)
    stopped = {}  # actuator -> the constant it delivers
    for label, fault in faults.items():
        i = labels.index(label)
        kind = actuator_kind(fault.kind)
        try:
            correction = kind.correction(fault.value)
        except IdentifiabilityError as exc:
            raise IdentifiabilityError(f"{label}: {exc}") from None
        if correction is None:
            stopped[i] = kind.affine(fault.value)[1]
        else:
            S[i, i] = correction[0]
            o[i] += correction[1]
    for i, delivered in stopped.items():
        others = [j for j in range(m) if j not in stopped]
        if not others:
            raise IdentifiabilityError("every actuator is stopped: nothing can take over")
        S[i, :] = 0.0
        takeover = np.linalg.pinv(B[:, others]) @ B[:, i]
        S[others, i] += takeover
        o[others] -= takeover * delivered
    return Correction(S, o)


def corrected_commands(u_d, faults: dict[str, ActuatorFaultEstimate], labels: tuple[str, ...], B: np.ndarray,
                       u_min, u_max) -> np.ndarray:
    """Corrected commands u* (m,) within bounds: the linear correction, then bounded least squares.

    The actuators that still act minimise ``|B_eff (u* - u_lin)|`` subject to bounds, where B_eff
    weights each actuator by its effectiveness (the gain its fault leaves: ``f_p`` for proportional
    faults) -- so the excess of a saturated actuator goes to the ones that can still act on the same
    forces; a stopped actuator is commanded exactly 0. A fault's shift (a bias) also narrows the
    command's bounds so that the command plus the shift stays within them.
    """
    from scipy.optimize import lsq_linear  # here: scipy.optimize costs every uvsym command about 0.1 s

    u_d = np.asarray(u_d, dtype=float)
    linear = linear_correction(faults, labels, B)
    u_lin = linear.S @ u_d + linear.o
    effectiveness, acting = np.ones(len(labels)), np.ones(len(labels), dtype=bool)  # acting: not stopped
    lower, upper = np.asarray(u_min, dtype=float).copy(), np.asarray(u_max, dtype=float).copy()
    for label, fault in faults.items():
        i, kind = labels.index(label), actuator_kind(fault.kind)
        if kind.ignores_command:
            acting[i] = False
        else:
            effectiveness[i], shift = kind.affine(fault.value)
            lower[i], upper[i] = max(lower[i] - shift, u_min[i]), min(upper[i] - shift, u_max[i])
    u_acting, lower, upper = u_lin[acting], lower[acting], upper[acting]
    if np.all((u_acting >= lower) & (u_acting <= upper)):
        return u_lin  # a stopped actuator's row of S is zero: commanded 0
    B_eff = np.asarray(B, dtype=float)[:, acting] * effectiveness[acting]
    u_star = np.zeros(len(labels))  # a stopped actuator is commanded nothing, not a rounding error of the solver
    u_star[acting] = lsq_linear(B_eff, B_eff @ u_acting, bounds=(lower, upper), method="bvls").x
    return u_star
