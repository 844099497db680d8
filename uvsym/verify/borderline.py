"""Borderline claims with known truth, for testing the verifiers' soundness (a generator, seeded).

Each case states a claim and whether it holds, decided independently of the verifier under test:

- :func:`region_cases`: loops ``x_i' = -a_i g(x_i) + b_i x_i^2`` (g the identity, sin, tanh or
  ``exp(x) - 1``), separable, with ``V = x^T x`` and the claim ``V' <= -gamma x^T x`` on a box whose
  edge sits just inside or just outside the point where the decrease fails, at scales from
  1e-170 to 1e160 (polynomial loops), or failing right at the equilibrium (gamma >= 2 a).
  For the polynomial loop ``W_i = x_i^2 (gamma - 2 a_i + 2 b_i x_i)``, so the claim holds exactly
  when ``gamma - 2 a_i + 2 b_i x_i <= 0`` at both ends of every side: decided in exact rationals on
  the double constants. For g = sin, tanh, exp - 1 (b = 0) the ratio ``g(x) / x`` is monotone on
  each side, so the claim holds when ``gamma <= 2 a g(x) / x`` at the ends: decided with mpmath at
  60 digits (the ends are drawn at least 1e-6 away from equality).
- :func:`linear_cases`: matrices with exact eigenvalues (triangular with dyadic diagonals, Jordan
  blocks conjugated by integer unimodular matrices, companion matrices of ``(s - lambda)^n``) and a
  rate gamma (or a radius rho) at, just above or just below the boundary.
- :func:`c_semantics_cases`: identities over the operations whose C meaning differs from the
  textbook one at their kinks (fmod, copysign, floor, ceil, sign, fmin/fmax, atan2, fabs): ones that
  C's semantics makes true for any arguments (random expressions of x and y put in), and ones false
  at a point C gives (``fmod(x + 1, 1)`` against ``fmod(x, 1)`` at x = -0.5, ``copysign(|x| + c, y)``
  against ``(|x| + c) sign(y)`` at y = 0, ...).
- :func:`identity_cases`: false identities (a relative error of 1e-15 to 1e-11; an error that
  matters only for ``|x|`` beyond 1e5..1e7; only near one point; in a small entry beside a large one) and true ones
  that cancel badly in floating point (``1 - tanh(x + c)`` against ``2 / (exp(2 (x + c)) + 1)``).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from fractions import Fraction

import casadi as ca
import mpmath
import numpy as np

__all__ = ["IdentityCase", "LinearCase", "RegionCase", "c_semantics_cases", "identity_cases", "linear_cases",
           "region_cases", "C_GRID", "C_OPERATIONS", "C_SEMANTICS", "c_semantics_unsound", "operations"]

_TRANSCENDENTAL = {"sin": (ca.sin, mpmath.sin), "tanh": (ca.tanh, mpmath.tanh),
                   "expm1": (lambda x: ca.exp(x) - 1, mpmath.expm1)}


@dataclass(frozen=True)
class RegionCase:
    """A region claim (arguments of :func:`~uvsym.verify.region.region_decrease`) and its truth.

    ``W(point)`` is ``V' + gamma x^T x`` at a point, evaluated with mpmath at 60 digits from the
    case's own formula (not from the graph the verifier reads), to re-check counterexamples."""

    name: str
    a: tuple[float, ...]
    b: tuple[float, ...]
    g: str
    gamma: float
    lower: np.ndarray
    upper: np.ndarray
    rho: float
    holds: bool

    def arguments(self) -> tuple:
        """(V, x_dot, x, gamma, lower, upper, rho) for region_decrease."""
        x = ca.SX.sym("x", len(self.a))
        g = (lambda v: v) if self.g == "poly" else _TRANSCENDENTAL[self.g][0]
        x_dot = ca.vertcat(*[-a * g(x[i]) + b * x[i] ** 2 for i, (a, b) in enumerate(zip(self.a, self.b))])
        return ca.dot(x, x), x_dot, x, self.gamma, self.lower, self.upper, self.rho

    def W(self, point) -> mpmath.mpf:
        g = (lambda v: v) if self.g == "poly" else _TRANSCENDENTAL[self.g][1]
        with mpmath.workdps(60):
            total = mpmath.mpf(0)
            for value, a, b in zip(point, self.a, self.b):
                v = mpmath.mpf(float(value))
                total += 2 * v * (-mpmath.mpf(a) * g(v) + mpmath.mpf(b) * v * v) + mpmath.mpf(self.gamma) * v * v
            return total


def _poly_holds(a, b, gamma, lower, upper) -> bool:
    return all(Fraction(gamma) - 2 * Fraction(ai) + 2 * Fraction(bi) * Fraction(float(end)) <= 0
               for ai, bi, lo, hi in zip(a, b, lower, upper) for end in (lo, hi))


