"""Unknown-input observer (Chen & Patton 1999, sec. 3.2 continuous, 3.6 discrete; Yang, Hu & Zhang eq. 20).

For ``x+ = A x + B u + D d`` (x+ the next sample, or x' in continuous time), ``y = C x`` with an
unknown input d, the observer

    z+ = F z + J u + K y,        xhat = z + Q y,        r = y - C xhat

with ``T = I - Q C``, ``A1 = T A``, ``F = A1 - K1 C``, ``J = T B``, ``K = K1 + F Q`` and
``Q = D M``, ``M = (C D)^+`` (so ``M C D = I``), has the error dynamics ``e+ = F e`` whatever d
is, because ``T D = (I - Q C) D = 0``. It exists iff

1. ``rank(C D) = rank(D)`` (d can be reconstructed from y), and
2. ``(C, A1)`` is detectable: every eigenvalue of A1 with ``|lambda| >= 1`` (discrete) or
   ``Re lambda >= 0`` (continuous) is observable, ``rank([A1 - lambda I; C]) = n``.

:func:`uio_conditions` checks both and gives Q, T, A1; :func:`uio_matrices` adds the gain K1
(pole placement, or given, e.g. from an LMI) and the rest. Both are independent of any plant
object or time step. :func:`uio_observer` makes the discrete design an
:class:`~uvsym.observers.base.Observer`.

With bounded measurement noise, ``y = C x + v``, the discrete error obeys
``e_{k+1} = F e_k - K1 v_k - Q v_{k+1}`` and the residual ``r_k = C e_k + v_k``.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import casadi as ca
import numpy as np
from scipy.signal import place_poles

from uvsym.errors import ObserverError, UIOConditionError
from uvsym.observers.base import Observer, check_name, observer
from uvsym.systems.signals import Signals

__all__ = ["TIME_DOMAINS", "UIOMatrices", "uio_conditions", "uio_matrices", "uio_observer", "unobservable_modes"]

TIME_DOMAINS = ("discrete", "continuous")
RANK_TOLERANCE = 1e-9  # relative to the largest singular value
STABILITY_MARGIN = 1e-9  # |lambda| >= 1 - margin (discrete) or Re lambda >= -margin counts as not stable


@dataclass(frozen=True)
class UIOMatrices:
    """The UIO of the module docstring: M (q, p) with ``M C D = I``; Q (n, p); T, A1, F (n, n);
    K1, K (n, p); J (n, m); C (p, n); D (n, q) the decoupled directions; eigenvalues of F."""

    M: np.ndarray
    Q: np.ndarray
    T: np.ndarray
    A1: np.ndarray
    K1: np.ndarray
    F: np.ndarray
    J: np.ndarray
    K: np.ndarray
    C: np.ndarray
    D: np.ndarray
    time: str
    eigenvalues: np.ndarray


def _matrix(value, what: str, rows: int | None = None, cols: int | None = None) -> np.ndarray:
    try:
        M = np.atleast_2d(np.asarray(value, dtype=float))
    except (TypeError, ValueError):
        raise ObserverError(f"UIO: {what} must be a numeric matrix, got {type(value).__name__}") from None
    if M.ndim != 2 or (rows is not None and M.shape[0] != rows) or (cols is not None and M.shape[1] != cols):
        raise ObserverError(f"UIO: {what} must be a ({rows if rows is not None else 'any'}, "
                            f"{cols if cols is not None else 'any'}) matrix, got shape {M.shape}")
    if not np.all(np.isfinite(M)):
        raise ObserverError(f"UIO: {what} must be finite (no NaN or infinity)")
    return M


def _square(A) -> np.ndarray:
    """A as an (n, n) float matrix; ObserverError naming A otherwise."""
    A = _matrix(A, "A")
    rows, cols = A.shape
    if rows != cols:
        raise ObserverError(f"UIO: A must be square, got shape {A.shape}")
    return A


def _check_time(time: str) -> None:
    if time not in TIME_DOMAINS:
        raise ObserverError(f"UIO: unknown time domain {time!r}; known: {', '.join(TIME_DOMAINS)}")


def _rank(M: np.ndarray) -> int:
    s = np.linalg.svd(M, compute_uv=False)
    return int(np.sum(s > RANK_TOLERANCE * max(1.0, s[0] if s.size else 0.0)))


def _unstable(eigenvalue: complex, time: str) -> bool:
    if time == "discrete":
        return abs(eigenvalue) >= 1.0 - STABILITY_MARGIN
    return eigenvalue.real >= -STABILITY_MARGIN


def unobservable_modes(A, C, time: str = "discrete") -> list[complex]:
    """The eigenvalues of A (n, n) that are unobservable from C (p, n) (PBH test) and not stable in ``time``.

    ObserverError for non-conforming sizes, non-finite entries or an unknown time domain."""
    _check_time(time)
    A = _square(A)
    n = len(A)
    C = _matrix(C, "C", cols=n)
    return [complex(lam) for lam in np.linalg.eigvals(A)
            if _unstable(lam, time) and _rank(np.vstack([A - lam * np.eye(n), C])) < n]


def uio_conditions(A, C, D, time: str = "discrete") -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(M, Q, T, A1) after checking both existence conditions (module docstring).

    A (n, n), C (p, n), D (n, q).

    Raises
    ------
    UIOConditionError
        ``rank(C D) != rank(D)`` (with the ranks) or ``(C, A1)`` not detectable (with the
        unobservable eigenvalues).
    ObserverError
        For non-conforming sizes, non-finite entries or an unknown time domain.
    """
    _check_time(time)
    A = _square(A)
    n = len(A)
    C, D = _matrix(C, "C", cols=n), _matrix(D, "D", rows=n)
    CD = C @ D
    ranks = (_rank(CD), _rank(D))
    if ranks[0] != ranks[1]:
        raise UIOConditionError(f"UIO: rank(C D) = {ranks[0]} but rank(D) = {ranks[1]}: the unknown input cannot "
                                "be decoupled from these outputs", ranks=ranks)
    M = np.linalg.pinv(CD)
    Q = D @ M
    T = np.eye(n) - Q @ C
    A1 = T @ A
    modes = unobservable_modes(A1, C, time)
    if modes:
        where = "|lambda| >= 1" if time == "discrete" else "Re lambda >= 0"
        listed = ", ".join(f"{m.real:.6g}{m.imag:+.3g}j" for m in modes)
        raise UIOConditionError(f"UIO: (C, T A) is not detectable: eigenvalues with {where} unobservable from C: "
                                f"{listed}", ranks=ranks, eigenvalues=modes)
    return M, Q, T, A1


