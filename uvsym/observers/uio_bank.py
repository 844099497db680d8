"""A bank of discrete unknown-input observers with zonotope thresholds (generalised observer scheme).

Observer i decouples the disturbance directions D and actuator i's column ``B_i`` (Yang, Hu &
Zhang, eq. 26): its residual ignores a fault on actuator i and reacts to a fault on any other.
With ``y = C x + v``, ``|v_j| <= vbar_j`` and ``|e_0,j| <= ebar_j`` (module :mod:`uvsym.observers.uio`),
the joint vector ``xi_k = [e_k; v_k]`` obeys

    xi_{k+1} = [[F, -K1], [0, 0]] xi_k + [[-Q], [I]] v_{k+1},        r_k = [C  I] xi_k,

so the measurement noise of a sample is one generator shared by the error and the residual
(eqs. 30-32 with the correlation kept). :func:`residual_bands` propagates these zonotopes
(:func:`uvsym.sets.propagate`); a residual outside its band's interval hull is an alarm
(:func:`outside_band`), and the observers that stay inside name the faulty actuator
(:func:`isolate`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from uvsym.errors import ObserverError, SetError
from uvsym.observers.base import Observer
from uvsym.observers.uio import UIOMatrices, _matrix, uio_matrices, uio_observer
from uvsym.sets import Propagation, Zonotope, propagate
from uvsym.sets.zonotope import finite_matrix
from uvsym.systems.signals import Signals

__all__ = ["UIOBank", "decision_limits", "isolate", "outside_band", "residual_bands", "residual_recursion",
           "uio_bank"]


@dataclass(frozen=True)
class UIOBank:
    """designs and observers, one per decoupled actuator (named in ``decoupled``), in input order."""

    designs: tuple[UIOMatrices, ...]
    observers: tuple[Observer, ...]
    decoupled: tuple[str, ...]


def uio_bank(A, B, C, D, poles, *, states: Signals, outputs: Signals, inputs: Signals, dt: float,
             name: str = "uio") -> UIOBank:
    """One discrete UIO per input i of B (n, m), decoupling ``[D B_i]``, F's eigenvalues at ``poles``.

    Observer i is named ``<name>_<input name>``. Raises UIOConditionError when an observer does
    not exist (the message names the actuator), ObserverError for sizes or non-numeric B, D (D (n,) is one
    direction)."""
    B = _matrix(B, "B")
    D = _matrix(np.reshape(D, (-1, 1)) if np.ndim(D) == 1 else D, "D", rows=B.shape[0])
    if B.shape[1] != inputs.size:
        raise ObserverError(f"{name}: B has {B.shape[1]} columns but {inputs.size} inputs are named")
    designs, observers = [], []
    for i, actuator in enumerate(inputs.names):
        try:
            design = uio_matrices(A, B, C, np.hstack([D, B[:, [i]]]), poles=poles)
        except ObserverError as exc:
            exc.args = (f"{name}, observer decoupling {actuator}: {exc}",)
            raise
        designs.append(design)
        observers.append(uio_observer(design, states=states, outputs=outputs, inputs=inputs, dt=dt,
                                      name=f"{name}_{actuator}"))
    return UIOBank(tuple(designs), tuple(observers), tuple(inputs.names))


def residual_recursion(design: UIOMatrices, noise_bound, error_bound) -> tuple:
    """``(A, C, initial, noise)`` of the healthy residual's recursion (module docstring): A (n + p, n + p),
    C (p, n + p) and the initial and noise zonotopes of ``xi = [e; v]``.

    noise_bound: (p,) vbar (in the outputs' units); error_bound: (n,) ebar of the initial error.
    Raises SetError for a bound that is not finite and non-negative or of the wrong size."""
    n, p = design.F.shape[0], design.C.shape[0]
    vbar = finite_matrix(noise_bound, "noise bound", (p,))
    ebar = finite_matrix(error_bound, "initial error bound", (n,))
    for what, bound in (("noise bound", vbar), ("initial error bound", ebar)):
        if np.any(bound < 0):
            raise SetError(f"{what} must be non-negative, got {bound.tolist()}")
    V = np.diag(vbar)
    A = np.block([[design.F, -design.K1], [np.zeros((p, n + p))]])
    noise = Zonotope(np.zeros(n + p), np.vstack([-design.Q @ V, V]))
    initial = Zonotope(np.zeros(n + p), np.block([[np.diag(ebar), np.zeros((n, p))], [np.zeros((p, n)), V]]))
    return A, np.hstack([design.C, np.eye(p)]), initial, noise


def residual_bands(design: UIOMatrices, noise_bound, error_bound, steps: int, generators: int,
                   method: str = "girard", growth_limit: float = 10.0, track: bool = True) -> Propagation:
    """Zonotopes of the healthy residual ``r_k``, k = 0 .. steps - 1, of :func:`residual_recursion`.

    track: keep the reductions' coefficient maps (see :func:`uvsym.sets.carry_coefficients`).
    Raises SetError for a bad bound (:func:`residual_recursion`), SetDivergenceError when the
    enclosure grows (an unstable F, or reduction wrapping)."""
    return propagate(*residual_recursion(design, noise_bound, error_bound), steps, generators, method, growth_limit,
                     track)


def outside_band(residuals, bands: Propagation, tolerance: float = 1e-12) -> np.ndarray:
    """(N,) or (N, runs) booleans: some entry of ``r_k`` lies outside its band's interval hull.

    residuals: (N, p) or (N, p, runs), N at most the bands' length. SetError for entries that are not numbers
    or the wrong shape. tolerance: a bound counts as exceeded only beyond ``tolerance * (1 + width)`` of its band."""
    try:
        r = np.asarray(residuals, dtype=float)
    except (TypeError, ValueError):
        raise SetError(f"residuals must be numbers in an (N, p[, runs]) array, got {residuals!r:.60}") from None
    if r.ndim not in (2, 3) or r.shape[0] > len(bands.lower) or r.shape[1] != bands.lower.shape[1]:
        raise SetError(f"residuals must be (N, {bands.lower.shape[1]}[, runs]) with N <= {len(bands.lower)}, "
                       f"got {r.shape}")
    lower, upper = decision_limits(bands, tolerance)
    lower, upper = lower[:len(r)], upper[:len(r)]
    if r.ndim == 3:
        lower, upper = lower[..., None], upper[..., None]
    return np.any((r < lower) | (r > upper), axis=1)


def decision_limits(bands: Propagation, tolerance: float = 1e-12) -> tuple[np.ndarray, np.ndarray]:
    """(N, p) lowest and highest residual :func:`outside_band` lets pass: each hull bound moved out by
    ``tolerance * (1 + width)`` (floats, as the decision compares them)."""
    slack = tolerance * (1.0 + np.abs(bands.upper - bands.lower))
    return bands.lower - slack, bands.upper + slack


def isolate(outside: np.ndarray, names, start: int, window: int) -> list[str]:
    """The observers (``names``, one per column of ``outside`` (N, n_obs)) whose residual stays
    inside its band on every sample of ``[start, start + window)``."""
    block = np.asarray(outside, dtype=bool)[start:start + window]
    return [name for name, column in zip(names, block.T) if not column.any()]
