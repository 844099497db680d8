"""Claims about an estimator's error dynamics ``e' = g(e, x, u, d, p)`` (an Observer's ``error_dynamics``).

For an output-injection observer of a plant ``x' = f(x, u, d, p), y = h(x, u, p)`` with gain L:

- ``linearisation_claim``: the derived error dynamics' Jacobian at ``e = 0``, ``d = 0`` equals
  ``df/dx - L dh/dx`` for every x, u, p (an identity: what the gain was designed for is what
  the observer runs);
- ``linear_decay_claim``: the Jacobian of the observer's own error dynamics at ``e = 0`` and an
  operating point decays at rate ``decay`` (LMI, re-checked in exact rationals; by Lyapunov's
  indirect method the error converges locally);
- ``sampled_decay_claim``: the observer's sampled step, linearised at the operating point,
  contracts (discrete Lyapunov inequality, exact re-check): the continuous design survives the
  sample period;
- ``region_decay_claim``: with the true state at an equilibrium x0, ``V = e^T P e`` (P checked
  positive definite, exactly) satisfies ``V' <= -gamma e^T e`` for every e in a box, on the
  nonlinear error dynamics (interval branch-and-bound).

The branch-and-bound needs ``e' = 0`` exactly at ``e = 0`` in floating point, which
``f(x0) - f(x0 - e)`` is not (two roundings of f(x0)). Where the error dynamics are built from
``+``, ``-``, ``*``, squares and constants only (a polynomial) of degree <= 2 in e, they are replaced by their
exact expansion ``e' = J e + 1/2 e^T H e`` (J, H at e = 0, in doubles), which is zero at e = 0 in
any arithmetic; ``e'(0) = 0`` is proved first, and the certificate's method says so.
"""

from __future__ import annotations

from dataclasses import replace
from fractions import Fraction

import casadi as ca
import numpy as np

from uvsym.errors import VerificationError
from uvsym.verify.certificate import Certificate
from uvsym.verify.identity import prove_identity
from uvsym.verify.lyapunov import discrete_lyapunov_decrease, exact_positive_definite, lyapunov_decrease
from uvsym.verify.region import region_decrease

__all__ = ["linearisation_claim", "linear_decay_claim", "region_decay_claim", "sampled_decay_claim"]

POLYNOMIAL_OPS = {ca.OP_INPUT, ca.OP_OUTPUT, ca.OP_CONST, ca.OP_ASSIGN, ca.OP_ADD, ca.OP_SUB, ca.OP_MUL, ca.OP_NEG,
                  ca.OP_SQ, ca.OP_TWICE}
EQUILIBRIUM_TOLERANCE = 1e-9  # |f(x0, u0)| relative to the size of its terms


def _quadratic_form(e_dot: ca.SX, e: ca.SX) -> ca.SX | None:
    """``J e + 1/2 [e^T H_i e]_i`` at e = 0 when e_dot is a polynomial of degree <= 2 in e, else None."""
    graph = ca.Function("graph", [e], [e_dot])
    if any(graph.instruction_id(k) not in POLYNOMIAL_OPS for k in range(graph.n_instructions())):
        return None
    J = ca.jacobian(e_dot, e)
    second = ca.jacobian(ca.vec(J), e)
    if ca.jacobian(ca.vec(second), e).nnz() > 0:
        return None
    zero = ca.DM.zeros(e.numel())
    linear = ca.mtimes(ca.evalf(ca.substitute(J, e, zero)), e)
    # vec(J) stacks columns, so row i n + j of `second` is d/de of J[j, i]: rows i n + j (i = 0..n-1)
    # make the Hessian of e_dot_j
    H, n = ca.evalf(ca.substitute(second, e, zero)), e.numel()
    return ca.vertcat(*[linear[j] + 0.5 * ca.bilin(H[[i * n + j for i in range(n)], :], e, e) for j in range(n)])


def _error_dynamics(observer) -> ca.Function:
    g = observer.error_dynamics
    if g is None or tuple(g.name_in()) != ("e", "x", "u", "d", "p"):
        raise VerificationError(f"{observer.name}: needs error_dynamics (e, x, u, d, p) -> e_dot, "
                                f"got {None if g is None else g.name_in()}")
    return g


def _point(plant, x0, u0) -> tuple[np.ndarray, np.ndarray, str]:
    """(x0, u0, its description); VerificationError unless the plant is at rest there (d = 0, p = p0)."""
    x0 = plant.x.vector(plant.x_op if x0 is None else x0, "x0")
    u0 = plant.u.vector(plant.u_op if u0 is None else u0, "u0")
    lin = plant.linearize(x0, u0)
    moving = [n for n, m in zip(plant.x.names, lin.moving(EQUILIBRIUM_TOLERANCE)) if m]
    if moving:
        raise VerificationError(f"{plant.name}: the point is not an equilibrium ({', '.join(moving)} move): the true "
                                "state would not stay there")
    where = ", ".join(f"{n} = {v:.6g}" for n, v in zip(plant.x.names, x0))
    inputs = ", ".join(f"{n} = {v:.6g}" for n, v in zip(plant.u.names, u0))
    return x0, u0, f"true state at the equilibrium {where}; {inputs}; d = 0, p = p0"


