"""The observer set ``actuator-observers`` (``uvsym codegen actuator-observers [--vehicle V] [--form F]``).

Liu et al. 2014's proportional, bias and constant observers on a vehicle, each as its continuous
right-hand side ``<kind>_observer(x, eta, nu, tau_d, K) -> (x_dot, f_hat)`` and as a discrete step
``<kind>_step(x, eta, nu, tau_d, K, dt) -> (x_next, f_hat)`` (one RK4 step of dt seconds with eta,
nu and tau_d held), plus ``actuator_observers_step``, all three at once.

The package's example (``main.c``, and the float check of ``--float``) is the combined step on
``EXAMPLE_STEPS`` samples of the vehicle's shipped scenario (the docking experiment for the
docking AUV) from ``EXAMPLE_START``: measured pose and velocity, desired forces, the observers'
states and the gains of the scenario's time constants. A vehicle without a shipped scenario
gets no example.
"""

from __future__ import annotations

import functools
from dataclasses import replace

import casadi as ca
import numpy as np

from derivations.actuator_observers.paper import DOCKING
from derivations.papers import paper
from uvsym.codegen.arguments import Entries, per_second
from uvsym.codegen.example import Example
from uvsym.codegen.observer_sets import ObserverSet
from uvsym.codegen.package import Exported
from uvsym.conventions import FORCE_LABELS
from uvsym.faults import actuator_kind
from uvsym.models.registry import vehicle as library_vehicle
from uvsym.observers.actuator import KINDS, actuator_observer
from uvsym.observers.discrete import gain_units
from uvsym.sim.scenario import ObserverSpec, load_scenario, read_scenario_file, shipped_scenarios
from uvsym.sim.simulation import scenario_observers, simulate_scenario
from uvsym.symbolic import rk4

__all__ = ["EXAMPLE_START", "EXAMPLE_STEPS", "actuator_observers"]

EXAMPLE_START = 10.0  # s into the scenario: the observers have converged on the faults present from t = 0
EXAMPLE_STEPS = 500  # samples of the example (5 s of the docking experiment)
PAPER = paper("liu2014")


def _step(function: ca.Function, name: str) -> ca.Function:
    """One RK4 step of dt (run-time argument, s) of an observer with its other inputs held."""
    n = function.size1_in("x")
    x, eta, nu, tau_d, K, dt = (ca.SX.sym(v, size) for v, size in
                                (("x", n), ("eta", n), ("nu", n), ("tau_d", n), ("K", n), ("dt", 1)))
    x_next = rk4(lambda s, _t: function(s, eta, nu, tau_d, K)[0], x, dt, 1)
    f_hat = function(x, eta, nu, tau_d, K)[1]
    return ca.Function(name, [x, eta, nu, tau_d, K, dt], [x_next, f_hat],
                       ["x", "eta", "nu", "tau_d", "K", "dt"], ["x_next", "f_hat"], {"cse": True})


def _scenario_name(vehicle: str) -> str | None:
    """The shipped scenario that runs ``vehicle`` with observers: the docking experiment first."""
    shipped = shipped_scenarios()
    ordered = [DOCKING, *sorted(set(shipped) - {DOCKING})]
    for name in ordered:
        data = read_scenario_file(shipped[name])
        if data.get("vehicle") == vehicle and data.get("observers"):
            return name
    return None


@functools.lru_cache(maxsize=8)
def _example(vehicle: str, form: str) -> Example | None:
    """The combined step on the vehicle's shipped scenario (module docstring), or None without one."""
    name = _scenario_name(vehicle)
    if name is None:
        return None
    scenario = load_scenario(name)
    given = {spec.kind: spec for spec in scenario.observers}
    first, proportional = scenario.observers[0], given.get("proportional")
    specs = tuple(replace(given[kind], form=form) if kind in given else
                  ObserverSpec(kind, form, first.time_constant, proportional.tau_d if proportional else None)
                  for kind in KINDS)
    start = int(round(EXAMPLE_START / scenario.step))
    duration = (start + EXAMPLE_STEPS) * scenario.step
    run = simulate_scenario(replace(scenario, observers=specs, duration=duration), compiled=False)
    rows = slice(start, start + EXAMPLE_STEPS)
    n = scenario.model.dof
    eta, nu = run["y"].values[rows, :n], run["y"].values[rows, n:]
    tau_d = run["tau_desired"].values[rows]
    states, gains = [], []
    for kind, (observer, K) in scenario_observers(scenario.model, specs).items():
        f_hat = run[f"f_hat/{kind}"].values[rows]
        R = observer.R.map(EXAMPLE_STEPS)(nu.T, tau_d.T, K)  # x = f_hat + R(nu, tau_d, K)
        states.append(f_hat + np.asarray(R).T)
        gains.append(np.tile(K, (EXAMPLE_STEPS, 1)))
    dt = np.full((EXAMPLE_STEPS, 1), scenario.step)
    source = (f"the shipped scenario {name} ({scenario.model.name}), {EXAMPLE_STEPS} samples from "
              f"t = {EXAMPLE_START:g} s, gains of its time constants")
    return Example("actuator_observers_step", (np.hstack(states), eta, nu, tau_d, np.hstack(gains), dt), source)


