"""System: a plant as frozen data plus named CasADi Functions over named, unit-carrying signals.

Continuous time (``dt is None``)::

    x' = f(x, u, d, p)        y = h(x, u, p)

discrete time (``dt`` in s): ``x_{k+1} = f(x_k, u_k, d_k, p)``. ``x`` states, ``u`` inputs
(what a controller sets), ``d`` disturbances (what nobody sets), ``p`` parameters (constant over
a run, with nominal values ``p0``), ``y`` outputs (what sensors measure). Every signal has a
name and a unit (:class:`~uvsym.systems.signals.Signals`); the Functions name their inputs
``x, u, d, p`` and outputs ``x_dot`` (or ``x_next``) and ``y``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from uvsym.checked import checked
from uvsym.errors import ModelError
from uvsym.symbolic import as_column, has_nan_constant
from uvsym.systems.signals import Signals

__all__ = ["System", "Linearization", "system"]

ARGUMENTS = ("x", "u", "d", "p")


@dataclass(frozen=True)
class Linearization:
    """``dx = A dx + B du + E dd`` (continuous; ``x_next`` in discrete time), ``dy = C dx + D du``
    about ``(x0, u0, d0, p0)``; ``f0`` = f there (at an equilibrium 0 in continuous time, x0 in
    discrete time), ``y0`` = h there."""

    A: np.ndarray
    B: np.ndarray
    E: np.ndarray
    C: np.ndarray
    D: np.ndarray
    x0: np.ndarray
    u0: np.ndarray
    d0: np.ndarray
    p0: np.ndarray
    f0: np.ndarray
    y0: np.ndarray
    dt: float | None = None

    def moving(self, tolerance: float = 1e-9) -> np.ndarray:
        """(n_x,) bool: the states that do not stay at ``x0`` (``f0`` beyond 0, or beyond ``x0`` in
        discrete time, by more than ``tolerance`` times the size of their linear terms)."""
        rest = self.x0 if self.dt is not None else np.zeros_like(self.f0)
        scale = 1.0 + np.abs(self.A) @ np.abs(self.x0) + np.abs(self.B) @ np.abs(self.u0)
        return np.abs(self.f0 - rest) > tolerance * scale


@dataclass(frozen=True)
class System:
    """A plant. ``f(x, u, d, p) -> x_dot`` (or ``x_next`` when ``dt`` is set), ``h(x, u, p) -> y``;
    numeric calls of f and h are checked (sizes, names, finite values: :mod:`uvsym.checked`), ``.raw``
    unchecked.

    p0: (n_p,) nominal parameter values; x_op, u_op: an operating point (default zeros) used as
    the default of :meth:`linearize` and as a sensible initial state; u_min, u_max: input bounds
    (default unbounded); constants: the physical constants the equations were built with, with
    units and sources (a :class:`~uvsym.models.parameters.ParameterSet` or None); source: where
    the model and its numbers come from.
    """

    name: str
    description: str
    x: Signals
    u: Signals
    d: Signals
    p: Signals
    y: Signals
    f: ca.Function
    h: ca.Function
    p0: np.ndarray
    dt: float | None = None
    x_op: np.ndarray | None = None
    u_op: np.ndarray | None = None
    u_min: np.ndarray | None = None
    u_max: np.ndarray | None = None
    constants: object = None
    source: str = ""
    extras: dict = field(default_factory=dict)

    def __post_init__(self):
        sizes = {"x": self.x.size, "u": self.u.size, "d": self.d.size, "p": self.p.size}
        out = "x_next" if self.discrete else "x_dot"
        _check_function(self.name, self.f, ARGUMENTS, sizes, {out: self.x.size})
        _check_function(self.name, self.h, ("x", "u", "p"), sizes, {"y": self.y.size})
        labels = {"x": self.x.names, "u": self.u.names, "d": self.d.names, "p": self.p.names, out: self.x.names,
                  "y": self.y.names}
        for attr in ("f", "h"):  # numeric calls checked (uvsym.checked); .raw unchecked
            object.__setattr__(self, attr, checked(getattr(self, attr), self.name, labels))
        if self.dt is not None and not (np.isfinite(self.dt) and self.dt > 0):
            raise ModelError(f"{self.name}: sample period dt must be positive and finite (s), got {self.dt}")
        object.__setattr__(self, "p0", self.p.vector(self.p0, f"{self.name}: nominal parameters p0"))
        for attr, group, default in (("x_op", self.x, 0.0), ("u_op", self.u, 0.0),
                                     ("u_min", self.u, -np.inf), ("u_max", self.u, np.inf)):
            value = getattr(self, attr)
            if value is None:
                value = np.full(group.size, default)
            elif attr in ("u_min", "u_max"):
                value = np.asarray(value, dtype=float).reshape(-1)
                if value.size != group.size or np.any(np.isnan(value)):
                    raise ModelError(f"{self.name}: {attr} must have {group.size} entries, none NaN")
            else:
                value = group.vector(value, f"{self.name}: {attr}")
            object.__setattr__(self, attr, value)
        for attr in ("p0", "x_op", "u_op", "u_min", "u_max"):  # frozen data: shared by every cached user
            frozen = np.array(getattr(self, attr), dtype=float)
            frozen.setflags(write=False)
            object.__setattr__(self, attr, frozen)
        low = [n for n, lo, hi in zip(self.u.names, self.u_min, self.u_max) if not lo < hi]
        if low:
            raise ModelError(f"{self.name}: inputs {low} have lower bound >= upper bound")

    @property
    def discrete(self) -> bool:
        """True for a discrete-time system (``dt`` set)."""
        return self.dt is not None

    def _point(self, x0, u0, d0, p0) -> list[np.ndarray]:
        return [self.x.vector(self.x_op if x0 is None else x0, f"{self.name}: x0"),
                self.u.vector(self.u_op if u0 is None else u0, f"{self.name}: u0"),
                self.d.vector(np.zeros(self.d.size) if d0 is None else d0, f"{self.name}: d0"),
                self.p.vector(self.p0 if p0 is None else p0, f"{self.name}: p0")]

    def linearize(self, x0=None, u0=None, d0=None, p0=None) -> Linearization:
        """Jacobians ``A = df/dx, B = df/du, E = df/dd, C = dh/dx, D = dh/du`` at a point, by
        ``casadi.jacobian``. Defaults: the operating point, d = 0, p = p0. Values may be arrays or
        ``{name: value}`` mappings. ModelError naming the entry where a Jacobian is not finite."""
        point = self._point(x0, u0, d0, p0)
        x, u, d, p = (ca.SX.sym(a, s.size) for a, s in zip(ARGUMENTS, (self.x, self.u, self.d, self.p)))
        fx, hy = self.f(x, u, d, p), self.h(x, u, p)
        jac = ca.Function("linearization", [x, u, d, p],
                          [ca.jacobian(fx, v) for v in (x, u, d)] + [ca.jacobian(hy, v) for v in (x, u)] + [fx, hy])
        values = [np.asarray(ca.densify(v), dtype=float) for v in jac(*point)]
        rows_cols = ((self.x, self.x), (self.x, self.u), (self.x, self.d), (self.y, self.x), (self.y, self.u),
                     (self.x, None), (self.y, None))
        for label, matrix, (rows, cols) in zip(("A", "B", "E", "C", "D", "f", "h"), values, rows_cols):
            bad = np.argwhere(~np.isfinite(matrix))
            if bad.size:
                i, j = bad[0]
                where = f"d {rows.names[i]} / d {cols.names[j]}" if cols is not None else rows.names[i]
                raise ModelError(f"{self.name}: {label} is not finite at the linearisation point ({where} = "
                                 f"{matrix[i, j]}); choose another point")
        A, B, E, C, D, f0, y0 = values
        return Linearization(A, B, E, C, D, *point, f0.ravel(), y0.ravel(), self.dt)

    def discretize(self, dt: float, method: str = "zoh", steps: int = 1) -> System:
        """The discrete-time system sampled every ``dt`` s with u, d, p held (see
        :func:`uvsym.systems.discretize.discretize`)."""
        from uvsym.systems.discretize import discretize

        return discretize(self, dt, method, steps)

    def summary(self) -> dict:
        """JSON-friendly description: signals with units, time domain, parameters, source."""
        constants = self.constants.to_dict() if hasattr(self.constants, "to_dict") else {}
        return {"name": self.name, "description": self.description,
                "time": "continuous" if self.dt is None else f"discrete, dt = {self.dt:g} s",
                "states": self.x.to_list(), "inputs": self.u.to_list(), "disturbances": self.d.to_list(),
                "parameters": self.p.to_list(), "outputs": self.y.to_list(), "p0": self.p0.tolist(),
                "operating_point": {"x": dict(zip(self.x.names, self.x_op.tolist())),
                                    "u": dict(zip(self.u.names, self.u_op.tolist()))},
                "constants": constants, "source": self.source,
                "sx_instructions": {"f": self.f.n_instructions()}}


def _check_function(name: str, function, inputs: tuple, sizes: dict, outputs: dict) -> None:
    """ModelError unless ``function`` takes ``inputs`` (named, of ``sizes``) and gives ``outputs``."""
    if not isinstance(function, ca.Function):
        raise ModelError(f"{name}: expected a casadi.Function, got {type(function).__name__}")
    if tuple(function.name_in()) != inputs or tuple(function.name_out()) != tuple(outputs):
        raise ModelError(f"{name}: Function {function.name()} must map ({', '.join(inputs)}) -> "
                         f"({', '.join(outputs)}), got ({', '.join(function.name_in())}) -> "
                         f"({', '.join(function.name_out())})")
    for i, arg in enumerate(inputs):
        if function.numel_in(i) != sizes[arg]:
            raise ModelError(f"{name}: {function.name()} input {arg} has {function.numel_in(i)} entries, "
                             f"the system has {sizes[arg]}")
    for i, (out, size) in enumerate(outputs.items()):
        if function.numel_out(i) != size:
            raise ModelError(f"{name}: {function.name()} output {out} has {function.numel_out(i)} entries, "
                             f"expected {size}")


def _expression(name: str, what: str, value) -> ca.SX:
    """An SX column from what a user's rhs/output returned; ModelError otherwise."""
    try:
        return as_column(value)
    except TypeError as exc:
        raise ModelError(f"{name}: {what} must return a CasADi expression or a list of them ({exc})") from None


