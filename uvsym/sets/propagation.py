"""Zonotopes of a linear recursion's outputs, step by step, with bounded order and a growth guard.

For ``xi_{k+1} = A xi_k + w_{k+1}``, ``w_k in W`` (a zonotope), ``xi_0 in X_0``, the outputs
``r_k = C xi_k`` lie in ``C X_k`` with ``X_{k+1} = reduce(A X_k + W)``. Noise that enters two
signals at once (the same measurement noise in an estimation error and in a residual) is one
generator of the joint vector ``xi`` and stays correlated: put both signals in ``xi``.

Guard: a set that keeps growing is an error, not a long run. Before anything runs, a spectral
radius of A >= 1 raises :class:`~uvsym.errors.SetDivergenceError` naming the eigenvalues; while
running, the reduced set's interval-hull radius is compared with the exact (unreduced) set's,
``sum_j |A^j G_W| 1 + |A^k G_0| 1``, and more than ``growth_limit`` times it raises too (the
reduction wraps).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from uvsym.errors import SetDivergenceError, SetError
from uvsym.sets.reduction import reduce
from uvsym.sets.zonotope import Zonotope, finite_matrix

__all__ = ["Propagation", "propagate", "carry_coefficients"]


@dataclass(frozen=True)
class Propagation:
    """outputs: r_k's zonotope per step (N entries); lower, upper: (N, n_r) interval hulls;
    exact_radius: (N, n_r) hull radius of the unreduced output sets; reductions: per step k >= 1,
    the coefficient map R_k of its reduction (``G_before = G_after R_k``; empty unless tracked);
    noise_generators: W's generator count."""

    outputs: list
    lower: np.ndarray
    upper: np.ndarray
    exact_radius: np.ndarray
    reductions: list
    noise_generators: int


def propagate(A, C, initial: Zonotope, noise: Zonotope, steps: int, generators: int, method: str = "girard",
              growth_limit: float = 10.0, track: bool = True) -> Propagation:
    """Output zonotopes ``C X_k``, k = 0 .. steps - 1 (module docstring).

    A (n, n), C (n_r, n); initial, noise: zonotopes in R^n; generators: the order bound of X_k;
    track: keep each reduction's coefficient map (for :func:`carry_coefficients`; else none).

    Raises
    ------
    SetError
        For non-conforming sizes or steps < 1. SetDivergenceError for a spectral radius >= 1 or
        a reduced hull more than ``growth_limit`` times the exact one.
    """
    A = finite_matrix(A, "A", (None, None))
    n = A.shape[0]
    if A.shape != (n, n):
        raise SetError(f"A must be square, got shape {A.shape}")
    C = finite_matrix(C, "C", (None, n))
    for what, z in (("initial", initial), ("noise", noise)):
        if not isinstance(z, Zonotope) or z.dimension != n:
            raise SetError(f"{what} set must be a Zonotope of dimension {n}")
    if isinstance(steps, bool) or not isinstance(steps, int) or steps < 1:
        raise SetError(f"steps must be a positive integer, got {steps!r}")
    eigenvalues = np.linalg.eigvals(A)
    growing = eigenvalues[np.abs(eigenvalues) >= 1.0 - 1e-12]
    if growing.size:
        raise SetDivergenceError(f"the enclosure grows without bound: A has eigenvalues of modulus >= 1: "
                                 f"{np.round(growing, 6).tolist()}")
    X, power = initial, np.eye(n)
    noise_radius = np.zeros(len(C))
    outputs, lower, upper, exact, reductions = [], np.zeros((steps, len(C))), np.zeros((steps, len(C))), \
        np.zeros((steps, len(C))), []
    for k in range(steps):
        if k:
            noise_radius += np.sum(np.abs(C @ power @ noise.generators), axis=1)
            power = A @ power
            step = reduce(X.map(A) + noise, generators, method, coefficients=track)
            X = step.zonotope
            if track:
                reductions.append(step.coefficients)
        out = X.map(C)
        outputs.append(out)
        lower[k], upper[k] = out.interval_hull()
        exact[k] = noise_radius + np.sum(np.abs(C @ power @ initial.generators), axis=1)
        if np.any(upper[k] - out.center > growth_limit * exact[k] + 1e-12 * max(exact[k].max(), 1e-300)):
            worst = int(np.argmax((upper[k] - out.center) / np.maximum(exact[k], 1e-300)))
            raise SetDivergenceError(f"the enclosure grows: at step {k}, output {worst}'s hull radius "
                                     f"{upper[k, worst] - out.center[worst]:.3g} exceeds {growth_limit:g} times the "
                                     f"exact set's {exact[k, worst]:.3g} (reduction wraps; raise generators)")
    return Propagation(outputs, lower, upper, exact, reductions, noise.order)


def carry_coefficients(propagation: Propagation, initial_coefficients, noise_coefficients) -> np.ndarray:
    """Coefficients of sampled points through the reductions: (N, m_k max, runs), zero-padded.

    initial_coefficients (m_0, runs): the points' coefficients in the initial set;
    noise_coefficients (N, n_W, runs): each step's noise coefficients (eta_k of
    ``w_k = c_W + G_W eta_k``). Then ``r_k = center_k + G_k a_k`` for the sampled trajectory, with
    ``||a_k||_inf <= 1`` whenever every input coefficient is.
    """
    if len(propagation.reductions) != len(propagation.outputs) - 1:
        raise SetError("the propagation kept no coefficient maps: propagate it with track=True")
    a = np.asarray(initial_coefficients, dtype=float)
    eta = np.asarray(noise_coefficients, dtype=float)
    widest = max(z.order for z in propagation.outputs)
    out = np.zeros((len(propagation.outputs), widest, a.shape[1]))
    out[0, :a.shape[0]] = a
    for k, R in enumerate(propagation.reductions, start=1):
        a = R @ np.vstack([a, eta[k]])
        out[k, :a.shape[0]] = a
    return out
