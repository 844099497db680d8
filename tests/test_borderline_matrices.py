"""The matrix and identity generators of uvsym.verify.borderline keep their promises: exact spectra, rates at
the stated distances from the boundary, unimodular conjugations, identities false where and by how much they say."""

import math
from fractions import Fraction

import casadi as ca
import numpy as np
import pytest
import sympy

from uvsym.verify import borderline
from uvsym.verify.borderline import _exact_product, _unimodular, identity_cases, linear_cases

GAMMA_SHIFTS = (0.0, 1e-12, -1e-12, 1e-6, -1e-6, 1e-2, -1e-2)  # the docstring's "at, just above or just below"
RHO_SHIFTS = (0.0, 1e-12, -1e-12, 1e-6, -1e-6)


class ExtremeRng:
    """Stands in for numpy's ``Generator``: every draw at one end of its range (``end`` "low" or "high").

    ``integers(low, high, size)`` (high exclusive; ``integers(k)`` is ``0..k-1``): the end value, or for an array
    the ``size`` distinct values counted inwards from the end; ``uniform(low, high)``: the bound; ``choice(a, size,
    replace)``: the end element, ``size`` copies of it with replacement, the ``size`` end elements without."""

    def __init__(self, end: str):
        self.high = end == "high"

    def integers(self, low, high=None, size=None):
        low, high = (0, low) if high is None else (low, high)
        values = list(range(high - 1, low - 1, -1) if self.high else range(low, high))
        return values[0] if size is None else np.array(values[:size])

    def uniform(self, low=0.0, high=1.0):
        return float(high if self.high else low)

    def choice(self, a, size=None, replace=True):
        population = list(range(a)) if isinstance(a, int) else list(a)
        population = population[::-1] if self.high else population
        if size is None:
            return population[0]
        return np.array(population[:1] * size if replace else population[:size])


@pytest.fixture
def extreme(monkeypatch):
    """``extreme(end)``: make the generators draw from :class:`ExtremeRng`; returns the seeds they were given."""
    seeds = []

    def use(end: str) -> list:
        def default_rng(seed=None):
            seeds.append(seed)
            return ExtremeRng(end)

        monkeypatch.setattr(borderline.np.random, "default_rng", default_rng)
        return seeds

    return use


def _exact(A: np.ndarray) -> sympy.Matrix:
    """The float matrix (n, n) in exact rationals (every double is one)."""
    return sympy.Matrix([[sympy.Rational(Fraction(float(v))) for v in row] for row in A])


def _spectrum(A: np.ndarray) -> dict:
    """Exact eigenvalues {rational: algebraic multiplicity} of a float matrix (n, n), from its characteristic
    polynomial in rationals (sympy); the multiplicities sum to n only if every eigenvalue is rational."""
    polynomial = _exact(A).charpoly()
    return {Fraction(int(r.p), int(r.q)): m for r, m in sympy.Poly(polynomial.as_expr(), polynomial.gen)
            .ground_roots().items()}


def _nearest(value: float, shifts: tuple, name: str) -> float:
    """The documented shift within 5e-16 of ``value`` (1 + s rounded to a double, times a dyadic), or fail."""
    matches = [s for s in shifts if abs(value - s) <= 5e-16]
    assert matches, (name, value)
    return matches[0]


# --- _unimodular and _exact_product ----------------------------------------------------------------------------

def test_unimodular_of_size_one_is_the_identity():
    """A 1 x 1 integer matrix with det 1 whose inverse is an integer matrix: [[1]] (no index pair to shear)."""
    assert _unimodular(np.random.default_rng(0), 1) == ([[1]], [[1]])


