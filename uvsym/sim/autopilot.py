"""The marine autopilot as a scenario block (``type = "autopilot"``): line-of-sight guidance along
waypoints with speed and heading PID loops (:class:`uvsym.sim.controllers.Autopilot`, direct
mode), mixed onto the plant's inputs and saturated at their limits.

Fields (besides type and name): ``waypoints`` ([north, east] pairs, m), ``lookahead``,
``turn_radius``, ``acceptance`` (m), ``speed`` (m/s, the surge set-point), ``speed_loop`` and
``heading_loop`` (tables ``kp``, ``ki``, ``kd``, ``feedforward``, ``i_limit``: the loops of
:class:`~uvsym.sim.controllers.Loop`, in N per m/s and N m per rad for thrust commands),
``mix`` (``{speed = {input = coefficient}, yaw = {...}}``), ``reads`` (the measured north, east,
heading, surge, sway and yaw rate: six loop signal names, default the plant's six states),
``limits`` ([lo, hi] for every input, in the inputs' unit; default the plant's input limits) and
``saturate`` (clamp to the limits, default true).

State: the two loops' error integrals, an unused depth integral and the LOS segment index;
publishes the mixed inputs, ``psi_ref`` (rad) and ``cross_track`` (m).
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from uvsym.errors import ScenarioError
from uvsym.models.actuators import saturate as clamp
from uvsym.sim.blocks import Block, block
from uvsym.sim.controllers import Autopilot, LineOfSight, Loop
from uvsym.sim.fields import Fields
from uvsym.systems.signals import Signals
from uvsym.systems.system import System

__all__ = ["autopilot_block"]

LOOP_KEYS = ("kp", "ki", "kd", "feedforward", "i_limit")


@dataclass(frozen=True)
class _Mixing:
    """What :meth:`Autopilot.law` asks of a model in direct mode: 3 DOF and the input names."""

    input_labels: tuple[str, ...]
    dof: int = 3


def _loop(fields: Fields, key: str, reference: float) -> Loop:
    table = fields.table(key)
    if table is None:
        raise ScenarioError(f"{fields._name(key)}: required table of {', '.join(LOOP_KEYS)} is missing")
    gains = {k: table.number(k, None if k == "kp" else 0.0) for k in LOOP_KEYS if k != "i_limit"}
    loop = Loop(reference, i_limit=table.number("i_limit", float("inf"), positive=True), **gains)
    table.done()
    return loop


def _mix(fields: Fields, plant: System) -> dict:
    value = fields.raw("mix", None, "table", "channel (speed, yaw) -> {input = coefficient}")
    if not isinstance(value, dict) or not value:
        raise ScenarioError(f"{fields._name('mix')}: expected a table channel = {{input = coefficient}}, got {value!r}")
    mix = {}
    for channel, entries in value.items():
        where = Fields(entries, fields._name(f"mix.{channel}"))
        if channel not in ("speed", "yaw"):
            raise ScenarioError(f"{fields._name('mix')}.{channel}: unknown channel; known: speed, yaw")
        for name in entries:
            if name not in plant.u.names:
                raise ScenarioError(f"{where.path}.{name}: not an input of {plant.name}; inputs: "
                                    f"{', '.join(plant.u.names)}")
        mix[channel] = {name: where.number(name) for name in entries}
    return mix


def autopilot_block(fields: Fields, plant: System, dt: float, name: str) -> Block:
    """The autopilot block a ``[[blocks]]`` table describes (module docstring)."""
    from uvsym.sim.catalogue import _group, _names

    waypoints = fields.raw("waypoints", None, "list of [north, east]", "m, at least two")
    try:
        path = LineOfSight(tuple(map(tuple, waypoints or ())), lookahead=fields.number("lookahead", 10.0,
                                                                                         positive=True),
                           acceptance=fields.number("acceptance", 2.0, positive=True),
                           turn_radius=fields.number("turn_radius", 0.0, minimum=0.0))
    except ScenarioError as exc:  # LineOfSight names its own field path.<field>
        raise ScenarioError(f"{fields.path}.{str(exc).removeprefix('path.')}") from None
    except (TypeError, ValueError):
        raise ScenarioError(f"{fields._name('waypoints')}: expected [north, east] pairs (m), got {waypoints!r}") \
            from None
    speed = fields.number("speed", positive=True)
    autopilot = Autopilot(speed=_loop(fields, "speed_loop", speed), heading=_loop(fields, "heading_loop", 0.0),
                          path=path, outputs=_mix(fields, plant))
    default = plant.x.names if plant.x.size == 6 else None
    fields.describe("reads", "string or list of strings", "the 6 signals read as x, y, psi, u, v, r (m, rad, m/s, "
                    "rad/s)", "the plant's states, for a 3-DOF vehicle")
    reads = _group(plant, _names(fields, "reads", default, size=6), fields.path, "read")
    saturate = fields.raw("saturate", True, "boolean", "clamp to the plant's input limits")
    if not isinstance(saturate, bool):
        raise ScenarioError(f"{fields._name('saturate')}: expected true or false, got {saturate!r}")
    model = _Mixing(plant.u.names)
    limits = fields.vector("limits", 2)
    if limits is not None and not limits[0] < limits[1]:
        raise ScenarioError(f"{fields._name('limits')}: expected [lo, hi] with lo < hi, got {limits.tolist()}")
    low, high = ((ca.DM(np.asarray(plant.u_min, float)), ca.DM(np.asarray(plant.u_max, float))) if limits is None
                 else (ca.DM.ones(plant.u.size) * limits[0], ca.DM.ones(plant.u.size) * limits[1]))
    state = Signals(autopilot.state_labels, ("m s", "rad s", "m s", "-"), group="state")
    publishes = plant.u.renamed(group="published") + Signals(("psi_ref", "cross_track"), ("rad", "m"),
                                                             ("heading set-point", "cross-track error"), "published")

    def step(s, r):
        s_next, u_d, refs = autopilot.law(s, r, dt, model)
        u = clamp(u_d, low, high) if saturate else u_d
        return s_next, ca.vertcat(u, refs[1], refs[4])

    return block(name, step=step, state=state, reads=reads, publishes=publishes, dt=dt,
                 description=f"LOS guidance ({len(path.waypoints)} waypoints) with speed and heading PID")