def _transcendental_holds(g: str, a, gamma, lower, upper) -> bool:
    function = _TRANSCENDENTAL[g][1]
    with mpmath.workdps(60):
        return all(mpmath.mpf(gamma) <= 2 * mpmath.mpf(ai) * function(mpmath.mpf(float(end))) / mpmath.mpf(float(end))
                   for ai, lo, hi in zip(a, lower, upper) for end in (lo, hi))


def region_cases(count: int, seed: int = 0) -> list[RegionCase]:
    """``count`` region claims: polynomial at random scales, transcendental, and failing at 0."""
    rng = np.random.default_rng(seed)
    cases = []
    for k in range(count):
        n = int(rng.integers(1, 3))
        a = tuple(float(v) for v in rng.uniform(0.5, 2.0, n))
        kind = ("poly", "poly", "sin", "tanh", "expm1", "at_zero")[k % 6]
        if kind == "at_zero":  # gamma at or beyond 2 a: fails right next to the equilibrium
            gamma = 2 * min(a) * float(1 + rng.choice([0.0, 1e-6, 0.1]))
            scale = 10.0 ** rng.uniform(-6, 6)
            b = tuple(float(v) for v in rng.normal(size=n) / scale)
            lower, upper = -scale * rng.uniform(0.5, 2, n), scale * rng.uniform(0.5, 2, n)
            g = "poly"
            holds = _poly_holds(a, b, gamma, lower, upper)
        elif kind == "poly":
            gamma = float(rng.uniform(0, 1.5) * min(a))
            scale = 10.0 ** rng.uniform(-170, 160)
            signs = rng.choice([-1.0, 1.0], n)
            b = tuple(float(s * (2 * ai - gamma) / (2 * scale)) for s, ai in zip(signs, a))  # fails at |x| = scale
            edge = scale * (1 + rng.choice([-1.0, 1.0], n) * 10.0 ** rng.uniform(-8, -1, n))
            other = scale * rng.uniform(0.3, 3.0, n)
            lower, upper = np.where(signs < 0, -edge, -other), np.where(signs > 0, edge, other)
            g = "poly"
            holds = _poly_holds(a, b, gamma, lower, upper)
        else:
            g, b = kind, (0.0,) * n
            width = rng.uniform(0.2, 2.5, n)
            lower, upper = -width * rng.uniform(0.5, 1.0, n), width
            ratios = [min(float(_TRANSCENDENTAL[g][1](v) / v) for v in (lo, hi)) for lo, hi in zip(lower, upper)]
            critical = 2 * min(ai * r for ai, r in zip(a, ratios))
            gamma = float(critical * (1 + rng.choice([-1.0, 1.0]) * 10.0 ** rng.uniform(-5, -1)))
            holds = _transcendental_holds(g, a, gamma, lower, upper)
        rho = float(0.4 * np.min(np.minimum(-lower, upper)))
        cases.append(RegionCase(f"{kind} #{k}", a, b, g, gamma, np.asarray(lower, float), np.asarray(upper, float),
                                rho, holds))
    return cases


@dataclass(frozen=True)
class LinearCase:
    """``A`` with known eigenvalues; continuous claim: every eigenvalue's real part < -gamma
    (``holds``); discrete claim: every modulus < rho (``holds_discrete``)."""

    name: str
    A: np.ndarray
    gamma: float
    holds: bool
    rho: float
    holds_discrete: bool


def _unimodular(rng, n: int) -> tuple[list[list[Fraction]], list[list[Fraction]]]:
    """An integer matrix T with det 1 and its integer inverse (products of elementary matrices)."""
    T = [[Fraction(int(i == j)) for j in range(n)] for i in range(n)]
    T_inv = [row[:] for row in T]
    for _ in range(2 * n):
        i, j = rng.choice(n, 2, replace=False) if n > 1 else (0, 0)
        if i == j:
            break
        m = int(rng.integers(-2, 3))
        for row in T:  # T <- T E, E = I + m e_i e_j^T: column j += m column i
            row[j] += m * row[i]
        T_inv[i] = [u - m * v for u, v in zip(T_inv[i], T_inv[j])]  # E^-1 T_inv: row i -= m row j
    return T, T_inv


def _exact_product(*matrices):
    result = matrices[0]
    for m in matrices[1:]:
        result = [[sum((x * y for x, y in zip(row, col)), Fraction(0)) for col in zip(*m)] for row in result]
    return result