def actuator_observers(vehicle: str = "remus100", form: str = "momentum") -> ObserverSet:
    """The three actuator observers of a vehicle of the library, in the observer form given."""
    model = library_vehicle(vehicle)
    n = model.dof
    forces = FORCE_LABELS[n]
    pose = Entries("eta, measured pose", model.state_labels[:n], model.state_units[:n])
    velocity = Entries("nu, measured velocity", model.state_labels[n:], model.state_units[n:])
    desired = Entries("tau_d, desired generalised force", forces, model.force_units)
    exported, steps = [], []
    for kind in KINDS:
        observer = actuator_observer(model, kind, form).function
        f_units = tuple(map(actuator_kind(kind).unit, model.force_units))
        state = Entries(f"observer state x = f_hat + R(nu) of the {kind} observer", forces, f_units)
        estimate = Entries(f"f_hat, {kind} fault estimate", forces, f_units)
        gain = Entries(f"K, gains of the {kind} observer", forces, gain_units(kind, form, model.force_units))
        inputs = (state, pose, velocity, desired, gain)
        rate = Entries("x_dot, rate of the observer state", forces, tuple(per_second(u) for u in state.units))
        exported.append(Exported(observer, inputs, (rate, estimate),
                                 f"{kind} observer of {model.name} ({form} form): continuous right-hand side"))
        step = _step(observer, f"{kind}_step")
        steps.append(step)
        following = Entries("x_next, observer state after dt", forces, state.units)
        decay = ("K tau_d^2" if kind == "proportional" else "K") + ("" if form == "momentum" else " / m^2")
        exported.append(Exported(step, (*inputs, Entries("dt, step", ("dt",), ("s",))), (following, estimate),
                                 f"{kind} observer of {model.name} ({form} form): one RK4 step of dt, explicit: "
                                 f"stable while dt times the decay rate {decay} of every channel stays below 2.78"))
    x, eta, nu, tau_d, K, dt = (ca.SX.sym(v, size) for v, size in
                                (("x", 3 * n), ("eta", n), ("nu", n), ("tau_d", n), ("K", 3 * n), ("dt", 1)))
    parts = [step(x[i * n:(i + 1) * n], eta, nu, tau_d, K[i * n:(i + 1) * n], dt) for i, step in enumerate(steps)]
    combined = ca.Function("actuator_observers_step", [x, eta, nu, tau_d, K, dt],
                           [ca.vertcat(*[p[0] for p in parts]), ca.vertcat(*[p[1] for p in parts])],
                           ["x", "eta", "nu", "tau_d", "K", "dt"], ["x_next", "f_hat"], {"cse": True})
    order = ", ".join(KINDS)

    def stacked(what: str, position: int, output: int | None = None) -> Entries:
        """The three observers' arguments at ``position`` (an input, or an output), stacked in KINDS order."""
        docs = [e.output_units[output] if output is not None else e.input_units[position] for e in exported[1::2]]
        return Entries(f"{what} of the {order} observers, stacked",
                       tuple(f"{kind}.{entry}" for kind, d in zip(KINDS, docs) for entry in d.names),
                       tuple(unit for d in docs for unit in d.units))

    exported.append(Exported(combined, (stacked("observer states", 0), pose, velocity, desired, stacked("gains K", 4),
                                        Entries("dt, step", ("dt",), ("s",))),
                             (stacked("x_next", 0, 0), stacked("f_hat", 0, 1)),
                             f"the {order} observers of {model.name} ({form} form): one RK4 step each "
                             f"(explicit: stable while dt times each observer's decay rate stays below 2.78)"))
    description = f"actuator-fault observers of {PAPER.short} for {model.name}, {form} form"
    return ObserverSet(f"uvsym_{vehicle}_observers", description, tuple(exported), citation=PAPER.reference(),
                       example=_example(vehicle, form))
