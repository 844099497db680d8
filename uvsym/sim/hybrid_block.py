"""The ``hybrid`` block of scenario files: the hybrid unknown-input / adaptive observer
(:mod:`uvsym.observers.hybrid`, Yu, Jiang & Zhang 2018, eqs. 5-6 and 17-18) designed from a table.

Fields (besides ``type`` and ``name``):

- ``model``: a registered plant (``uvsym models``) the observer is designed on, with the same
  inputs and outputs as the scenario's plant (e.g. the plant without the disturbance schedule the
  scenario drives through its own ``d``); default the scenario's plant. Its linearisation at the
  operating point gives A, C and the disturbance directions E that subsystem 1 decouples;
- ``z1``, ``w1``: subsystem 1's states and outputs (the others are subsystem 2's), checked by
  :func:`~uvsym.observers.hybrid.decouple` (no unknown-input observer for them: an error naming
  ``w1``);
- ``sensor``, ``sensor_gain``: the output of subsystem 2 whose fault ``f`` the observer is built
  for (it reads ``y + sensor_gain f``; gain default 1);
- ``k1``: subsystem 1's gain (n1 x p1; a number k stands for ``k C1^T``: each residual injected into
  the states it measures), or ``decay`` (1/s): K1 from the block LMI of Theorem 1 for
  ``Tu A11 - K1 C1`` (refused, naming ``decay``, when the LMI has no solution);
- ``l``: subsystem 2's gain (n2 x p2; a number l stands for ``l C4^T``), default 0;
- ``gamma``, ``m1``, ``m2`` (q x q, q x p2, q x p2; all three or none): the adaptive fault estimator
  of eq. 18; with them the block also publishes ``f_<sensor>_hat`` (f, not the sensor's offset);
- ``x0``: the estimate the observer starts at (a list in the states' order, or a table state =
  value, others at the operating point); default the operating point.

The linearised error (:func:`~uvsym.observers.hybrid.linear_error_model`) must not grow: an
eigenvalue with a positive real part is refused naming ``k1`` (subsystem 1's error alone grows) or
``l`` (the coupled error grows). Marginal modes (the estimator's
zero mode, subsystem-1 modes C1 cannot see) are accepted, as the paper's design has them.
"""

from __future__ import annotations

import numpy as np

from uvsym.errors import ObserverError, ScenarioError
from uvsym.sim.blocks import Block, observer_block
from uvsym.sim.fields import Fields
from uvsym.systems.signals import signals
from uvsym.systems.system import System

__all__ = ["hybrid_block"]

GROWTH_TOLERANCE = 1e-9  # relative to the largest |eigenvalue|: real parts above it grow


def _model(fields: Fields, plant: System) -> System:
    """The plant the observer is designed on (module docstring)."""
    from uvsym.systems.registry import plant as registered
    from uvsym.systems.registry import plant_names

    name = fields.raw("model", None, "string", "registered plant the observer is designed on (default: the scenario's)")
    if name is None:
        return plant
    if not isinstance(name, str) or name not in plant_names():
        raise ScenarioError(f"{fields._name('model')}: unknown plant {name!r}; known: {', '.join(plant_names())}")
    model = registered(name)
    if model.y.names != plant.y.names or model.u.names != plant.u.names:
        raise ScenarioError(f"{fields._name('model')}: {name} reads outputs {list(model.y.names)} and inputs "
                            f"{list(model.u.names)}; the scenario's plant has {list(plant.y.names)} and "
                            f"{list(plant.u.names)}")
    return model


def _gain(fields: Fields, key: str, C: np.ndarray, default=None) -> np.ndarray:
    """A gain (C.shape[1] x C.shape[0]): a full matrix, or a number k for ``k C^T``."""
    from uvsym.sim.catalogue import _matrix

    value = fields.data.get(key, default)
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        fields.raw(key, default, "number or matrix", "states x outputs of the subsystem, or k for k C^T")
        if not np.isfinite(value):
            raise ScenarioError(f"{fields._name(key)}: expected a finite number, got {value!r}")
        return float(value) * C.T
    return _matrix(fields, key, (C.shape[1], C.shape[0]), "states x outputs of the subsystem", default,
                   diagonal=False)


def _k1(fields: Fields, dec, name: str) -> np.ndarray:
    """K1 from ``k1`` or from the block LMI at ``decay`` (module docstring)."""
    if not fields.has("decay"):
        return _gain(fields, "k1", dec.C1)
    from uvsym.verify.lmi import block_lmi, solve_block_lmi

    decay = fields.number("decay", positive=True)
    gains, certificate = solve_block_lmi(block_lmi(dec.exact["Omega1"], [("e", dec.exact["C1"])], decay),
                                         f"{name}: Tu A11 - K1 C1 decays at {decay:g} 1/s")
    if gains is None:
        raise ScenarioError(f"{fields._name('decay')}: no K1 makes subsystem 1's error decay at {decay:g} 1/s "
                            f"(block LMI {certificate.status}"
                            + (f"; modes C1 cannot see: {', '.join(f'{v:.4g}' for v in dec.undetectable)}"
                               if dec.undetectable else "") + ")")
    return gains.K[0]


