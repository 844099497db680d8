"""Analytic fault estimates from the linearised error models (the values the simulations are set beside).

For ``e' = A e + B f_s'``, ``f_s - f_hat = G e`` with ``e = 0`` before the onset: a unit step gives
``e(tau) = expm(A tau) B``; ``f_s = 1 - exp(-a tau)`` gives
``e(tau) = a (A + a I)^-1 (expm(A tau) - exp(-a tau) I) B`` (tau = t - onset). With an initial error
e0 and no fault, ``e(t) = expm(A t) e0``. The hybrid estimator's error matrix has a zero eigenvalue
(a speed error traded for a fault error that no residual sees), so its estimate settles where the
zero mode's projection puts it: for a step, ``f_hat -> 1 - L2 / (L2 + 2 Gamma M1)`` (F2 = 2, e1 = 0).
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import expm

from derivations.motor_hybrid_observer.design import ESTIMATOR, L2, design
from derivations.motor_luenberger.experiment import FAULT_ONSET, INCIPIENT_RATE, INITIAL_OFFSET
from uvsym.observers.hybrid import LinearErrorModel, linear_error_model

__all__ = ["corrected_model", "estimate", "estimator_model", "step_limit"]


def estimator_model() -> LinearErrorModel:
    """The paper's estimator (subsystem-1 UIO and adaptive subsystem 2) with the study's gains."""
    d = design()
    return linear_error_model(d.split, d.K1, [[L2]], ESTIMATOR)


def corrected_model() -> LinearErrorModel:
    """The corrected design: ``e = (x - xhat, f_s - f_hat)``, ``A = A_aug - K C_aug``."""
    d = design()
    lin = d.corrected_plant.linearize()
    n = lin.A.shape[0]
    return LinearErrorModel(lin.A - d.corrected.K[0] @ lin.C, np.eye(n)[:, -1:], np.eye(n)[-1:])


def estimate(model: LinearErrorModel, case: str, times) -> np.ndarray:
    """f_hat at ``times`` (s) for ``case`` "step", "incipient" (unit fault from FAULT_ONSET, 0 before)
    or "initial error" (no fault; the motor's initial offset, the observer at the operating point)."""
    out = []
    for t in np.atleast_1d(np.asarray(times, dtype=float)):
        tau = t - FAULT_ONSET
        if case == "initial error":
            e0 = np.concatenate([INITIAL_OFFSET, np.zeros(model.A.shape[0] - INITIAL_OFFSET.size)])
            out.append(-float((model.G @ expm(model.A * t) @ e0)[0]))
            continue
        if tau < 0:  # before the onset: no fault, no error
            out.append(0.0)
            continue
        if case == "step":
            fault, e = 1.0, expm(model.A * tau) @ model.B
        else:
            a = INCIPIENT_RATE
            fault = 1.0 - np.exp(-a * tau)
            e = a * np.linalg.solve(model.A + a * np.eye(model.A.shape[0]),
                                    (expm(model.A * tau) - np.exp(-a * tau) * np.eye(model.A.shape[0])) @ model.B)
        out.append(fault - float((model.G @ e)[0, 0]))
    return np.asarray(out)


def step_limit() -> float:
    """The hand-derived limit of the estimator's step estimate, ``1 - L2 / (L2 + 2 Gamma M1)``."""
    k = float(ESTIMATOR.Gamma[0, 0] * ESTIMATOR.M1[0, 0])
    return 1.0 - L2 / (L2 + 2.0 * k)