def linearisation_claim(observer, plant, L, expected: str = "proved") -> Certificate:
    """``d e'/d e (e = 0, d = 0) = df/dx - L dh/dx`` for all x, u, p (see the module docstring)."""
    g = _error_dynamics(observer)
    e, x, u, p = (ca.SX.sym(a, s.size) for a, s in (("e", plant.x), ("x", plant.x), ("u", plant.u), ("p", plant.p)))
    d0 = ca.DM.zeros(plant.d.size)
    derived = ca.substitute(ca.jacobian(g(e, x, u, d0, p), e), e, ca.DM.zeros(plant.x.size))
    designed = ca.jacobian(plant.f(x, u, d0, p), x) - ca.mtimes(ca.DM(L), ca.jacobian(plant.h(x, u, p), x))
    return prove_identity(f"{observer.name} on {plant.name}: linearised error dynamics are A(x, u) - L C(x, u)",
                          ca.vec(derived), ca.vec(designed), [x, u, p], "all x, u, p; e = 0, d = 0", expected)


def linear_decay_claim(observer, plant, decay: float, x0=None, u0=None, expected: str = "proved") -> Certificate:
    """``V = e^T P e`` with ``V' <= -2 decay V`` for the observer's own error dynamics linearised at
    ``e = 0`` and the equilibrium (x0, u0) (default the operating point)."""
    g = _error_dynamics(observer)
    x0, u0, where = _point(plant, x0, u0)
    e = ca.SX.sym("e", plant.x.size)
    A_cl = np.asarray(ca.evalf(ca.substitute(ca.jacobian(g(e, x0, u0, ca.DM.zeros(plant.d.size), plant.p0), e), e,
                                             ca.DM.zeros(plant.x.size))))
    return lyapunov_decrease(f"{observer.name} on {plant.name}: linearised error decays at rate {decay:g} 1/s",
                             [A_cl], decay, f"e near 0, {where}", expected)


def sampled_decay_claim(observer, plant, rho: float = 1.0, x0=None, u0=None, expected: str = "proved") -> Certificate:
    """The observer's step, linearised in its state at the equilibrium (x0, u0) with y = h(x0, u0),
    contracts: spectral radius < rho, shown by a discrete Lyapunov certificate (the error of an
    estimate of x obeys this map to first order when the plant moves as the observer's model)."""
    if observer.state.size != plant.x.size:
        raise VerificationError(f"{observer.name}: its state ({observer.state.size}) is not an estimate of "
                                f"{plant.name}'s {plant.x.size} states")
    x0, u0, where = _point(plant, x0, u0)
    s = ca.SX.sym("s", plant.x.size)
    y0 = plant.h(x0, u0, plant.p0)
    s_next = observer.step(s, y0, u0, observer.p0)[0]
    Ad = np.asarray(ca.evalf(ca.substitute(ca.jacobian(s_next, s), s, ca.DM(x0))))
    return discrete_lyapunov_decrease(f"{observer.name} on {plant.name}, sampled every {observer.dt:g} s: the error "
                                      f"map contracts (spectral radius < {rho:g})", Ad, rho, where, expected)


def region_decay_claim(observer, plant, P, gamma: float, half_widths, cube: float, x0=None, u0=None,
                       expected: str = "proved") -> Certificate:
    """``V = e^T P e``, ``V' <= -gamma e^T e`` for every ``|e_i| <= half_widths_i`` on the nonlinear
    error dynamics with the true state at the equilibrium ``x0`` (default the operating point),
    inputs ``u0``, d = 0, p = p0. VerificationError unless P is symmetric positive definite
    (checked exactly) and (x0, u0) is an equilibrium."""
    g = _error_dynamics(observer)
    P = np.asarray(P, dtype=float)
    half = np.asarray(half_widths, dtype=float).ravel()
    if P.shape != (plant.x.size,) * 2 or half.size != plant.x.size:
        raise VerificationError(f"P must be {plant.x.size}x{plant.x.size} and the box have {plant.x.size} entries")
    P = 0.5 * (P + P.T)
    if not exact_positive_definite([[Fraction(float(v)) for v in row] for row in P])[0]:
        raise VerificationError(f"P must be positive definite for V = e'Pe to measure the error; it is not "
                                f"(eigenvalues {np.round(np.linalg.eigvalsh(P), 6).tolist()})")
    x0, u0, where = _point(plant, x0, u0)
    e = ca.SX.sym("e", plant.x.size)
    e_dot = g(e, x0, u0, ca.DM.zeros(plant.d.size), plant.p0)
    quadratic = _quadratic_form(e_dot, e)
    if quadratic is not None:
        x, u, p = (ca.SX.sym(a, s.size) for a, s in (("x", plant.x), ("u", plant.u), ("p", plant.p)))
        at_zero = g(ca.DM.zeros(plant.x.size), x, u, ca.DM.zeros(plant.d.size), p)
        zero = prove_identity("e' = 0 at e = 0, d = 0", at_zero, ca.DM.zeros(plant.x.size), [x, u, p], "all x, u, p")
        if zero.status != "proved":
            raise VerificationError(f"{observer.name}: its error dynamics are not 0 at e = 0 ({zero.status})")
        e_dot = quadratic
    labels = tuple(f"e_{name} ({unit})" for name, unit in zip(plant.x.names, plant.x.units))
    box = ", ".join(f"|e_{n}| <= {h:g} {u}" for n, h, u in zip(plant.x.names, half, plant.x.units))
    certificate = region_decrease(f"{observer.name} on {plant.name}: V = e'Pe, V' <= -{gamma:g} e'e (nonlinear error "
                                  "dynamics)", ca.bilin(ca.DM(P), e, e), e_dot, e, gamma, -half, half, cube,
                                  labels=labels, set_description=f"{box}; {where}", expected=expected)
    if quadratic is None:
        return certificate
    return replace(certificate, method=f"{certificate.method}; e' as its exact quadratic expansion (polynomial of "
                                       "degree <= 2 in e, e'(0) = 0 proved in exact rationals)")
