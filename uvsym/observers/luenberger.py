"""Luenberger observer of any System, with a constant output-injection gain (Luenberger 1964).

Continuous design model (d = 0 assumed)::

    xhat' = f(xhat, u, 0, p) + L (y - h(xhat, u, p))

whose error ``e = x - xhat`` obeys, exactly,

    e' = f(x, u, d, p) - f(x - e, u, 0, p) - L (h(x, u, p) - h(x - e, u, p))

(``error_dynamics``); at ``e = 0``, ``d = 0`` its Jacobian is ``A(x, u) - L C(x, u)``, the matrix
the gain is designed for (e.g. by :func:`uvsym.verify.synthesize_observer_gain`). It runs as the
discrete predictor

    xhat_{k+1} = F(xhat_k, u_k) + dt L (y_k - h(xhat_k, u_k, p))

with F ``steps`` RK4 steps of the model over the sample period dt. For a linear plant the
sampled error obeys ``e_{k+1} = (A_d - dt L C) e_k = (I + dt (A - L C) + O(dt^2)) e_k`` exactly:
no lag from holding y over the sample, and the continuous design's rate to first order in dt.
The observer publishes the estimate ``<x>_hat`` of every state and the residual
``r_<y> = y - h(xhat)`` of every output, both at the sample (before the update).
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from uvsym.errors import ObserverError
from uvsym.observers.base import Observer, check_name, observer
from uvsym.symbolic import rk4
from uvsym.systems.system import System

__all__ = ["luenberger_observer"]


def luenberger_observer(plant: System, L, dt: float, *, name: str = "luenberger", steps: int = 1) -> Observer:
    """The Luenberger observer (module docstring) of a continuous ``plant`` with gain L (n_x, n_y).

    Reads the plant's outputs (by their names) and inputs; its parameters are the plant's p
    (default ``plant.p0``). Starts from ``xhat = x_op`` unless given a state.

    Raises
    ------
    ObserverError
        For a discrete plant, a gain of the wrong shape or with non-finite entries, or steps < 1.
    """
    check_name(name, "observer")
    if plant.discrete:
        raise ObserverError(f"{name}: the Luenberger observer here is built on a continuous plant; "
                            f"{plant.name} is discrete (dt = {plant.dt} s)")
    L = np.atleast_2d(np.asarray(L, dtype=float))
    if L.shape != (plant.x.size, plant.y.size) or not np.all(np.isfinite(L)):
        raise ObserverError(f"{name}: gain L must be a finite ({plant.x.size}, {plant.y.size}) matrix "
                            f"(states x outputs), got shape {L.shape}")
    if not (isinstance(steps, int) and steps >= 1):
        raise ObserverError(f"{name}: steps must be a positive integer, got {steps!r}")
    no_disturbance = ca.DM.zeros(plant.d.size)

    def xhat_dot(xhat, y, u, p):
        return plant.f(xhat, u, no_disturbance, p) + ca.mtimes(ca.DM(L), y - plant.h(xhat, u, p))

    def step(s, y, u, p):
        residual = y - plant.h(s, u, p)
        prediction = rk4(lambda xh, _t: plant.f(xh, u, no_disturbance, p), s, dt, steps)
        return prediction + dt * ca.mtimes(ca.DM(L), residual), ca.vertcat(s, residual)

    xh, y, u, p = (ca.SX.sym(a, g.size) for a, g in (("xhat", plant.x), ("y", plant.y), ("u", plant.u),
                                                      ("p", plant.p)))
    continuous = ca.Function(f"{name}_continuous", [xh, y, u, p], [xhat_dot(xh, y, u, p)],
                             ["xhat", "y", "u", "p"], ["xhat_dot"])
    e, x, d = ca.SX.sym("e", plant.x.size), ca.SX.sym("x", plant.x.size), ca.SX.sym("d", plant.d.size)
    e_dot = (plant.f(x, u, d, p) - plant.f(x - e, u, no_disturbance, p)
             - ca.mtimes(ca.DM(L), plant.h(x, u, p) - plant.h(x - e, u, p)))
    error_dynamics = ca.Function(f"{name}_error", [e, x, u, d, p], [e_dot], ["e", "x", "u", "d", "p"], ["e_dot"])
    x_op = plant.x_op
    return observer(
        name, step=step, dt=dt, p0=plant.p0, params=plant.p.renamed(group="parameter"),
        state=plant.x.renamed(suffix="_hat", group="state"),
        reads_y=plant.y.renamed(group="measurement"), reads_u=plant.u.renamed(group="input"),
        publishes=plant.x.renamed(suffix="_hat", group="estimate") + plant.y.renamed(prefix="r_", group="residual"),
        init=lambda y0, u0, p: x_op, error_dynamics=error_dynamics, equations={"continuous": continuous},
        description=f"Luenberger observer of {plant.name}: xhat' = f(xhat, u) + L (y - h(xhat, u)), "
                    f"sampled every {dt:g} s ({steps} RK4 step(s) of the model)")