@pytest.mark.parametrize("end, n, T_expected", [
    # every shear on (i, j) = (0, 1) with m = -2, four times: T = I - 8 e_0 e_1^T
    ("low", 2, [[1, -8], [0, 1]]),
    # six shears on (i, j) = (2, 1) with m = 2: column 1 += 2 column 2, so T = I + 12 e_2 e_1^T
    ("high", 3, [[1, 0, 0], [0, 1, 0], [0, 12, 1]]),
])
def test_unimodular_applies_2n_shears_with_multipliers_from_minus_2_to_2(end, n, T_expected):
    """Each of the 2 n steps shears with two distinct indices and a multiplier from -2..2 (here all at one end):
    T by hand, its inverse by sympy; both integer with det 1."""
    T, T_inv = _unimodular(ExtremeRng(end), n)
    expected = sympy.Matrix(T_expected)
    assert sympy.Matrix(T) == expected and sympy.Matrix(T_inv) == expected.inv()
    assert expected.det() == 1 and all(isinstance(v, Fraction) for row in T + T_inv for v in row)


def test_unimodular_of_random_sizes_is_integer_with_its_inverse():
    rng = np.random.default_rng(3)
    for n in range(1, 7):
        T, T_inv = _unimodular(rng, n)
        assert sympy.Matrix(T).det() == 1 and sympy.Matrix(T) * sympy.Matrix(T_inv) == sympy.eye(n)
        assert all(v.denominator == 1 for row in T + T_inv for v in row)


def test_exact_product_is_exact_in_fractions_even_for_integer_entries():
    """[[1, 2]] [[3], [4]] [[1/3]] = [[11/3]] exactly; integer inputs give Fractions, not ints."""
    product = _exact_product([[1, 2]], [[3], [4]])
    assert product == [[11]] and type(product[0][0]) is Fraction
    assert _exact_product([[1, 2]], [[3], [4]], [[Fraction(1, 3)]]) == [[Fraction(11, 3)]]


# --- linear_cases ------------------------------------------------------------------------------------------------

def _companion_of_power(lam: Fraction, n: int) -> sympy.Matrix:
    """Companion matrix (n, n) of (s - lam)^n: first row -C(n, k) (-lam)^k for k = 1..n, ones below the diagonal."""
    A = sympy.zeros(n, n)
    for k in range(1, n + 1):
        A[0, k - 1] = -math.comb(n, k) * sympy.Rational(-lam) ** k
    for i in range(1, n):
        A[i, i - 1] = 1
    return A


def test_linear_cases_at_the_low_end_of_every_draw(extreme):
    """Every draw at its low end, the three kinds by hand: triangular n = 2 with eigenvalues -24/8, -23/8 and
    superdiagonal -4/2, Jordan n = 2 at -3 (the first eigenvalue drawn), companion n = 2 of (s + 1/4)^2; T = I - 8
    e_0 e_1^T; no shift (the first of each list): gamma = -top, rho = the spectral radius, both claims false."""
    seeds = extreme("low")
    cases = linear_cases(3)
    assert seeds == [0] and len(cases) == 3
    T = sympy.Matrix([[1, -8], [0, 1]])
    expected = [T * sympy.Matrix([[-3, -2], [0, sympy.Rational(-23, 8)]]) * T.inv(),
                T * sympy.Matrix([[-3, 1], [0, -3]]) * T.inv(),
                _companion_of_power(Fraction(-1, 4), 2)]
    assert expected[0] == sympy.Matrix([[-3, -3], [0, sympy.Rational(-23, 8)]])
    assert expected[2] == sympy.Matrix([[sympy.Rational(-1, 2), sympy.Rational(-1, 16)], [1, 0]])
    names = ["triangular n=2 #0", "jordan n=2 #1", "companion n=2 #2"]
    for case, name, A, top, radius in zip(cases, names, expected, (-2.875, -3.0, -0.25), (3.0, 3.0, 0.25)):
        assert case.name == name and _exact(case.A) == A, name
        assert (case.gamma, case.holds, case.rho, case.holds_discrete) == (-top, False, radius, False), name


