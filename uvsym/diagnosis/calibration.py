"""Residual noise of a wired loop, from its stated noise model: the thresholds' calibration.

The loop :func:`uvsym.sim.wiring.interconnect` builds is linearised at a point ``(z0, w0)``::

    z_{k+1} = A z_k + B n_k,     r_k = C z_k + D n_k,     n_k ~ N(0, I)

with n the standard normal draws of the sensor noise (each output's noise fault scales its draw;
``A = dz_next/dz``, ``B = dz_next/dn``, ``C``, ``D`` the same for the logged signals r, all by
``casadi.jacobian``). The stationary covariance ``S = sum_k A^k B B' A'^k`` is summed by doubling
(``S <- S + A_j S A_j'``, ``A_j <- A_j^2``), and the residuals' covariance is ``C S C' + D D'``.
Modes the noise does not reach (a latch, an integrator of a signal no noise feeds) do not enter
the sum, so they need not be stable; the sum is refused when it does not settle.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from uvsym.codegen.cache import memoized
from uvsym.errors import DiagnosisError

__all__ = ["residual_covariance", "signal_rows"]

_DOUBLINGS = 64  # 2^64 samples: any stable mode has settled long before


def signal_rows(loop, names: tuple[str, ...]) -> list[int]:
    """Rows of the loop's logged output ``out`` holding the signals ``names`` (``<group>.<label>``:
    a block's name or x, y, u, then one of its labels). DiagnosisError naming an unknown one."""
    rows = []
    for name in names:
        group, _, label = name.partition(".")
        entry = loop.signals.get(group)
        if entry is None or label not in entry[1]:
            known = [f"{g}.{lab}" for g, (_, labels, _) in loop.signals.items() if g not in ("x", "u")
                     for lab in labels]
            raise DiagnosisError(f"signal {name!r} is not logged by the loop; logged: {', '.join(known)}")
        rows.append(entry[0].start + list(entry[1]).index(label))
    return rows


def residual_covariance(loop, z0: np.ndarray, w0: np.ndarray, names: tuple[str, ...]) -> np.ndarray:
    """(m, m) stationary covariance of the logged signals ``names`` (module docstring) under the
    loop's sensor noise, linearised at ``(z0 (n_z,), w0 (n_w,))`` with the noise draws at 0.

    Raises DiagnosisError naming the signal for an unknown name, and when the sum does not settle
    (the loop linearised there is unstable in a mode the noise excites).
    """
    n_y = loop.plant.y.size
    point = np.array(w0, dtype=float)
    point[1:1 + n_y] = 0.0
    return _stationary(loop.step, tuple(signal_rows(loop, names)), n_y, np.asarray(z0, dtype=float), point,
                       tuple(names)).copy()


@memoized(64)
def _stationary(step: ca.Function, rows: tuple[int, ...], n_y: int, z0: np.ndarray, point: np.ndarray,
                names: tuple[str, ...]) -> np.ndarray:
    """residual_covariance's sum (module docstring) at (z0, point); the runs of a campaign that share a loop
    and its calibration point share it."""
    A, B, C, D = (np.asarray(M, dtype=float) for M in _linearised(step, rows, n_y)(z0, point))
    S, A_j = B @ B.T, A
    previous = C @ S @ C.T + D @ D.T
    for _ in range(_DOUBLINGS):
        with np.errstate(over="ignore", invalid="ignore"):  # a diverging sum is refused below
            S = S + A_j @ S @ A_j.T
            A_j = A_j @ A_j
            current = C @ S @ C.T + D @ D.T
        if not np.all(np.isfinite(current)):
            break
        if np.allclose(current, previous, rtol=1e-12, atol=0.0):
            return current
        previous = current
    raise DiagnosisError(f"the noise variance of {', '.join(names)} does not settle: the loop linearised at "
                         "the calibration point is unstable in a mode the sensor noise excites (stabilise the loop, "
                         "or state the residuals' standard deviations in the detector's std field)")


@memoized(16)
def _linearised(step: ca.Function, rows: tuple[int, ...], n_y: int) -> ca.Function:
    """(z, w) -> (A, B, C, D) of the module docstring for the loop ``step`` (z, w) -> (z_next, out), the
    residuals its ``out`` rows, the noise draws w[1:1 + n_y]; built once per loop (the runs of a campaign
    share theirs)."""
    z, w = ca.SX.sym("z", step.nnz_in(0)), ca.SX.sym("w", step.nnz_in(1))
    z_next, out = step(z, w)
    r = ca.vertcat(*[out[i] for i in rows])
    noise = w[1:1 + n_y]
    return ca.Function("linearised", [z, w], [ca.jacobian(z_next, z), ca.jacobian(z_next, noise),
                                              ca.jacobian(r, z), ca.jacobian(r, noise)])
