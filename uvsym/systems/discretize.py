"""Sampling a continuous System: exact zero-order hold (affine systems) or a symbolic RK4 step.

``zoh``: for ``x' = A x + B u + E d + c(p)`` with u, d, p held over a sample, the exact solution
is ``x_{k+1} = Ad x_k + Bd u_k + Ed d_k + Gd c(p)`` with ``[[Ad, Gd], [0, I]] = expm(dt [[A, I], [0, 0]])``
and ``Bd = Gd B``, ``Ed = Gd E`` (Franklin, Powell & Workman, *Digital Control*, sec. 4.3). It
needs A, B, E constant (f affine in x, u, d; they may not depend on p).
``rk4``: ``steps`` classical Runge-Kutta steps over ``dt`` of any f (approximate, O(dt^4)).
The output map h is unchanged.
"""

from __future__ import annotations

from dataclasses import replace

import casadi as ca
import numpy as np

from uvsym.errors import ModelError
from uvsym.numbers import real
from uvsym.symbolic import rk4
from uvsym.systems.system import ARGUMENTS, System

__all__ = ["METHODS", "discretize", "zoh_matrices"]

METHODS = ("zoh", "rk4")


def zoh_matrices(A, B, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """(Ad, Bd) of the exact zero-order hold of ``x' = A x + B u`` over ``dt`` s (ModelError for dt <= 0)."""
    dt = real(dt, "zero-order hold: dt (s)", ModelError, positive=True)
    A, B = np.atleast_2d(np.asarray(A, dtype=float)), np.asarray(B, dtype=float).reshape(len(A), -1)
    n, m = A.shape[0], B.shape[1]
    augmented = np.zeros((n + m, n + m))
    augmented[:n, :n], augmented[:n, n:] = A, B
    from scipy.linalg import expm  # here: scipy.linalg costs every uvsym command about 0.13 s

    phi = expm(dt * augmented)
    return phi[:n, :n], phi[:n, n:]


def discretize(system: System, dt: float, method: str = "zoh", steps: int = 1) -> System:
    """The discrete-time System ``x_{k+1} = f_d(x_k, u_k, d_k, p)`` sampled every ``dt`` s.

    Raises
    ------
    ModelError
        For an unknown method, a non-positive dt or steps, a system already discrete, or ``zoh``
        on a system that is not affine in (x, u, d) with constant matrices (use ``rk4``).
    """
    if method not in METHODS:
        raise ModelError(f"unknown discretisation method {method!r}; known: {', '.join(METHODS)}")
    if system.discrete:
        raise ModelError(f"{system.name} is already discrete (dt = {system.dt} s)")
    dt = real(dt, f"{system.name}: sample period dt (s)", ModelError, positive=True)
    if not (isinstance(steps, int) and steps >= 1):
        raise ModelError(f"{system.name}: steps must be a positive integer, got {steps!r}")
    x, u, d, p = (ca.SX.sym(a, s.size) for a, s in zip(ARGUMENTS, (system.x, system.u, system.d, system.p)))
    if method == "rk4":
        x_next = rk4(lambda s, _t: system.f(s, u, d, p), x, dt, steps)
    else:
        x_next = _zoh_expression(system, dt, x, u, d, p)
    f_d = ca.Function("f_d", [x, u, d, p], [x_next], list(ARGUMENTS), ["x_next"])
    return replace(system, name=f"{system.name}_d", f=f_d, dt=float(dt),
                   description=f"{system.description} (sampled every {dt:g} s, {method})")


def _zoh_expression(system: System, dt: float, x, u, d, p):
    """Ad x + Bd u + Ed d + Gd c(p) of the module docstring; ModelError unless f is affine."""
    fx = system.f(x, u, d, p)
    variables = ca.vertcat(x, u, d)
    jacobian = ca.jacobian(fx, variables)
    if ca.depends_on(jacobian, ca.vertcat(variables, p)):
        raise ModelError(f"{system.name}: zoh needs x' affine in (x, u, d) with matrices independent of p; "
                         "use method='rk4' for a nonlinear system")
    J = np.asarray(ca.evalf(ca.densify(jacobian)), dtype=float)
    n, m = system.x.size, system.u.size
    A = J[:, :n]
    c = ca.substitute(fx, variables, ca.DM.zeros(variables.numel()))
    Ad, Gd = zoh_matrices(A, np.eye(n), dt)
    return ca.mtimes(ca.DM(Ad), x) + ca.mtimes(ca.DM(Gd @ J[:, n:n + m]), u) + \
        ca.mtimes(ca.DM(Gd @ J[:, n + m:]), d) + ca.mtimes(ca.DM(Gd), c)