def test_linear_cases_at_the_high_end_of_every_draw(extreme):
    """Every draw at its high end: n = 6 (8 for the companion), triangular eigenvalues 8/8, 7/8, ..., 3/8 with
    superdiagonal 4/2, Jordan at 1, companion of (s + 8/4)^8; T = I + 24 e_5 e_4^T (12 shears of column 4 by
    2 column 5); the last shifts: gamma = -top (1 - 1e-2), rho = radius (1 - 1e-6)."""
    extreme("high")
    cases = linear_cases(3, seed=5)
    T = sympy.eye(6)
    T[5, 4] = 24
    J_triangular, J_jordan = sympy.zeros(6, 6), sympy.zeros(6, 6)
    for i in range(6):
        J_triangular[i, i], J_jordan[i, i] = sympy.Rational(8 - i, 8), 1
    for i in range(5):
        J_triangular[i, i + 1], J_jordan[i, i + 1] = 2, 1
    expected = [T * J_triangular * T.inv(), T * J_jordan * T.inv(), _companion_of_power(Fraction(-2), 8)]
    assert expected[2][0, :] == -sympy.Matrix([[16, 112, 448, 1120, 1792, 1792, 1024, 256]])  # C(8, k) 2^k
    names = ["triangular n=6 #0", "jordan n=6 #1", "companion n=8 #2"]
    for case, name, A, top, radius, holds in zip(cases, names, expected, (1.0, 1.0, -2.0), (1.0, 1.0, 2.0),
                                                 (False, False, True)):  # -2 < -1.98 only
        assert case.name == name and _exact(case.A) == A, name
        assert case.gamma == pytest.approx(-top * 0.99, rel=1e-15) and case.holds is holds, name
        assert case.rho == pytest.approx(radius * (1 - 1e-6), rel=1e-15) and not case.holds_discrete, name


def test_linear_cases_have_exact_spectra_of_their_kind_and_every_documented_shift():
    """60 cases of seed 0, eigenvalues from the characteristic polynomial (sympy): all rational, dyadic in [-3, 1]
    (companion: one eigenvalue -k/4, k = 1..8, at the binomial coefficients); a Jordan case is lam I plus an
    integer nilpotent N of index n whose entries have gcd 1 (as a unimodular conjugate of the Jordan block);
    gamma = -top (1 + s) (gamma = s when top = 0) and rho = radius (1 + s) (0.5 when the radius is 0) with s from
    the documented shifts, each of which occurs; both truth labels agree with the exact spectrum."""
    cases, again = linear_cases(60, seed=0), linear_cases(60, seed=0)
    assert len(cases) == 60 and all(a.name == b.name and np.array_equal(a.A, b.A)
                                    and (a.gamma, a.rho) == (b.gamma, b.rho) for a, b in zip(cases, again))
    gamma_shifts, rho_shifts, zero_top, zero_radius = set(), set(), [], []
    for k, case in enumerate(cases):
        kind, n = ("triangular", "jordan", "companion")[k % 3], len(case.A)
        assert case.name == f"{kind} n={n} #{k}" and case.A.shape == (n, n)
        spectrum = _spectrum(case.A)
        assert sum(spectrum.values()) == n, case.name
        assert all(-3 <= v <= 1 and (8 * v).denominator == 1 for v in spectrum), case.name
        if kind == "companion":
            lam = Fraction(float(case.A[0, 0])) / n  # the trace
            assert 2 <= n <= 8 and spectrum == {lam: n} and _exact(case.A) == _companion_of_power(lam, n), case.name
        else:
            assert 2 <= n <= 6, case.name
        if kind == "jordan":
            (lam, multiplicity), = spectrum.items()
            N = _exact(case.A) - sympy.Rational(lam) * sympy.eye(n)
            assert all(v.is_integer for v in N) and math.gcd(*(int(v) for v in N)) == 1, case.name
            assert N ** (n - 1) != sympy.zeros(n, n) and N ** n == sympy.zeros(n, n), case.name
        top, radius = max(spectrum), max(abs(v) for v in spectrum)
        gamma, rho = Fraction(case.gamma), Fraction(case.rho)
        assert case.holds == (top < -gamma) and case.holds_discrete == (radius < rho), case.name
        if top:
            gamma_shifts.add(_nearest(float(-gamma / top - 1), GAMMA_SHIFTS, case.name))
        else:
            zero_top.append(case.gamma)
            assert case.gamma in GAMMA_SHIFTS, case.name
        if radius:
            rho_shifts.add(_nearest(float(rho / radius - 1), RHO_SHIFTS, case.name))
        else:
            zero_radius.append(case.rho)
    assert gamma_shifts == set(GAMMA_SHIFTS) and rho_shifts == set(RHO_SHIFTS)
    assert any(zero_top) and zero_radius and set(zero_radius) == {0.5}


