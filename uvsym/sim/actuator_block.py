"""The actuator-fault observers of Liu et al. 2014 as a block of a loop wired by signal name.

``type = "actuator_observer"`` on a marine vehicle plant (``plant = "<vehicle>"``): the observer
of ``kind`` (proportional, bias, constant) in ``form`` (paper, momentum) with gains designed for
``time_constant`` (s) at the nominal ``tau_d`` (N, N m; needed by the kinds that scale the
command), as ``[[observers]]`` of a vehicle scenario. It reads the vehicle's measured states and
the commands its controller sends (``commands``: the signals that drive the plant's inputs, by
default the inputs' own names, i.e. whichever block publishes them) and forms the desired force
``tau_d = tau(eta, nu, u_cmd)`` (no current) itself; it publishes ``tau_d.<force>`` (N, N m) and
its fault estimate ``f_hat.<force>`` (factors for proportional, N and N m otherwise).

In this format the plant's inputs are what the actuators deliver at once: a vehicle's own
actuator lag and the commands' correction by a supervisor belong to the vehicle format
(:mod:`uvsym.sim.closed_loop`), whose observers read ``tau(y, a_expected)`` instead.
"""

from __future__ import annotations

from dataclasses import dataclass
from dataclasses import fields as fields_of

import casadi as ca

from uvsym.conventions import FORCE_LABELS
from uvsym.errors import ObserverError, ScenarioError
from uvsym.models.model import Model
from uvsym.observers import FORMS, KINDS, ActuatorObserver, actuator_observer
from uvsym.observers.discrete import actuator_fault_observer
from uvsym.observers.gains import design_gains
from uvsym.sim.blocks import Block, block
from uvsym.sim.fields import Fields
from uvsym.systems.signals import Signals
from uvsym.systems.system import System

__all__ = ["ActuatorObserverBlock", "actuator_observer_block", "vehicle_of"]


@dataclass(frozen=True)
class ActuatorObserverBlock(Block):
    """The block of one actuator-fault observer; design: the continuous observer it samples
    (kind, form, R, L, error matrix), K: (dof,) its gains, model: the vehicle (for what decides on
    its estimate, :mod:`uvsym.diagnosis.wired`)."""

    design: ActuatorObserver | None = None
    K: tuple[float, ...] = ()
    model: Model | None = None


def vehicle_of(plant: System, where: str) -> Model:
    """The vehicle Model a plant was made from (``Model.as_system``); ScenarioError naming ``where`` else."""
    from uvsym.models.registry import vehicle_names

    model = plant.extras.get("vehicle")
    if not isinstance(model, Model):
        raise ScenarioError(f"{where}: needs a marine vehicle plant ({', '.join(vehicle_names())}), "
                            f"got plant {plant.name!r}")
    return model


def actuator_observer_block(fields: Fields, plant: System, dt: float, name: str) -> Block:
    """The block of a ``[[blocks]]`` table of type actuator_observer (module docstring), sampled every dt s."""
    model = vehicle_of(plant, f"{fields.path}.type")
    kind = fields.text("kind", choices=KINDS)
    form = fields.text("form", "paper", choices=FORMS)
    time_constant = fields.number("time_constant", positive=True)  # s
    tau_d = fields.vector("tau_d", model.dof)
    commands = fields.raw("commands", list(plant.u.names), "list of strings",
                          "the signals driving the plant's inputs, in their order", "the inputs' names")
    if (not isinstance(commands, list) or len(commands) != plant.u.size
            or not all(isinstance(c, str) for c in commands)):
        raise ScenarioError(f"{fields.path}.commands: expected {plant.u.size} signal names (one per input: "
                            f"{', '.join(plant.u.names)}), got {commands!r}")
    continuous = actuator_observer(model, kind, form)
    try:
        K = design_gains(continuous, time_constant, None if tau_d is None else tuple(tau_d)).K
    except ObserverError as exc:
        raise ScenarioError(f"{fields.path}.tau_d: {exc}") from None
    observer = actuator_fault_observer(model, kind, dt, K, form=form, name=name)
    n, n_y = model.dof, 2 * model.dof
    forces = Signals(FORCE_LABELS[n], model.force_units, group="force")

    def desired(r):
        """tau_d (n,) from the reads r = [eta; nu; u_cmd]: what the commands give with no current."""
        return model.tau(r[:n], r[n:n_y], r[n_y:], 0.0, 0.0)

    def step(s, r):
        s_next, f_hat = observer.step(s, r[:n_y], desired(r), ca.DM(K))
        return s_next, ca.vertcat(desired(r), f_hat)

    def init(r0):
        tau0 = desired(ca.DM(r0))
        return observer.initial_state(r0[:n_y], tau0, K)

    reads = Signals(model.state_labels + tuple(commands), model.state_units + plant.u.units, group="read")
    publishes = forces.renamed(prefix="tau_d.", group="published") + observer.publishes.renamed(group="published")
    built = block(name, step=step, state=observer.state, reads=reads, publishes=publishes, dt=dt, init=init,
                  description=observer.description)
    made = {f.name: getattr(built, f.name) for f in fields_of(Block)}
    made["parameters"] = tuple(zip(observer.params.names, map(float, K)))
    return ActuatorObserverBlock(**made, design=continuous, K=tuple(map(float, K)), model=model)