def uio_matrices(A, B, C, D, *, poles=None, K1=None, time: str = "discrete") -> UIOMatrices:
    """The UIO (module docstring) with F's eigenvalues at ``poles`` (n,) or with the gain K1 (n, p).

    Raises
    ------
    UIOConditionError
        When an existence condition fails (see :func:`uio_conditions`).
    ObserverError
        For sizes, for neither or both of poles and K1, poles that are not n finite numbers or cannot
        be placed, or a gain that leaves F unstable (names its eigenvalues).
    """
    M, Q, T, A1 = uio_conditions(A, C, D, time)
    n = A1.shape[0]
    C, D = _matrix(C, "C"), _matrix(D, "D")
    B = _matrix(B, "B", rows=n)
    if (poles is None) == (K1 is None):
        raise ObserverError("UIO: give exactly one of poles (F's eigenvalues) and K1 (the gain)")
    if poles is not None:
        try:
            poles = np.asarray(poles, dtype=complex).ravel()
        except (TypeError, ValueError):
            raise ObserverError(f"UIO: poles must be numbers, got {poles!r}") from None
        if poles.size != n or not np.all(np.isfinite(poles)):
            raise ObserverError(f"UIO: poles must be {n} finite eigenvalues, got {poles.size}")
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # a non-converged placement is caught below by its eigenvalues
                K1 = place_poles(A1.T, C.T, poles).gain_matrix.T
        except (ValueError, np.linalg.LinAlgError) as exc:
            raise ObserverError(f"UIO: poles cannot be placed: {exc}") from None
        placed = np.sort_complex(np.linalg.eigvals(A1 - K1 @ C))
        if not np.allclose(placed, np.sort_complex(poles), atol=1e-6):
            raise ObserverError(f"UIO: poles cannot be placed (placement needs (C, T A) observable, not only "
                                f"detectable); got eigenvalues {np.round(placed, 6).tolist()}: give K1 instead")
    K1 = _matrix(K1, "K1", rows=n, cols=C.shape[0])
    F = A1 - K1 @ C
    eigenvalues = np.linalg.eigvals(F)
    unstable = [complex(lam) for lam in eigenvalues if _unstable(lam, time)]
    if unstable:
        raise ObserverError(f"UIO: F = T A - K1 C is not stable ({time}): eigenvalues "
                            f"{', '.join(f'{v.real:.6g}{v.imag:+.3g}j' for v in unstable)}")
    return UIOMatrices(M=M, Q=Q, T=T, A1=A1, K1=K1, F=F, J=T @ B, K=K1 + F @ Q, C=C, D=D, time=time,
                       eigenvalues=eigenvalues)


def uio_observer(design: UIOMatrices, *, states: Signals, outputs: Signals, inputs: Signals, dt: float,
                 name: str = "uio", prior=None) -> Observer:
    """The discrete UIO as an Observer: state z, reads ``outputs`` and ``inputs`` (loop names),
    publishes ``<state>_hat`` and ``r_<output>``; starts at ``xhat_0 = prior`` (default 0), i.e.
    ``z_0 = prior - Q y_0``.

    Raises ObserverError for a continuous design or signals that do not match its sizes."""
    check_name(name, "observer")
    if design.time != "discrete":
        raise ObserverError(f"{name}: uio_observer runs a discrete design, got a {design.time} one")
    n, p = design.F.shape[0], design.C.shape[0]
    for what, group, size in (("states", states, n), ("outputs", outputs, p), ("inputs", inputs, design.J.shape[1])):
        if group.size != size:
            raise ObserverError(f"{name}: {what} has {group.size} signals, the design {size}")
    x_prior = np.zeros(n) if prior is None else states.vector(prior, f"{name}: prior")
    F, J, K, Q, C = (ca.DM(getattr(design, k)) for k in ("F", "J", "K", "Q", "C"))

    def step(z, y, u, _p):
        xhat = z + ca.mtimes(Q, y)
        return ca.mtimes(F, z) + ca.mtimes(J, u) + ca.mtimes(K, y), ca.vertcat(xhat, y - ca.mtimes(C, xhat))

    return observer(name, step=step, dt=dt, state=states.renamed(prefix="z_", group="state"),
                    reads_y=outputs.renamed(group="measurement"), reads_u=inputs.renamed(group="input"),
                    publishes=states.renamed(suffix="_hat", group="estimate") + outputs.renamed(prefix="r_",
                                                                                               group="residual"),
                    init=lambda y0, u0, p: x_prior - design.Q @ np.asarray(y0, dtype=float),
                    description=f"unknown-input observer decoupling {design.D.shape[1]} direction(s): "
                                "z+ = F z + J u + K y, xhat = z + Q y")
