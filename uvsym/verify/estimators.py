"""Claims about an estimator's error dynamics ``e' = g(e, x, u, d, p)`` (an Observer's ``error_dynamics``).

For an output-injection observer of a plant ``x' = f(x, u, d, p), y = h(x, u, p)`` with gain L:

- ``linearisation_claim``: the derived error dynamics' Jacobian at ``e = 0``, ``d = 0`` equals
  ``df/dx - L dh/dx`` for every x, u, p (an identity: what the gain was designed for is what
  the observer runs);
- ``linear_decay_claim``: ``A - L C`` at an operating point decays at rate ``decay``
  (LMI, re-checked in exact rationals; Lyapunov's indirect method gives local convergence);
- ``region_decay_claim``: with the true state at the operating point, ``V = e^T P e`` satisfies
  ``V' <= -gamma e^T e`` for every e in a box, on the nonlinear error dynamics (interval
  branch-and-bound: a rigorous region of attraction estimate, not only a linearisation).

The branch-and-bound needs ``e' = 0`` exactly at ``e = 0`` in floating point, which
``f(x0) - f(x0 - e)`` is not (two roundings of f(x0)). Where the error dynamics are a polynomial
of degree <= 2 in e (bilinear plants: the third derivative is structurally zero), they are
replaced by their exact expansion ``e' = J e + 1/2 e^T H e`` (J, H at e = 0, in doubles), which is
zero at e = 0 in any arithmetic; ``e'(0) = 0`` itself is proved first as a symbolic identity.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from uvsym.errors import VerificationError
from uvsym.verify.certificate import Certificate
from uvsym.verify.identity import prove_identity
from uvsym.verify.lyapunov import lyapunov_decrease
from uvsym.verify.region import region_decrease

__all__ = ["linearisation_claim", "linear_decay_claim", "region_decay_claim"]


def _quadratic_form(e_dot: ca.SX, e: ca.SX) -> ca.SX | None:
    """``J e + 1/2 [e^T H_i e]_i`` at e = 0 when e_dot is a polynomial of degree <= 2 in e, else None."""
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


def linearisation_claim(observer, plant, L, expected: str = "proved") -> Certificate:
    """``d e'/d e (e = 0, d = 0) = df/dx - L dh/dx`` for all x, u, p (see the module docstring)."""
    g = _error_dynamics(observer)
    e, x, u, p = (ca.SX.sym(a, s.size) for a, s in (("e", plant.x), ("x", plant.x), ("u", plant.u), ("p", plant.p)))
    d0 = ca.DM.zeros(plant.d.size)
    derived = ca.substitute(ca.jacobian(g(e, x, u, d0, p), e), e, ca.DM.zeros(plant.x.size))
    designed = ca.jacobian(plant.f(x, u, d0, p), x) - ca.mtimes(ca.DM(L), ca.jacobian(plant.h(x, u, p), x))
    return prove_identity(f"{observer.name} on {plant.name}: linearised error dynamics are A(x, u) - L C(x, u)",
                          ca.vec(derived), ca.vec(designed), [x, u, p], "all x, u, p; e = 0, d = 0", expected)


def linear_decay_claim(observer, lin, L, decay: float, expected: str = "proved") -> Certificate:
    """``V = e^T P e`` with ``V' <= -2 decay V`` for ``e' = (A - L C) e`` at the linearisation ``lin``."""
    A_cl = lin.A - np.asarray(L, dtype=float) @ lin.C
    return lyapunov_decrease(f"{observer.name}: e' = (A - L C) e decays at rate {decay:g} 1/s", [A_cl], decay,
                             "A, C at the operating point", expected)


def region_decay_claim(observer, plant, P, gamma: float, half_widths, cube: float, x0=None, u0=None,
                       expected: str = "proved") -> Certificate:
    """``V = e^T P e``, ``V' <= -gamma e^T e`` for every ``|e_i| <= half_widths_i`` on the nonlinear
    error dynamics with the true state at ``x0`` (default the operating point), inputs ``u0``, d = 0."""
    g = _error_dynamics(observer)
    P = np.asarray(P, dtype=float)
    half = np.asarray(half_widths, dtype=float).ravel()
    if P.shape != (plant.x.size,) * 2 or half.size != plant.x.size:
        raise VerificationError(f"P must be {plant.x.size}x{plant.x.size} and the box have {plant.x.size} entries")
    x0 = plant.x.vector(plant.x_op if x0 is None else x0, "x0")
    u0 = plant.u.vector(plant.u_op if u0 is None else u0, "u0")
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
    return region_decrease(f"{observer.name} on {plant.name}: V = e'Pe, V' <= -{gamma:g} e'e (nonlinear, true "
                           "state at the operating point)", ca.bilin(ca.DM(P), e, e), e_dot, e, gamma, -half, half,
                           cube, labels=labels, expected=expected)
