"""Blocks: the discrete parts of a loop wired by signal name (controllers, observers, tables).

A block is sampled every ``dt`` seconds::

    s_{k+1}, out_k = step(s_k, r_k)

``s`` its own state, ``r`` the loop signals it reads (by name), ``out`` the signals it publishes
(by name); ``out_k`` belongs to sample k and may use ``r_k`` (direct feed-through), so
:func:`uvsym.sim.wiring.interconnect` orders the blocks by what each output really depends on.
A unit left empty (``""``) is the unit of the signal it is joined to, filled in by the wiring.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import casadi as ca
import numpy as np

from uvsym.errors import WiringError
from uvsym.observers.base import Observer, check_name
from uvsym.systems.signals import Signals

__all__ = ["Block", "block", "observer_block", "renamed", "as_signals", "select"]

STEP_INPUTS = ("s", "r")
STEP_OUTPUTS = ("s_next", "out")


@dataclass(frozen=True)
class Block:
    """A discrete block of a loop (module docstring).

    step(s (n_s,), r (n_r,)) -> (s_next (n_s,), out (n_out,)), a Function named ``<name>_step``;
    state, reads, publishes: the Signals of s, r and out (reads and publishes are loop signal
    names); s0: (n_s,) initial state; dt: the sample period (s) the step was designed for, None
    for a block valid at any rate; init(r0 (n_r,)) -> s0: the initial state from the first
    sample's reads, or None to start at s0; source: the Observer the block runs (for claims about
    it, :mod:`uvsym.scenario_exports`), None for other blocks; parameters: (name, value) of the parameters its step
    holds fixed (an observer's p, :func:`observer_block`), for what reads the block's design.
    """

    name: str
    state: Signals
    reads: Signals
    publishes: Signals
    step: ca.Function
    s0: np.ndarray
    dt: float | None = None
    init: Callable | None = None
    description: str = ""
    source: object = None
    parameters: tuple[tuple[str, float], ...] = ()

    def __post_init__(self):
        check_name(self.name, "block", WiringError)
        f = self.step
        if not isinstance(f, ca.Function) or tuple(f.name_in()) != STEP_INPUTS or \
                tuple(f.name_out()) != STEP_OUTPUTS:
            raise WiringError(f"block {self.name}: step must be a casadi.Function (s, r) -> (s_next, out)")
        for what, size, group in (("input s", f.numel_in(0), self.state), ("input r", f.numel_in(1), self.reads),
                                  ("output s_next", f.numel_out(0), self.state),
                                  ("output out", f.numel_out(1), self.publishes)):
            if size != group.size:
                raise WiringError(f"block {self.name}: step {what} has {size} entries but {group.size} signals are "
                                  f"named ({', '.join(group.names)})")
        s0 = np.asarray(self.s0, dtype=float).reshape(-1)
        if s0.size != self.state.size or not np.all(np.isfinite(s0)):
            raise WiringError(f"block {self.name}: s0 must be {self.state.size} finite numbers, got {s0.tolist()}")
        object.__setattr__(self, "s0", s0)
        if self.dt is not None and not (np.isfinite(self.dt) and self.dt > 0):
            raise WiringError(f"block {self.name}: sample period dt must be positive and finite (s), got {self.dt}")

    def initial_state(self, r0) -> np.ndarray:
        """The state before the first sample: ``init(r0)``, or s0 for a block without init."""
        if self.init is None:
            return self.s0
        s0 = np.asarray(self.init(np.asarray(r0, dtype=float)), dtype=float).reshape(-1)
        if s0.size != self.state.size or not np.all(np.isfinite(s0)):
            raise WiringError(f"block {self.name}: init gave {s0.tolist()}, expected {self.state.size} finite numbers")
        return s0


def as_signals(spec: str | Sequence[str] | Signals, group: str) -> Signals:
    """A Signals from a name, a sequence of names (units left empty: taken from the loop) or a Signals."""
    if isinstance(spec, Signals):
        return spec
    names = (spec,) if isinstance(spec, str) else tuple(spec)
    return Signals(names, ("",) * len(names), group=group)


def block(name: str, *, step: Callable, state: Signals | None = None, reads=(), publishes=(), s0=None,
          dt: float | None = None, init: Callable | None = None, description: str = "", source=None) -> Block:
    """A Block from a Python callable ``step(s, r) -> (s_next, out)`` on SX column vectors.

    reads, publishes: Signals, names or one name; state: Signals (default none); s0 default zeros.
    """
    check_name(name, "block", WiringError)
    state = state if state is not None else Signals(group="state")
    reads, publishes = as_signals(reads, "read"), as_signals(publishes, "published")
    s, r = ca.SX.sym("s", state.size), ca.SX.sym("r", reads.size)
    result = step(s, r)
    if not isinstance(result, tuple) or len(result) != 2:
        raise WiringError(f"block {name}: step must return (s_next, out)")
    s_next, out = (ca.densify(ca.vec(ca.SX(v))) for v in result)
    function = ca.Function(f"{name}_step", [s, r], [s_next, out], list(STEP_INPUTS), list(STEP_OUTPUTS))
    return Block(name, state, reads, publishes, function, np.zeros(state.size) if s0 is None else s0, dt, init,
                 description, source)


def renamed(blk: Block, reads: dict[str, str] | None = None, publishes: dict[str, str] | None = None) -> Block:
    """The same block joined to other loop signals: ``reads={"psi": "psi.raw"}`` makes it read
    ``psi.raw`` where it read ``psi``; likewise ``publishes``. WiringError for a name it lacks."""
    def rename(group: Signals, mapping: dict[str, str] | None, what: str) -> Signals:
        mapping = mapping or {}
        unknown = sorted(set(mapping) - set(group.names))
        if unknown:
            raise WiringError(f"block {blk.name} {what} no signal {unknown}; it {what}: {', '.join(group.names)}")
        return Signals(tuple(mapping.get(n, n) for n in group.names), group.units, group.descriptions, group.group)

    return replace(blk, reads=rename(blk.reads, reads, "reads"),
                   publishes=rename(blk.publishes, publishes, "publishes"))


def observer_block(obs: Observer, p=None, *, s0=None) -> Block:
    """An :class:`~uvsym.observers.base.Observer` as a block: reads ``obs.reads_y + obs.reads_u``,
    publishes ``obs.publishes``, parameters fixed at p (default ``obs.p0``; the block's ``parameters``),
    ``dt = obs.dt``.

    It starts at s0 if given, else at ``obs.init(y0, u0, p)`` of its first reads (zeros without init).
    """
    p = obs.parameters(p)
    n_y = obs.reads_y.size
    init = None
    if s0 is None and obs.init is not None:
        def init(r0):
            return obs.initial_state(r0[:n_y], r0[n_y:], p)

    built = block(obs.name, step=lambda s, r: obs.step(s, r[:n_y], r[n_y:], ca.DM(p)), state=obs.state,
                  reads=obs.reads_y + obs.reads_u, publishes=obs.publishes, s0=s0, dt=obs.dt, init=init,
                  description=obs.description, source=obs)
    return replace(built, parameters=tuple(zip(obs.params.names, (float(v) for v in np.ravel(p)))))


def select(name: str, *, flag: str, on: str | Sequence[str], off: str | Sequence[str], output: str | Sequence[str],
           unit: str = "") -> Block:
    """A switch of the same sample: ``output_k = on_k if flag_k > 0.5 else off_k``, no state.

    flag: one loop signal (0/1, e.g. an observer's fault flag); on, off, output: n loop signal
    names each (n >= 1, entry i of output is entry i of on or off); unit: of on, off and output
    (the wiring then refuses an on or off in another unit), or "" to take it from the loop. The
    output feeds its reads through within the sample, so the wiring evaluates it after the flag
    and both branches; a flag that depends on the output is an algebraic loop (WiringError).
    WiringError naming the argument for sizes that differ, no names, or a name used twice.
    """
    groups = {"on": on, "off": off, "output": output}
    names = {what: (spec,) if isinstance(spec, str) else tuple(spec) for what, spec in groups.items()}
    size = len(names["output"])
    for what, group in names.items():
        if len(group) != size or not group:
            raise WiringError(f"select {name}: {what} must name as many signals as output (at least one); got "
                              f"{list(group)} for output {list(names['output'])}")
    if not isinstance(flag, str):
        raise WiringError(f"select {name}: flag must be one signal name, got {flag!r}")
    read = (flag,) + names["on"] + names["off"]
    repeated = sorted({n for n in read if read.count(n) > 1} | (set(read) & set(names["output"])))
    if repeated:
        raise WiringError(f"select {name}: flag, on, off and output must name different signals; repeated: {repeated}")
    reads = Signals(read, ("",) + (unit,) * 2 * size, ("switch (0/1)",) + ("when set",) * size + ("when clear",) * size,
                    "read")
    publishes = Signals(names["output"], (unit,) * size, (f"{flag} ? on : off",) * size, "published")
    return block(name, step=lambda s, r: (s, ca.if_else(r[0] > 0.5, r[1:1 + size], r[1 + size:])), reads=reads,
                 publishes=publishes, description=f"{', '.join(names['output'])} = {flag} ? "
                                                  f"{', '.join(names['on'])} : {', '.join(names['off'])}")