def linear_cases(count: int, seed: int = 0) -> list[LinearCase]:
    """``count`` matrices whose eigenvalues are dyadic rationals known exactly, with borderline rates."""
    rng = np.random.default_rng(seed)
    cases = []
    while len(cases) < count:
        k = len(cases)
        kind = ("triangular", "jordan", "companion")[k % 3]
        n = int(rng.integers(2, 9 if kind == "companion" else 7))
        if kind == "companion":
            lam = Fraction(-int(rng.integers(1, 9)), 4)
            coefficients = np.poly(np.full(n, float(lam)))  # (s - lam)^n: exact for these small dyadics
            A = np.zeros((n, n))
            A[0, :], A[1:, :-1] = -coefficients[1:], np.eye(n - 1)
            eigenvalues = [lam]
        else:
            eigenvalues = [Fraction(int(v), 8) for v in rng.integers(-24, 9, n)]
            if kind == "jordan":
                eigenvalues = [eigenvalues[0]] * n
            J = [[eigenvalues[i] if i == j else Fraction(0) for j in range(n)] for i in range(n)]
            for i in range(n - 1):
                J[i][i + 1] = Fraction(1) if kind == "jordan" else Fraction(int(rng.integers(-4, 5)), 2)
            T, T_inv = _unimodular(rng, n)
            exact = _exact_product(T, J, T_inv)
            A = np.array([[float(v) for v in row] for row in exact])
            if any(Fraction(float(v)) != v for row in exact for v in row):
                continue
        top = max(eigenvalues)
        spectral = max(abs(v) for v in eigenvalues)
        shift = rng.choice([0.0, 1e-12, -1e-12, 1e-6, -1e-6, 1e-2, -1e-2])
        gamma = float(-top * (1 + shift)) if top != 0 else float(shift)
        rho = float(spectral * (1 + rng.choice([0.0, 1e-12, -1e-12, 1e-6, -1e-6]))) if spectral else 0.5
        cases.append(LinearCase(f"{kind} n={n} #{k}", A, gamma, top < -Fraction(gamma), rho,
                                spectral < Fraction(rho)))
    return cases


@dataclass(frozen=True)
class IdentityCase:
    """An identity ``lhs == rhs`` over ``inputs`` and whether it holds (``kind`` names its class)."""

    kind: str
    lhs: ca.SX
    rhs: ca.SX
    inputs: list
    holds: bool


def identity_cases(count: int, seed: int = 0) -> list[IdentityCase]:
    """``count`` identities, false ones of four classes and true ones that cancel badly."""
    rng = np.random.default_rng(seed)
    x = ca.SX.sym("x")
    cases = []
    for k in range(count):
        kind = ("relative", "far", "spot", "masked", "cancelling")[k % 5]
        if kind == "relative":
            lhs, rhs, holds = x * (1 + 10.0 ** rng.uniform(-15, -11)), x, False
        elif kind == "far":  # x (x / T)^20 is below 1e-20 x for |x| < T / 10
            threshold = 10.0 ** rng.uniform(5, 7)
            lhs, rhs, holds = x + 10.0 ** rng.uniform(-3, 0) * x * (x / threshold) ** 20, x, False
        elif kind == "spot":  # a bump of height 1 and width w around one point, below 1e-40 elsewhere
            centre, width = rng.uniform(-10, 10), 10.0 ** rng.uniform(-3, -1)
            lhs, rhs, holds = x + ca.exp(-((x - centre) / width) ** 2), x, False
        elif kind == "masked":
            big, error = 10.0 ** rng.uniform(6, 12), 10.0 ** rng.uniform(-9, -3)
            lhs, rhs, holds = ca.vertcat(big * x, x * (1 + error)), ca.vertcat(big * x, x), False
        else:
            c = float(rng.uniform(20, 200))
            lhs, rhs, holds = 1 - ca.tanh(x + c), 2 / (ca.exp(2 * (x + c)) + 1), True
        cases.append(IdentityCase(kind, lhs, rhs, [x], holds))
    return cases


def _c_true(a, b):
    """Identities that hold in C for all real a, b where both sides are defined (a real zero is +0)."""
    return {"copysign_magnitude": (ca.copysign(a, b), ca.copysign(ca.fabs(a), b)),
            "copysign_square": (ca.copysign(1, b) ** 2, ca.SX(1)),
            "fmod_odd": (ca.fmod(-a, b * b + 1), -ca.fmod(a, b * b + 1)),
            "fmod_divisor_sign": (ca.fmod(a, -(b * b + 1)), ca.fmod(a, b * b + 1)),
            "floor_ceil": (ca.floor(a), -ca.ceil(-a)),
            "sign_abs": (ca.sign(a) * ca.fabs(a), a),
            "fmin_fmax": (ca.fmin(a, b), -ca.fmax(-a, -b)),
            "abs_copysign": (ca.fabs(a), ca.copysign(a, 1))}


