"""The ``uio_bank`` block of scenario files: a bank of discrete unknown-input observers designed for
the scenario's plant (:mod:`uvsym.observers.uio_bank`; Yang, Hu & Zhang, eqs. 20 and 26).

Fields (besides type and name): ``poles`` (n eigenvalues of every observer's ``F = T G - K1 C``),
``measured`` (the outputs the bank reads, default all), ``decouple`` (the plant's disturbances
decoupled by every observer, default all); observer i decouples input i as well (one per input:
the generalised observer scheme). The plant is linearised at its operating point,
``x_{k+1} = G x_k + H u_k + D1 d_k``, ``y = C x``: a discrete plant as it is (its period must be
the loop's), a continuous one by the exact zero-order hold of its linearisation at the loop's
period (a nonlinear plant then differs from the bank's model away from that point).

The block reads the measured outputs and every input, runs the observers on their deviations
from the operating point (each starts at ``xhat_0 = x_op`` from the first measurement, noise
included: ``z_0 = -Q (y_0 - y_op)``) and publishes, for observer i (named
by its actuator a) and measured output y, the residual ``r_<a>_<y>`` (y's unit), read as
``<block>.r_<a>_<y>``. The bank's designs stay on the block (:class:`UIOBankBlock`) for the
detector that judges the residuals (:mod:`uvsym.diagnosis.zonotope_bands`).
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from uvsym.errors import ObserverError, ScenarioError, UIOConditionError
from uvsym.observers.uio_bank import UIOBank, uio_bank
from uvsym.sim.blocks import Block, block
from uvsym.sim.fields import Fields
from uvsym.systems.discretize import zoh_matrices
from uvsym.systems.signals import Signals
from uvsym.systems.system import System

__all__ = ["UIOBankBlock", "residual_name", "uio_bank_block"]


def residual_name(actuator: str, output: str) -> str:
    """The published name of observer ``actuator``'s residual on ``output``."""
    return f"r_{actuator}_{output}"


@dataclass(frozen=True)
class UIOBankBlock(Block):
    """A :class:`~uvsym.sim.blocks.Block` running a :class:`~uvsym.observers.uio_bank.UIOBank`;
    measured: the output names its residuals are over (in the order of each observer's entries)."""

    bank: UIOBank | None = None
    measured: tuple[str, ...] = ()


def _names(fields: Fields, key: str, known: tuple[str, ...], what: str) -> tuple[str, ...]:
    value = fields.raw(key, list(known), "list of strings", f"{what} of the plant", f"all the plant's {what}")
    value = [value] if isinstance(value, str) else value
    if not isinstance(value, list) or not value or any(v not in known for v in value) or len(set(value)) < len(value):
        raise ScenarioError(f"{fields._name(key)}: expected distinct {what} of the plant ({', '.join(known)}), "
                            f"got {value!r}")
    return tuple(value)


def uio_bank_block(fields: Fields, plant: System, dt: float, name: str) -> UIOBankBlock:
    """The ``uio_bank`` block a ``[[blocks]]`` table describes (module docstring).

    ScenarioError naming the field: ``measured`` when no UIO exists for those outputs (the
    decoupled directions cannot be reconstructed, or (C, T G) is not detectable: the message
    names the actuator and the unobservable eigenvalues), ``poles`` when they cannot be placed,
    ``decouple`` for a plant without disturbances, unknown names with the known ones."""
    measured = _names(fields, "measured", plant.y.names, "outputs")
    if not plant.d.size:
        raise ScenarioError(f"{fields._name('decouple')}: plant {plant.name} has no disturbance input to decouple")
    decouple = _names(fields, "decouple", plant.d.names, "disturbances")
    n = plant.x.size
    poles = fields.raw("poles", None, "list of numbers", "n_x eigenvalues of F, inside the unit circle")
    if not isinstance(poles, list) or len(poles) != n or not all(isinstance(p, (int, float)) and not isinstance(
            p, bool) and abs(p) < 1 for p in poles):
        raise ScenarioError(f"{fields._name('poles')}: expected {n} real eigenvalues inside the unit circle, got "
                            f"{poles!r}")
    lin = plant.linearize()
    G, H, E = lin.A, lin.B, lin.E
    if not plant.discrete:  # the linearisation's exact zero-order hold at the loop's period
        G, HE = zoh_matrices(lin.A, np.hstack([lin.B, lin.E]), dt)
        H, E = HE[:, :plant.u.size], HE[:, plant.u.size:]
    rows = [plant.y.index(y) for y in measured]
    D1 = E[:, [plant.d.index(d) for d in decouple]]
    outputs = Signals(measured, tuple(plant.y.units[i] for i in rows), group="measurement")
    try:
        bank = uio_bank(G, H, lin.C[rows], D1, np.asarray(poles, dtype=float), states=plant.x,
                        outputs=outputs, inputs=plant.u, dt=dt, name=name)
    except UIOConditionError as exc:
        raise ScenarioError(f"{fields._name('measured')}: no unknown-input observer exists for the outputs "
                            f"{', '.join(measured)} decoupling {', '.join(decouple)}: {exc}") from None
    except ObserverError as exc:
        raise ScenarioError(f"{fields._name('poles')}: {exc}") from None
    return _bank_block(bank, plant, lin, rows, name)


def _bank_block(bank: UIOBank, plant: System, lin, rows: list[int], name: str) -> UIOBankBlock:
    """The block of the bank: reads the measured outputs and every input, observers on deviations."""
    measured = tuple(plant.y.names[i] for i in rows)
    y_op, u_op = np.asarray(lin.y0, dtype=float).ravel()[rows], np.asarray(lin.u0, dtype=float).ravel()
    sizes = [obs.state.size for obs in bank.observers]
    starts = np.concatenate([[0], np.cumsum(sizes)])
    p = len(rows)

    def step(s, r):
        # s = [z of each observer; started]: on the first sample (started = 0) every observer starts at
        # xhat_0 = x_op, z_0 = -Q (y_0 - y_op), from the first measurement as it is read (noise included)
        dy, du, started = r[:p] - ca.DM(y_op), r[p:] - ca.DM(u_op), s[-1]
        s_next, out = [], []
        for obs, design, a, b in zip(bank.observers, bank.designs, starts[:-1], starts[1:]):
            z = ca.if_else(started > 0.5, s[int(a):int(b)], -ca.mtimes(ca.DM(design.Q), dy))
            z_next, published = obs.step(z, dy, du, obs.p0)
            s_next.append(z_next)
            out.append(published[-p:])
        return ca.vertcat(*s_next, 1.0), ca.vertcat(*out)

    units = tuple(plant.y.units[i] for i in rows)
    publishes = Signals(tuple(residual_name(a, y) for a in bank.decoupled for y in measured),
                        units * len(bank.decoupled), group="residual")
    state = Signals(tuple(f"z_{a}_{x}" for a in bank.decoupled for x in plant.x.names) + ("started",),
                    plant.x.units * len(bank.decoupled) + ("-",), group="state")
    reads = Signals(measured, units, group="measurement") + plant.u.renamed(group="input")
    generic = block(name, step=step, state=state, reads=reads, publishes=publishes, dt=bank.observers[0].dt,
                    description=f"bank of {len(bank.decoupled)} unknown-input observers, one per actuator "
                                           f"({', '.join(bank.decoupled)})")
    return UIOBankBlock(generic.name, generic.state, generic.reads, generic.publishes, generic.step, generic.s0,
                        generic.dt, generic.init, generic.description, bank=bank, measured=measured)