# --- identity_cases ----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("end, relative, threshold, factor, centre, width, big, error, c", [
    ("low", 1e-15, 1e5, 1e-3, -10.0, 1e-3, 1e6, 1e-9, 20.0),
    ("high", 1e-11, 1e7, 1.0, 10.0, 1e-1, 1e12, 1e-3, 200.0),
])
def test_identity_cases_at_each_end_of_their_documented_ranges(extreme, end, relative, threshold, factor, centre,
                                                               width, big, error, c):
    """Every draw at one end, each class evaluated against its closed form: relative error ``relative``; far:
    ``factor x (x / T)^20``, so ``factor 2T 2^20`` at 2T and nothing at T / 10; spot: ``exp(-t^2)`` at
    ``centre + t width``; masked: the large entry ``big x`` equal, the small one off by ``error x``; cancelling
    with ``c``: ``2 / (exp(2 c) + 1)`` at 0, where ``1 - tanh(c)`` has cancelled to 0."""
    seeds = extreme(end)
    cases = identity_cases(5)
    assert seeds == [0] and [case.kind for case in cases] == ["relative", "far", "spot", "masked", "cancelling"]
    assert [case.holds for case in cases] == [False, False, False, False, True]
    x = cases[0].inputs[0]
    assert all(case.inputs == [x] for case in cases) and x.name() == "x"
    values = [ca.Function("f", [x], [case.lhs, case.rhs]) for case in cases]

    def at(k, point):
        return [np.asarray(v, float).ravel() for v in values[k](point)]

    lhs, rhs = at(0, 1.0)
    assert rhs == 1.0 and lhs - rhs == pytest.approx(relative, rel=0.12, abs=0)  # 1 + 1e-15 rounds to 1 + 1.11e-15
    lhs, rhs = at(1, 2 * threshold)
    assert rhs == 2 * threshold and lhs - rhs == pytest.approx(factor * 2 * threshold * 2.0 ** 20, rel=1e-12)
    assert at(1, threshold / 10) == [threshold / 10] * 2
    for t in (0.0, 1.0, 2.0, -1.0):
        lhs, rhs = at(2, centre + t * width)
        assert lhs - rhs == pytest.approx(math.exp(-t * t), rel=1e-9), t
    assert at(2, 0.0) == [0.0, 0.0]
    lhs, rhs = at(3, 2.0)
    assert lhs[0] == rhs[0] == 2 * big and rhs[1] == 2.0
    assert lhs[1] - rhs[1] == pytest.approx(2 * error, rel=1e-6, abs=0)
    lhs, rhs = at(4, 0.0)
    assert lhs == 0.0 and rhs == pytest.approx(2 / (math.exp(2 * c) + 1), rel=1e-12, abs=0)


def test_identity_cases_are_reproducible_from_the_default_seed():
    """No seed means seed 0: the same expressions, in the five classes in turn."""
    assert [str(case.lhs) for case in identity_cases(5)] == [str(case.lhs) for case in identity_cases(5, seed=0)]
    assert [str(case.lhs) for case in identity_cases(5)] != [str(case.lhs) for case in identity_cases(5, seed=1)]