def _c_false(x, y, c):
    """Identities false at some point of C's semantics (x, y symbols, c > 0)."""
    return {"fmod_shift": (ca.fmod(x + 1, 1), ca.fmod(x, 1)),
            "copysign_sign": (ca.copysign(ca.fabs(x) + c, y), (ca.fabs(x) + c) * ca.sign(y)),
            "floor_odd": (ca.floor(x), -ca.floor(-x)),
            "sign_square": (ca.sign(x) ** 2, ca.SX(1)),
            "fmod_floored": (ca.fmod(x, 1 + c), x - (1 + c) * ca.floor(x / (1 + c))),
            "fmin_is_fmax": (ca.fmin(x, y), ca.fmax(x, y)),
            "ceil_floor": (ca.ceil(x), ca.floor(x) + 1),
            "atan2_atan": (ca.atan2(y, x), ca.atan(y / x))}


C_SEMANTICS = tuple(_c_true(0, 0)) + tuple(_c_false(ca.SX.sym("x"), ca.SX.sym("y"), 1.0))


def _expression(rng, x, y, depth: int):
    """A random expression of x and y over +, *, fabs, sign, floor, ceil, fmod, copysign, fmin, fmax, atan2."""
    if depth == 0 or rng.uniform() < 0.3:
        return [x, y, x + y, 2 * x - y, x * y][int(rng.integers(5))] + float(rng.choice([0.0, 0.5, -1.5]))
    a, b = _expression(rng, x, y, depth - 1), _expression(rng, x, y, depth - 1)
    return [a + b, a * b, ca.fabs(a), ca.sign(a) * b, ca.floor(a), ca.ceil(a), ca.fmod(a, b * b + 1),
            ca.copysign(a, b), ca.fmin(a, b), ca.fmax(a, b), ca.atan2(a, b)][int(rng.integers(11))]


C_OPERATIONS = {ca.OP_FMOD: "fmod", ca.OP_COPYSIGN: "copysign", ca.OP_FLOOR: "floor", ca.OP_CEIL: "ceil",
                ca.OP_SIGN: "sign", ca.OP_FABS: "fabs", ca.OP_FMIN: "fmin", ca.OP_FMAX: "fmax",
                ca.OP_ATAN2: "atan2"}  # CasADi's operations whose C meaning differs from the textbook one at a kink


def operations(case: IdentityCase) -> set[str]:
    """The operation classes of :data:`C_OPERATIONS` that either side of ``case`` uses."""
    sides = ca.Function("sides", list(case.inputs), [case.lhs, case.rhs])
    return {C_OPERATIONS[op] for op in map(sides.instruction_id, range(sides.n_instructions()))
            if op in C_OPERATIONS}


def c_semantics_cases(count: int, seed: int = 0) -> list[IdentityCase]:
    """``count`` identities over x and y (module docstring), the true and the false classes in turn."""
    rng = np.random.default_rng(seed)
    x, y = ca.SX.sym("x"), ca.SX.sym("y")
    cases = []
    for k in range(count):
        if k % 2 == 0:
            kinds = _c_true(_expression(rng, x, y, 2), _expression(rng, x, y, 2))
            holds = True
        else:
            kinds = _c_false(x, y, float(rng.uniform(0.1, 3.0)))
            holds = False
        kind = list(kinds)[(k // 2) % len(kinds)]
        lhs, rhs = kinds[kind]
        cases.append(IdentityCase(kind, lhs, rhs, [x, y], holds))
    return cases


C_GRID = tuple(v / 4 for v in range(-14, 15))  # dyadic: the operations of the generated claims are exact there


def _c_differs(case: IdentityCase, point) -> bool:
    """Whether CasADi's values (C semantics, no sympy) of the two sides differ at the point."""
    a, b = (float(ca.Function("side", list(case.inputs), [e])(*point)) for e in (case.lhs, case.rhs))
    return math.isfinite(a) and math.isfinite(b) and abs(a - b) > 1e-9 * (1 + abs(a) + abs(b))


def c_semantics_unsound(case: IdentityCase, certificate) -> str | None:
    """Why a verdict on a :func:`c_semantics_cases` claim is unsound, checked by CasADi's own evaluation
    (C's semantics) alone, or None: a ``proved`` claim that is false by construction or differs somewhere
    on the dyadic grid ``C_GRID`` squared, a ``refuted`` one that is true by construction or whose
    counterexample does not differ."""
    if certificate.status == "proved":
        if not case.holds:
            return f"{case.kind}: proved, false by construction"
        wrong = [p for p in itertools.product(C_GRID, repeat=2) if _c_differs(case, p)]
        return f"{case.kind}: proved, differs in C at {wrong[0]}" if wrong else None
    if certificate.status == "refuted":
        point = tuple(certificate.counterexample["point"].values())
        if case.holds:
            return f"{case.kind}: refuted at {point}, true by construction"
        return None if _c_differs(case, point) else f"{case.kind}: refuted at {point}, where C gives equal sides"
    return None
