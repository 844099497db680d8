"""The Model: a vehicle's equations of motion as named CasADi Functions, frozen.

Equations (Fossen 2021, eq. 6.101, relative-velocity form)::

    M (nu_dot - nu_c_dot) + h(eta, nu, nu_r) = tau(eta, nu, nu_r, u)
    eta_dot = J(eta) nu

with ``h`` the sum of the vehicle's named hull terms (Coriolis, damping, restoring, ...).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from uvsym.checked import checked
from uvsym.conventions import (
    FORCE_LABELS,
    FORCE_UNITS,
    POSITION_LABELS,
    POSITION_UNITS,
    VELOCITY_LABELS,
    VELOCITY_UNITS,
)
from uvsym.errors import KinematicsError, ModelError
from uvsym.kinematics import J, Rzyx, Tzyx
from uvsym.models.hydrodynamics import current_velocity, current_velocity_derivative
from uvsym.models.parameters import ParameterSet
from uvsym.systems.signals import Signals
from uvsym.systems.system import System

__all__ = ["Model", "VehicleEquations", "assemble"]


@dataclass(frozen=True)
class VehicleEquations:
    """What a vehicle module supplies to :func:`assemble`.

    hull_terms(eta, nu, nu_r) -> {name: (dof,) SX}: every non-control force as it stands on the
    left-hand side (their sum is h). actuation(eta, nu, nu_r, u) -> (dof,) SX: tau.
    actuator_rate(u, u_cmd) -> (m,) SX: the actuators' own dynamics (s^-1 times units of u).
    """

    M: np.ndarray
    hull_terms: Callable
    actuation: Callable
    actuator_rate: Callable
    input_labels: tuple[str, ...]
    input_units: tuple[str, ...]
    u_min: tuple[float, ...]
    u_max: tuple[float, ...]


@dataclass(frozen=True)
class Model:
    """A frozen vehicle model. Functions take (and name) their arguments as below; numeric calls
    are checked (sizes, names, finite values: :mod:`uvsym.checked`, ``.raw`` unchecked).

    nu_dot(eta, nu, u, V_c, beta_c) -> nu_dot; f(x, u, p) -> x_dot with x = [eta; nu],
    p = [V_c, beta_c]; tau(eta, nu, u, V_c, beta_c) -> tau; h(eta, nu) -> h (no current);
    B(eta, nu, u, V_c, beta_c) -> d tau / d u; actuator_rate(u, u_cmd) -> u_dot;
    terms(eta, nu, V_c, beta_c) -> every named hull term.
    """

    name: str
    description: str
    dof: int
    parameters: ParameterSet
    M: np.ndarray
    input_labels: tuple[str, ...]
    input_units: tuple[str, ...]
    u_min: np.ndarray
    u_max: np.ndarray
    nu_dot: ca.Function
    f: ca.Function
    tau: ca.Function
    h: ca.Function
    B: ca.Function
    actuator_rate: ca.Function
    terms: ca.Function
    term_names: tuple[str, ...] = field(default=())

    @property
    def n_inputs(self) -> int:
        """Number of actuator inputs m."""
        return len(self.input_labels)

    @property
    def M_inv(self) -> np.ndarray:
        """Inverse mass matrix (dof x dof)."""
        return np.linalg.inv(self.M)

    @property
    def state_labels(self) -> tuple[str, ...]:
        """Labels of x = [eta; nu]."""
        return POSITION_LABELS[self.dof] + VELOCITY_LABELS[self.dof]

    @property
    def state_units(self) -> tuple[str, ...]:
        """Units of x = [eta; nu]."""
        return POSITION_UNITS[self.dof] + VELOCITY_UNITS[self.dof]

    @property
    def force_units(self) -> tuple[str, ...]:
        """Units of tau and h."""
        return FORCE_UNITS[self.dof]

    def as_system(self) -> System:
        """This vehicle as a :class:`~uvsym.systems.System`: ``x = [eta; nu]``, ``u`` the actuator
        inputs (delivered at once: no actuator lag), no disturbance, ``p = (V_c, beta_c)`` the current
        (nominal 0), ``y = x``; ``extras["vehicle"]`` is this Model."""
        x = Signals(self.state_labels, self.state_units, group="state")
        u = Signals(self.input_labels, self.input_units, group="input")
        p = Signals(("V_c", "beta_c"), ("m/s", "rad"),
                    ("current speed", "direction the current flows towards, from north"), "parameter")
        xs, us, ds, ps = ca.SX.sym("x", x.size), ca.SX.sym("u", u.size), ca.SX.sym("d", 0), ca.SX.sym("p", 2)
        f = ca.Function("f", [xs, us, ds, ps], [self.f(xs, us, ps)], ["x", "u", "d", "p"], ["x_dot"])
        h = ca.Function("h", [xs, us, ps], [xs], ["x", "u", "p"], ["y"])
        return System(name=self.name, description=self.description, x=x, u=u, d=Signals(group="disturbance"),
                      p=p, y=x.renamed(group="output"), f=f, h=h, p0=np.zeros(2), u_min=self.u_min,
                      u_max=self.u_max, constants=self.parameters,
                      source=f"uvsym vehicle library ({self.name}): M (nu' - nu_c') + h(eta, nu_r) = tau(u)",
                      extras={"vehicle": self})

    def summary(self) -> dict:
        """JSON-friendly description: sizes, labels, units, mass matrix and parameters."""
        return {
            "name": self.name,
            "description": self.description,
            "dof": self.dof,
            "states": [{"label": lab, "unit": u} for lab, u in zip(self.state_labels, self.state_units)],
            "inputs": [{"label": lab, "unit": u, "min": float(lo), "max": float(hi)}
                       for lab, u, lo, hi in zip(self.input_labels, self.input_units, self.u_min, self.u_max)],
            "hull_terms": list(self.term_names),
            "M": self.M.tolist(),
            "parameters": self.parameters.to_dict(),
            "sx_instructions": {"nu_dot": self.nu_dot.n_instructions()},
        }


def _check_mass_matrix(name: str, M: np.ndarray, dof: int) -> None:
    """ModelError unless M is a finite, symmetric, positive definite dof x dof matrix."""
    if M.shape != (dof, dof):
        raise ModelError(f"{name}: mass matrix M must be {dof}x{dof}, got {M.shape}")
    if not np.all(np.isfinite(M)):
        raise ModelError(f"{name}: mass matrix M has non-finite entries")
    asym = np.max(np.abs(M - M.T))
    if asym > 1e-12 * max(1.0, np.max(np.abs(M))):
        raise ModelError(f"{name}: mass matrix M is not symmetric (max |M - M^T| = {asym:.3g})")
    smallest = float(np.min(np.linalg.eigvalsh(0.5 * (M + M.T))))
    if smallest <= 0.0:
        raise ModelError(f"{name}: mass matrix M is not positive definite "
                         f"(smallest eigenvalue {smallest:.6g}); check the mass, inertia and added-mass parameters")


def _check_inputs(name: str, eq: VehicleEquations) -> None:
    """ModelError unless labels, units and bounds of the inputs agree in size and order."""
    m = len(eq.input_labels)
    for what, seq in (("input_units", eq.input_units), ("u_min", eq.u_min), ("u_max", eq.u_max)):
        if len(seq) != m:
            raise ModelError(f"{name}: {what} has {len(seq)} entries, the model has {m} inputs")
    for label, lo, hi in zip(eq.input_labels, eq.u_min, eq.u_max):
        if not lo < hi:
            raise ModelError(f"{name}: input {label!r} has lower bound {lo} >= upper bound {hi}")


def assemble(name: str, description: str, dof: int, parameters: ParameterSet, eq: VehicleEquations) -> Model:
    """Build the named CasADi Functions of a Model from a vehicle's equations, validating them.

    Raises
    ------
    ModelError
        For a mass matrix that is not symmetric positive definite, inconsistent input
        sizes or bounds, or force terms of the wrong size.
    """
    M = np.asarray(eq.M, dtype=float)
    _check_mass_matrix(name, M, dof)
    _check_inputs(name, eq)
    m = len(eq.input_labels)

    eta, nu = ca.SX.sym("eta", dof), ca.SX.sym("nu", dof)
    u, u_cmd = ca.SX.sym("u", m), ca.SX.sym("u_cmd", m)
    V_c, beta_c = ca.SX.sym("V_c"), ca.SX.sym("beta_c")
    psi, r = eta[dof - 1], nu[dof - 1]
    nu_c = current_velocity(V_c, beta_c, psi, dof)
    nu_r = nu - nu_c

    terms = eq.hull_terms(eta, nu, nu_r)
    for term_name, value in terms.items():
        if value.shape != (dof, 1):
            raise ModelError(f"{name}: hull term {term_name!r} has shape {value.shape}, expected ({dof}, 1)")
    h = sum(terms.values(), ca.SX.zeros(dof))
    tau = eq.actuation(eta, nu, nu_r, u)
    if tau.shape != (dof, 1):
        raise ModelError(f"{name}: actuation gives shape {tau.shape}, expected ({dof}, 1)")
    nu_dot = current_velocity_derivative(V_c, beta_c, psi, r, dof) + ca.mtimes(ca.DM(np.linalg.inv(M)), tau - h)
    eta_dot = ca.mtimes(J(eta), nu) if dof == 6 else ca.mtimes(Rzyx(0.0, 0.0, psi), nu)
    states = POSITION_LABELS[dof] + VELOCITY_LABELS[dof]
    labels = {"eta": POSITION_LABELS[dof], "nu": VELOCITY_LABELS[dof], "x": states, "x_dot": states,
              "u": tuple(eq.input_labels), "u_cmd": tuple(eq.input_labels), "tau": FORCE_LABELS[dof],
              "h": FORCE_LABELS[dof], "nu_dot": VELOCITY_LABELS[dof]}

    def check(function: ca.Function, guard=None) -> ca.Function:
        return checked(function, name, labels, guard)

    env, env_names = [V_c, beta_c], ["V_c", "beta_c"]
    h_still = ca.substitute(h, ca.vertcat(V_c, beta_c), ca.DM.zeros(2))
    nu_dot_fn = ca.Function("nu_dot", [eta, nu, u, *env], [nu_dot], ["eta", "nu", "u", *env_names], ["nu_dot"])
    eta_dot_fn = ca.Function("eta_dot", [eta, nu], [eta_dot], ["eta", "nu"], ["eta_dot"])
    x, p = ca.SX.sym("x", 2 * dof), ca.SX.sym("p", 2)
    x_dot = ca.vertcat(eta_dot_fn(x[:dof], x[dof:]), nu_dot_fn(x[:dof], x[dof:], u, p[0], p[1]))

    return Model(
        name=name,
        description=description,
        dof=dof,
        parameters=parameters,
        M=M,
        input_labels=tuple(eq.input_labels),
        input_units=tuple(eq.input_units),
        u_min=np.asarray(eq.u_min, dtype=float),
        u_max=np.asarray(eq.u_max, dtype=float),
        nu_dot=check(nu_dot_fn),
        f=check(ca.Function("f", [x, u, p], [x_dot], ["x", "u", "p"], ["x_dot"]),
                _AttitudeGuard(name) if dof == 6 else None),
        tau=check(ca.Function("tau", [eta, nu, u, *env], [tau], ["eta", "nu", "u", *env_names], ["tau"])),
        h=check(ca.Function("h", [eta, nu], [h_still], ["eta", "nu"], ["h"])),
        B=check(ca.Function("B", [eta, nu, u, *env], [ca.jacobian(tau, u)], ["eta", "nu", "u", *env_names], ["B"])),
        actuator_rate=check(ca.Function("actuator_rate", [u, u_cmd], [eq.actuator_rate(u, u_cmd)],
                                        ["u", "u_cmd"], ["u_dot"])),
        terms=check(ca.Function("terms", [eta, nu, *env], list(terms.values()), ["eta", "nu", *env_names],
                                list(terms))),
        term_names=tuple(terms),
    )


@dataclass(frozen=True)
class _AttitudeGuard:
    """A guard for ``f(x, u, p)`` of a 6-DOF model: KinematicsError where eta' = J(eta) nu is
    singular (theta = +-90 deg, :func:`~uvsym.kinematics.Tzyx`), which would otherwise give 1e15.
    A class rather than a closure, so that a Model still pickles."""

    name: str

    def __call__(self, values: dict) -> None:
        x = values["x"]
        phi, theta = x[3:5] if x.size > 4 else (x[0], x[0])
        if abs(math.cos(theta)) > 1e-6:  # far from it: Tzyx (CasADi on numbers) only decides near it
            return
        try:
            Tzyx(phi, theta)
        except KinematicsError as exc:
            raise KinematicsError(f"{self.name}.f: x entry theta: {exc}") from None
