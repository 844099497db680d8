"""Closed loops of any System, wired by signal name (like python-control's ``interconnect``).

The loop publishes its time ``t`` (s); the plant publishes its measured outputs under its output
names and reads its inputs under its input names; each block reads and publishes the signals its
Signals name. A signal block B publishes as N is read as ``B.N``, a measured output N as ``y.N``
(``y``: the group of measured outputs), and either as the bare N while no other block or output
publishes N; a bare N published more than once is a WiringError only when read, naming the
qualified choices. Nothing but the loop publishes ``t``, and no published name may be another
signal's qualified one. The loop's names (``names``, ``units``, ``order``) are bare where the bare
name reads the signal, qualified otherwise. A read named ``N.raw`` gets N (bare or qualified) as
published, never substituted (unless some block publishes ``N.raw`` itself).

State ``z = [x (n_x); s of each block, in order; held (n_y)]``: plant state, block states, and
the outputs latched at the last sample before a stuck sensor fault. Per-sample input
``w = [t; noise (n_y); d (n_d); theta (7 per fault); on (n_c)]``: time (s), standard normal draws
for sensor noise, the plant's disturbances, each fault's numbers (value and profile times,
:func:`uvsym.faults.fault_parameters`, constant over a run) and one switch (0 or 1) per
substitution channel. The loop's Functions depend on its faults' shapes only (target, kind,
profile kind), so runs that differ in fault sizes, onsets and durations share one compiled step
(and its lanes); :func:`interconnect` makes the loop of one shape once per process. At each sample

    y_k = h(x_k, u_f(u_k, t_k), p) + sensor faults,     blocks: s_{k+1}, out_k = step(s_k, r_k)

in the order the outputs depend on each other; the plant inputs u_k are held over the sample
while ``x' = f(x, u_f(u_k, t), d_k, p)`` is integrated, with actuator faults u_f in continuous
time (the fixed-step RK4 path smears a fault that switches inside a sample over that sample;
the CasADi integrators, or onsets on the sample grid, avoid it). A discrete-time plant (its
``dt`` equal to the loop's) steps ``x_{k+1} = f_d(x_k, u_f(u_k, t_k), d_k, p)`` instead, on the
fast path only. Measurement substitution
``{"psi": "psi_hat"}``: while channel psi is on, every block that reads ``psi`` (under any of its
names but ``.raw``) gets ``psi_hat`` instead, except the block publishing ``psi_hat`` (an estimator
keeps seeing its sensor); switches are columns of w, set by a supervisor's ``Substitution``.
"""

from __future__ import annotations

import difflib
import graphlib
from dataclasses import dataclass, field, replace

import casadi as ca
import numpy as np

from uvsym.codegen.cache import memoized
from uvsym.errors import WiringError
from uvsym.faults import (
    FAULT_PARAMETERS,
    ActuatorFault,
    SensorFault,
    apply_actuator_faults,
    apply_sensor_faults,
    fault_shape,
    symbolic_fault,
)
from uvsym.sim.blocks import Block
from uvsym.sim.loop import SampledLoop, logged_signals
from uvsym.symbolic import rk4
from uvsym.systems.signals import Signals
from uvsym.systems.system import System

__all__ = ["WiredLoop", "interconnect", "RESERVED", "RAW"]

# result groups, and the loop Functions' own argument names
RESERVED = ("x", "y", "u", "t", "held", "fault_sensor", "fault_actuator", "substitution", "z", "w")
RAW = ".raw"


