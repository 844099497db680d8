"""Small systems with known answers, shared by the tests."""

import casadi as ca

from uvsym.systems import signals, system

DT = 0.01


def double_integrator(outputs=("pos", "vel")):
    """pos' = vel, vel' = acc; y the named states."""
    x = signals(("pos", "m"), ("vel", "m/s"), group="state")
    picked = x.indices(outputs)
    return system("double_integrator", "pos'' = acc", x=x, u=signals(("acc", "m/s^2"), group="input"),
                  rhs=lambda x, u, d, p: ca.vertcat(x[1], u[0]), y=x.select(outputs).renamed(group="output"),
                  output=lambda x, u, p: ca.vertcat(*[x[i] for i in picked]))


def first_order(a=0.5, b=2.0, gain=1.0):
    """v' = -a v + b F (+ tau_d), y = m = gain v."""
    return system("first_order", "v' = -a v + b F", x=signals(("v", "m/s"), group="state"),
                  u=signals(("F", "N"), group="input"), d=signals(("tau_d", "N"), group="disturbance"),
                  rhs=lambda x, u, d, p: -a * x + b * (u + d), y=signals(("m", "m/s"), group="output"),
                  output=lambda x, u, p: gain * x)


def integrator():
    """q' = u, y = q."""
    return system("integrator", "q' = u", x=signals(("q", "m"), group="state"),
                  u=signals(("u", "m/s"), group="input"), rhs=lambda x, u, d, p: u)