def _estimator(fields: Fields, q: int, p2: int):
    """The FaultEstimator of ``gamma``, ``m1``, ``m2``, or None without them."""
    from uvsym.observers.hybrid import FaultEstimator
    from uvsym.sim.catalogue import _matrix

    given = [key for key in ("gamma", "m1", "m2") if fields.has(key)]
    if not given:
        for key in ("gamma", "m1", "m2"):
            fields.raw(key, None, "matrix", "fault estimator (eq. 18): all three or none")
        return None
    if len(given) < 3 or q == 0:
        missing = sorted({"gamma", "m1", "m2", *(() if q else ("sensor",))} - set(given))
        raise ScenarioError(f"{fields.path}: the fault estimator needs gamma, m1, m2 and sensor; missing "
                            f"{', '.join(missing)}")
    return FaultEstimator(_matrix(fields, "gamma", (q, q), "faults x faults"),
                          _matrix(fields, "m1", (q, p2), "faults x outputs of subsystem 2", diagonal=False),
                          _matrix(fields, "m2", (q, p2), "faults x outputs of subsystem 2", diagonal=False))


def _start(fields: Fields, model: System, dec, q: int) -> np.ndarray | None:
    """The observer's state for the estimate ``x0`` (module docstring), None without it."""
    from uvsym.observers.hybrid import observer_state
    from uvsym.sim.system_scenario import _point

    if not fields.has("x0"):
        fields.raw("x0", None, "list or table", "the starting estimate (default: the operating point)")
        return None
    xhat = _point(fields, "x0", model.x, model.x_op)
    return observer_state(dec, xhat, model.linearize().C, q)


def hybrid_block(fields: Fields, plant: System, dt: float, name: str) -> Block:
    """The ``hybrid`` block (module docstring) sampled every ``dt`` s; ScenarioError naming the field."""
    from uvsym.observers.hybrid import decouple, hybrid_observer, linear_error_model  # sympy: only when used
    from uvsym.sim.catalogue import _names

    model = _model(fields, plant)
    lin = model.linearize()
    z1, w1 = _names(fields, "z1"), _names(fields, "w1")
    sensor = fields.raw("sensor", None, "string", "output of subsystem 2 the fault acts on")
    gain = fields.number("sensor_gain", 1.0)
    if sensor is not None and sensor not in model.y.names:
        raise ScenarioError(f"{fields._name('sensor')}: {sensor!r} is not an output of {model.name} "
                            f"({', '.join(model.y.names)})")
    F = np.zeros((model.y.size, 0 if sensor is None else 1))
    if sensor is not None:
        F[model.y.index(sensor), 0] = gain
    try:
        dec = decouple(model, lin, z1=list(z1), w1=list(w1), F=F)
    except ObserverError as exc:
        raise ScenarioError(f"{fields._name('w1')}: {exc}") from None
    K1 = _k1(fields, dec, name)
    if not dec.iz2 and fields.has("l"):
        raise ScenarioError(f"{fields._name('l')}: z1 holds every state, so there is no subsystem 2 to gain")
    L = _gain(fields, "l", dec.C4, 0.0) if dec.iz2 else np.zeros((0, len(dec.iw2)))
    estimator = _estimator(fields, F.shape[1], len(dec.iw2))
    faults = signals((f"f_{sensor}", model.y.units[model.y.index(sensor)], f"fault of sensor {sensor}"),
                     group="fault") if estimator is not None else None
    try:
        obs = hybrid_observer(model, dec, K1, L, dt, estimator=estimator, faults=faults, name=name)
        error = linear_error_model(dec, K1, L, estimator)
    except ObserverError as exc:
        raise ScenarioError(f"{fields._name('k1')}: {exc}") from None
    n1 = len(dec.iz1)
    for key, A in (("k1", error.A[:n1, :n1]), ("l", error.A)):  # subsystem 1's error alone, then the whole
        eig = np.linalg.eigvals(A)
        if eig.size and np.max(eig.real) > GROWTH_TOLERANCE * max(1.0, float(np.max(np.abs(eig)))):
            raise ScenarioError(f"{fields._name(key)}: with these gains the observer's error grows (eigenvalue "
                                f"{eig[np.argmax(eig.real)]:.4g} 1/s of the linearised error)")
    q = F.shape[1] if estimator is not None else 0
    return observer_block(obs, s0=_start(fields, model, dec, len(dec.iw2) if q else 0))
