"""The observer set ``actuator-observers`` (``uvsym codegen actuator-observers [--vehicle V] [--form F]``).

The core paper's proportional, bias and constant observers on a vehicle, each as its continuous
right-hand side ``<kind>_observer(x, eta, nu, tau_d, K) -> (x_dot, f_hat)`` and as a discrete step
``<kind>_step(x, eta, nu, tau_d, K, dt) -> (x_next, f_hat)`` (one RK4 step of dt seconds with eta,
nu and tau_d held), plus ``actuator_observers_step``, all three at once.
"""

from __future__ import annotations

import casadi as ca

from uvsym.codegen.observer_sets import ObserverSet
from uvsym.codegen.package import Exported
from uvsym.models.registry import vehicle as library_vehicle
from uvsym.observers.actuator import KINDS, actuator_observer
from uvsym.symbolic import rk4

__all__ = ["actuator_observers"]


def _units(model, kind: str, form: str) -> tuple[str, str]:
    """(unit of x and f_hat, unit of K) for an observer kind and form."""
    force = ", ".join(model.force_units)
    if kind == "proportional":
        return "-", ("1/s per (desired force)^2, per channel" if form == "momentum" else "kg^2/(s (N or N m)^2)")
    return force, ("1/s" if form == "momentum" else "kg^2/s, per channel (rate k/m^2)")


def _step(function: ca.Function, name: str) -> ca.Function:
    """One RK4 step of dt (run-time argument, s) of an observer with its other inputs held."""
    n = function.size1_in("x")
    x, eta, nu, tau_d, K, dt = (ca.SX.sym(v, size) for v, size in
                                (("x", n), ("eta", n), ("nu", n), ("tau_d", n), ("K", n), ("dt", 1)))
    x_next = rk4(lambda s, _t: function(s, eta, nu, tau_d, K)[0], x, dt, 1)
    f_hat = function(x, eta, nu, tau_d, K)[1]
    return ca.Function(name, [x, eta, nu, tau_d, K, dt], [x_next, f_hat],
                       ["x", "eta", "nu", "tau_d", "K", "dt"], ["x_next", "f_hat"], {"cse": True})


def actuator_observers(vehicle: str = "remus100", form: str = "momentum") -> ObserverSet:
    """The three actuator observers of a vehicle of the library, in the observer form given."""
    model = library_vehicle(vehicle)
    pose = ", ".join(model.state_units[:model.dof])
    velocity = ", ".join(model.state_units[model.dof:])
    force = ", ".join(model.force_units)
    exported, steps = [], []
    for kind in KINDS:
        observer = actuator_observer(model, kind, form).function
        f_unit, k_unit = _units(model, kind, form)
        inputs = (f"observer state ({f_unit})", f"eta ({pose})", f"nu ({velocity})", f"tau_d ({force})",
                  f"K ({k_unit})")
        exported.append(Exported(observer, inputs, (f"x_dot ({f_unit}/s)", f"f_hat ({f_unit})"),
                                 f"{kind} observer of {model.name} ({form} form): continuous right-hand side"))
        step = _step(observer, f"{kind}_step")
        steps.append(step)
        exported.append(Exported(step, (*inputs, "dt (s)"), (f"x_next ({f_unit})", f"f_hat ({f_unit})"),
                                 f"{kind} observer of {model.name} ({form} form): one RK4 step of dt"))
    n = model.dof
    x, eta, nu, tau_d, K, dt = (ca.SX.sym(v, size) for v, size in
                                (("x", 3 * n), ("eta", n), ("nu", n), ("tau_d", n), ("K", 3 * n), ("dt", 1)))
    parts = [step(x[i * n:(i + 1) * n], eta, nu, tau_d, K[i * n:(i + 1) * n], dt) for i, step in enumerate(steps)]
    combined = ca.Function("actuator_observers_step", [x, eta, nu, tau_d, K, dt],
                           [ca.vertcat(*[p[0] for p in parts]), ca.vertcat(*[p[1] for p in parts])],
                           ["x", "eta", "nu", "tau_d", "K", "dt"], ["x_next", "f_hat"], {"cse": True})
    order = ", ".join(KINDS)
    exported.append(Exported(combined, (f"states of the {order} observers, stacked", f"eta ({pose})",
                                        f"nu ({velocity})", f"tau_d ({force})", f"K of the {order} observers, stacked",
                                        "dt (s)"),
                             (f"x_next, stacked ({order})", f"f_hat, stacked ({order})"),
                             f"the {order} observers of {model.name} ({form} form): one RK4 step each"))
    description = f"actuator-fault observers of the core paper (seeds/000) for {model.name}, {form} form"
    return ObserverSet(f"uvsym_{vehicle}_observers", description, tuple(exported))