def system(name: str, description: str, *, x: Signals, u: Signals, rhs: Callable,
           d: Signals | None = None, p: Signals | None = None, y: Signals | None = None,
           output: Callable | None = None, p0=None, dt: float | None = None, **options) -> System:
    """Build a System from expressions.

    rhs(x, u, d, p) -> (n_x,) SX: ``x'`` (or ``x_next`` with ``dt``); output(x, u, p) -> (n_y,)
    SX, default ``y = x`` (then y has the states' names). ``options`` go to :class:`System`
    (x_op, u_op, u_min, u_max, constants, source, extras).

    Raises
    ------
    ModelError
        For expressions of the wrong size or that use symbols other than x, u, d, p.
    """
    d = d if d is not None else Signals(group="disturbance")
    p = p if p is not None else Signals(group="parameter")
    if output is None and y is None:
        y = x.renamed(group="output")
    if y is None:
        raise ModelError(f"{name}: an output function needs its output signals y")
    syms = [ca.SX.sym(a, s.size) for a, s in zip(ARGUMENTS, (x, u, d, p))]
    xs, us, ds, ps = syms
    rhs_expr = _expression(name, "rhs", rhs(xs, us, ds, ps))
    out_expr = _expression(name, "output", xs if output is None else output(xs, us, ps))
    for what, expr, size in (("rhs", rhs_expr, x.size), ("output", out_expr, y.size)):
        if expr.numel() != size:
            raise ModelError(f"{name}: {what} gives {expr.numel()} entries (shape {expr.shape}), expected {size}")
    free = ca.symvar(ca.vertcat(ca.vec(rhs_expr), ca.vec(out_expr)))
    known = {s.name() for s in ca.symvar(ca.vertcat(*syms))}
    stray = sorted({s.name() for s in free} - known)
    if stray:
        raise ModelError(f"{name}: the equations use symbols other than x, u, d, p: {stray}")
    for what, expr in (("rhs", rhs_expr), ("output", out_expr)):
        if has_nan_constant(ca.Function("graph", syms, [expr], {"allow_free": True})):
            raise ModelError(f"{name}: the {what} holds a NaN constant: a math or numpy function applied to a "
                             "CasADi symbol gives NaN; use casadi's own (ca.sin, ca.exp, ...)")
    out_name = "x_dot" if dt is None else "x_next"
    f = ca.Function("f" if dt is None else "f_d", syms, [ca.vec(rhs_expr)], list(ARGUMENTS), [out_name])
    h = ca.Function("h", [xs, us, ps], [ca.vec(out_expr)], ["x", "u", "p"], ["y"])
    return System(name=name, description=description, x=x, u=u, d=d, p=p, y=y, f=f, h=h,
                  p0=np.zeros(p.size) if p0 is None else p0, dt=dt, **options)