@dataclass(frozen=True, kw_only=True)
class WiredLoop(SampledLoop):
    """A loop of a System and blocks (the runner's fields in :class:`~uvsym.sim.loop.SampledLoop`):
    s = x, env = [d; theta]; z = [x; each block's state; held]. reads(z, w) -> what each block reads,
    one output per block (named by it); names: the published signals; units: name -> unit; order:
    their evaluation order; layout: x, each block's name, held -> slice; substitution_columns:
    channel -> the column of w holding its switch; no command correction. faults: the actuator
    then sensor faults whose numbers :func:`~uvsym.sim.system_simulation.loop_inputs` writes in the
    ``fault_columns`` of w (another run of the same shapes gives its own).
    """

    plant: System
    blocks: tuple[Block, ...]
    p: np.ndarray
    reads: ca.Function
    names: tuple[str, ...]
    units: dict[str, str]
    order: tuple[str, ...]
    faults: tuple = ()
    fault_columns: slice = field(default_factory=lambda: slice(0, 0))

    def integrated(self, out: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """s = x and the plant inputs as commanded (u less its actuator fault), per logged row."""
        return self.logged(out, "x"), self.logged(out, "u") - self.logged(out, "fault_actuator")


def _column(items) -> ca.SX:
    return ca.vertcat(*items) if items else ca.SX(0, 1)


def _check(plant: System, blocks: tuple[Block, ...], dt: float, substeps: int) -> None:
    """WiringError for a bad period, a discrete plant sampled at another period, repeated or
    reserved block names, a block designed for another period."""
    if not (np.isfinite(dt) and dt > 0) or not (isinstance(substeps, int) and substeps >= 1):
        raise WiringError(f"dt must be positive (s) and substeps a positive integer, got {dt} and {substeps!r}")
    if plant.discrete and abs(plant.dt - dt) > 1e-9 * dt:
        raise WiringError(f"plant {plant.name} is sampled every {plant.dt:g} s, the loop every {dt:g} s")
    for b in blocks:
        if not isinstance(b, Block):
            raise WiringError(f"blocks must be Block objects, got {type(b).__name__}")
    names = [b.name for b in blocks]
    for b in blocks:
        if names.count(b.name) > 1 or b.name in RESERVED:
            raise WiringError(f"block name {b.name!r} is used twice or reserved ({', '.join(RESERVED)})")
        if b.dt is not None and abs(b.dt - dt) > 1e-9 * dt:
            raise WiringError(f"block {b.name} was designed for dt = {b.dt} s; the loop samples every {dt} s")


@dataclass(frozen=True)
class _Published:
    """who: canonical name -> its publisher; units: canonical name -> its declared unit; alias: each
    name that reads one signal (bare or qualified) -> its canonical name; shared: each bare name
    published more than once -> the canonical (qualified) names of its signals."""

    who: dict[str, str]
    units: dict[str, str]
    alias: dict[str, str]
    shared: dict[str, list[str]]


def _listing(items: list[str], last: str = "and") -> str:
    return f"{', '.join(items[:-1])} {last} {items[-1]}" if len(items) > 1 else items[0]


def _publishers(plant: System, blocks: tuple[Block, ...]) -> _Published:
    """The loop's signals (module docstring); WiringError for a published ``t`` (the loop's time) or
    a published name that is another signal's qualified name."""
    groups = [("y", f"plant {plant.name}", plant.y)] + [(b.name, f"block {b.name}", b.publishes) for b in blocks]
    by_name: dict[str, list[str]] = {}
    for _, label, group in groups:
        for name in group.names:
            by_name.setdefault(name, []).append(label)
    published = _Published({"t": "the loop"}, {"t": "s"}, {"t": "t"}, {})
    for key, label, group in groups:
        for name, unit in zip(group.names, group.units):
            qualified = f"{key}.{name}"
            if name == "t":
                raise WiringError(f"{label} publishes 't', the name of the loop's time (s)")
            if qualified in by_name:
                raise WiringError(f"{label} publishes {name!r}, read as {qualified!r}, a name "
                                  f"{_listing(by_name[qualified])} also publishes")
            canonical = name if len(by_name[name]) == 1 else qualified
            published.who[canonical], published.units[canonical] = label, unit
            published.alias[qualified] = canonical
            if canonical == name:
                published.alias[name] = name
            else:
                published.shared.setdefault(name, []).append(canonical)
    return published


def _source(name: str, published: _Published, reader: str, plant: System) -> tuple[str, bool]:
    """(the canonical signal a read of ``name`` joins, whether it reads it raw: ``N.raw``);
    WiringError if nothing publishes it, or for a bare name several publish."""
    alias, shared = published.alias, published.shared
    raw = name.endswith(RAW) and name not in alias and name not in shared
    base = name[:-len(RAW)] if raw else name
    if base in alias:
        return alias[base], raw
    driven = f"plant {plant.name} input {name!r} is driven by" if reader == f"plant {plant.name}" else ""
    if base in shared:
        labels = [published.who[c] for c in shared[base]]
        if all(label.startswith("block ") for label in labels):
            labels = [f"blocks {_listing([label.removeprefix('block ') for label in labels])}"]
        if driven:
            raise WiringError(f"{driven} {_listing(labels)}; rename all but one (uvsym.sim.renamed)")
        choices = _listing([f"'{c}{name[len(base):]}'" for c in shared[base]], "or")
        raise WiringError(f"{reader} reads {name!r}, which {_listing(labels)} "
                          f"{'both' if len(shared[base]) == 2 else 'all'} publish; read {choices}")
    close = difflib.get_close_matches(name, [*alias, *shared])
    known = ", ".join(sorted(published.who)) + (f"; did you mean {_listing([repr(c) for c in close], 'or')}?"
                                                 if close else "")
    if driven:
        raise WiringError(f"{driven} no block; published: {known}")
    raise WiringError(f"{reader} reads {name!r}, which nothing publishes; published: {known}")


def _resolve_units(readers: list[tuple[str, Signals]], published: _Published, plant: System) -> dict:
    """Units of every published signal: the publisher's, else the first reader's; WiringError on a mismatch."""
    units = dict(published.units)
    for reader, group in readers:
        for name, unit in zip(group.names, group.units):
            source = _source(name, published, reader, plant)[0]
            units[source] = units[source] or unit
    for reader, group in readers:
        for name, unit in zip(group.names, group.units):
            source = _source(name, published, reader, plant)[0]
            if unit and unit != units[source]:
                raise WiringError(f"{reader} reads {name!r} in {unit!r} but {published.who[source]} publishes it in "
                                  f"{units[source]!r}")
    return units


def _resolve(exprs: dict[str, ca.SX], P: dict[str, ca.SX], who: dict[str, str],
             substitutions: dict[str, str] | None = None) -> tuple[list[str], dict]:
    """(evaluation order, signal -> its expression free of placeholders).

    ``exprs[n]`` is signal n in terms of the placeholders ``P`` of the signals it reads; the
    dependencies are the structural ones (``jacobian_sparsity``), sorted topologically, then each
    placeholder is replaced by its signal in that order. WiringError naming a cycle (substitutions:
    channel, as given, -> its substitute's canonical name).
    """
    names = list(P)
    pattern = ca.jacobian_sparsity(ca.vertcat(*[exprs[n] for n in names]), ca.vertcat(*[P[n] for n in names]))
    deps: dict[str, list[str]] = {n: [] for n in names}
    for row, col in zip(*pattern.get_triplet()):
        deps[names[row]].append(names[col])
    try:
        order = list(graphlib.TopologicalSorter(deps).static_order())
    except graphlib.CycleError as exc:
        cycle = " -> ".join(f"{n} ({who[n]})" for n in exc.args[1])
        through = [c for c, s in (substitutions or {}).items() if s in exc.args[1]]
        hint = (f"; it runs through the substitution of {', '.join(through)}: a block that must see the sensor "
                f"reads '{through[0]}{RAW}'" if through else "")
        raise WiringError(f"algebraic loop: {cycle}; each signal needs the next within the same sample "
                          f"(break it with a block whose output does not depend on its input){hint}") from None
    values = {}
    for name in order:
        used = deps[name]
        values[name] = ca.substitute([exprs[name]], [P[n] for n in used], [values[n] for n in used])[0]
    return order, values


def interconnect(plant: System, blocks, *, dt: float, actuator_faults: tuple[ActuatorFault, ...] = (),
                 sensor_faults: tuple[SensorFault, ...] = (), substitutions: dict[str, str] | None = None,
                 substeps: int = 1, p=None) -> WiredLoop:
    """The loop of ``plant`` and ``blocks`` sampled every ``dt`` s (module docstring).

    Actuator faults index the plant's inputs, sensor faults its outputs; p: plant parameters
    (default ``plant.p0``); substitutions: channel -> the signal that replaces it when on.

    Raises
    ------
    WiringError
        For a read nobody publishes (names the block, the signal, the published ones and close
        names), a bare read of a name several publish (names the qualified choices), a published
        ``t`` or qualified name of another signal, a plant input no block drives, an algebraic loop
        (names the cycle), an unknown substitution or a channel given twice, a unit mismatch, or a
        block designed for another sample period.
    """
    blocks = tuple(blocks)
    _check(plant, blocks, dt, substeps)
    p = tuple(plant.p.vector(plant.p0 if p is None else p, f"{plant.name}: parameters p"))
    faults = tuple(actuator_faults) + tuple(sensor_faults)
    shapes = tuple(fault_shape(f) for f in faults)
    loop = _wired(plant, blocks, float(dt), shapes, tuple(dict(substitutions or {}).items()), substeps, p)
    return replace(loop, faults=faults)


@memoized(32)
def _wired(plant: System, blocks: tuple[Block, ...], dt: float, shapes: tuple, substitutions: tuple,
           substeps: int, p: tuple) -> WiredLoop:
    """The loop of :func:`interconnect` for faults of these shapes, their numbers symbols of w."""
    p = ca.DM(p)
    substitutions = dict(substitutions)
    raw = [f"{c!r} -> {s!r}" for c, s in substitutions.items() if c.endswith(RAW) or s.endswith(RAW)]
    if raw:
        raise WiringError(f"substitutions {', '.join(raw)}: a substitution joins two published signals; "
                          f"'{RAW}' is only for reading a sensor past its substitution")
    published = _publishers(plant, blocks)
    canonical = published.alias
    plant_label = f"plant {plant.name}"
    readers = [(f"block {b.name}", b.reads) for b in blocks] + [(plant_label, plant.u)]
    units = _resolve_units(readers, published, plant)
    pairs = [tuple(_source(n, published, f"substitution {c!r} -> {s!r}", plant)[0] for n in (c, s))
             for c, s in substitutions.items()]  # (channel, substitute), canonical names
    if len({channel for channel, _ in pairs}) < len(pairs):
        raise WiringError(f"substitutions {list(substitutions)} name one channel twice")
    for (c, s), (channel, substitute) in zip(substitutions.items(), pairs):  # an empty unit is the other's
        if units[channel] and units[substitute] and units[channel] != units[substitute]:
            raise WiringError(f"substitution {c!r} -> {s!r}: units {units[channel]!r} and "
                              f"{units[substitute]!r} differ")
        units[channel] = units[substitute] = units[channel] or units[substitute]

    n_x, n_y, n_d, n_c = plant.x.size, plant.y.size, plant.d.size, len(substitutions)
    layout, start = {}, 0
    for part, size in [("x", n_x)] + [(b.name, b.state.size) for b in blocks] + [("held", n_y)]:
        layout[part], start = slice(start, start + size), start + size
    n_theta = len(FAULT_PARAMETERS) * len(shapes)
    n_env = n_d + n_theta
    n_z, n_w = start, 1 + n_y + n_env + n_c
    z, w = ca.SX.sym("z", n_z), ca.SX.sym("w", n_w)
    x, held, t = z[layout["x"]], z[layout["held"]], w[0]
    noise, env_w, on = w[1:1 + n_y], w[1 + n_y:1 + n_y + n_env], w[1 + n_y + n_env:]
    d = env_w[:n_d]
    actuator_faults, sensor_faults = _symbolic_faults(shapes, env_w[n_d:])
    switch = {channel: (on[i], substitute) for i, (channel, substitute) in enumerate(pairs)}
    P = {name: ca.SX.sym(name) for name in published.who}

    def read(reader: str, group: Signals) -> ca.SX:
        values = []
        for name in group.names:
            source, raw = _source(name, published, reader, plant)
            value = P[source]
            if source in switch and not raw and published.who[switch[source][1]] != reader:
                value = ca.if_else(switch[source][0], P[switch[source][1]], value)
            values.append(value)
        return _column(values)

    exprs, s_next, reads = {"t": t}, [], []
    for b in blocks:
        reads.append(read(f"block {b.name}", b.reads))
        s_b, out_b = b.step(z[layout[b.name]], reads[-1])
        s_next.append(s_b)
        exprs.update({canonical[f"{b.name}.{n}"]: out_b[i] for i, n in enumerate(b.publishes.names)})
    u_cmd = read(plant_label, plant.u)
    u_applied = apply_actuator_faults(u_cmd, t, actuator_faults)
    y_true = plant.h(x, u_applied, p)
    y, held_next = apply_sensor_faults(y_true, t, sensor_faults, held, noise)
    exprs.update({canonical[f"y.{n}"]: y[i] for i, n in enumerate(plant.y.names)})
    order, values = _resolve(exprs, P, published.who, {c: s for c, (_, s) in zip(substitutions, pairs)})
    parts = {"x": (x, plant.x, plant.x.units), "y": (y, plant.y, plant.y.units),
             "u": (u_applied, plant.u, plant.u.units)}
    for b in blocks:
        own = [canonical[f"{b.name}.{n}"] for n in b.publishes.names]
        parts[b.name] = (_column([exprs[n] for n in own]), b.publishes, tuple(units[n] for n in own))
    parts["fault_sensor"] = (y - y_true, plant.y, plant.y.units)
    parts["fault_actuator"] = (u_applied - u_cmd, plant.u, plant.u.units)
    if substitutions:
        parts["substitution"] = (on, tuple(substitutions), ("-",) * n_c)
    out, signals = logged_signals(parts)
    names = tuple(P)
    resolved = ca.substitute([u_cmd, _column(s_next + [held_next]), out] + reads, [P[n] for n in names],
                             [values[n] for n in names])
    u_cmd, z_disc, out, *reads = (ca.densify(e) for e in resolved)
    discrete = ca.Function("wired_loop_discrete", [z, w], [z_disc, u_cmd, out], ["z", "w"], ["z_disc", "u_cmd", "out"])
    reads = ca.Function("wired_loop_reads", [z, w], reads, ["z", "w"], [b.name for b in blocks])

    if plant.discrete:  # x_{k+1} = f_d(x_k, u_k, d_k, p): no integration, and no integrator path
        plant_ode = None
        x_next = plant.f(x, apply_actuator_faults(u_cmd, t, actuator_faults), d, p)
    else:
        s, uc, env, ts = ca.SX.sym("s", n_x), ca.SX.sym("u_cmd", plant.u.size), ca.SX.sym("env", n_env), ca.SX.sym("t")
        ode_faults = _symbolic_faults(shapes, env[n_d:])[0]
        s_dot = plant.f(s, apply_actuator_faults(uc, ts, ode_faults), env[:n_d], p)
        plant_ode = ca.Function("plant_ode", [s, uc, env, ts], [s_dot], ["s", "u_cmd", "env", "t"], ["s_dot"])
        x_next = rk4(plant_ode, x, dt, substeps, u_cmd, env_w, t=t)
    step = ca.Function("wired_loop_step", [z, w], [ca.densify(ca.vertcat(x_next, z_disc)), out], ["z", "w"],
                       ["z_next", "out"], {"cse": True})
    return WiredLoop(plant=plant, blocks=blocks, p=np.asarray(p).ravel(), dt=float(dt), substeps=substeps, n_z=n_z,
                     n_w=n_w, n_s=n_x, discrete=discrete, plant_ode=plant_ode, step=step, reads=reads,
                     names=names, units=units, order=tuple(order), layout=layout, signals=signals,
                     env_columns=slice(1 + n_y, 1 + n_y + n_env),
                     fault_columns=slice(1 + n_y + n_d, 1 + n_y + n_env),
                     substitution_columns={channel: 1 + n_y + n_env + i for i, channel in enumerate(substitutions)})


def _symbolic_faults(shapes: tuple, theta: ca.SX) -> tuple[tuple, tuple]:
    """(actuator faults, sensor faults) of these shapes with their numbers the consecutive entries of theta."""
    size = len(FAULT_PARAMETERS)
    faults = [symbolic_fault(shape, theta[size * i:size * (i + 1)]) for i, shape in enumerate(shapes)]
    return (tuple(f for f, shape in zip(faults, shapes) if shape[0] == ActuatorFault.__name__),
            tuple(f for f, shape in zip(faults, shapes) if shape[0] != ActuatorFault.__name__))
