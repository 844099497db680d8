"""The region-claim generator of uvsym.verify.borderline keeps its promises: borderline boxes at the stated
scales, truth labels that an independent computation confirms, the stated mix of loop kinds."""

import math
from fractions import Fraction

import casadi as ca
import mpmath
import numpy as np
import pytest

from uvsym.verify.borderline import _poly_holds, region_cases

# 900 cases (150 of each at-zero/transcendental kind, 300 polynomial): a sample large enough that every drawn
# range is reached near both of its ends; seed 18 is one where the polynomial scales come within 0.5 decade of
# 1e-170 and 1e160 and some offsets reach within 10 % of their upper bound 0.1 (both needed to see the bounds)
SEED, COUNT = 18, 900
FUNCTIONS = {"sin": math.sin, "tanh": math.tanh, "expm1": math.expm1}


@pytest.fixture  # per test, not per module: a mutation tool links a function to the tests whose set-up called it
def cases():
    return region_cases(COUNT, seed=SEED)


def _of_kind(cases, *kinds):
    return [c for c in cases if c.name.split(" #")[0] in kinds]


def _key(case):
    return (case.name, case.a, case.b, case.g, case.gamma, case.lower.tolist(), case.upper.tolist(), case.rho,
            case.holds)


def _failure_point(a: float, b: float, gamma: float) -> Fraction:
    """Where ``gamma - 2 a + 2 b x`` (W_i / x^2 of ``x' = -a x + b x^2``, ``V = x^2``) vanishes, exactly."""
    return (2 * Fraction(a) - Fraction(gamma)) / (2 * Fraction(b))


def test_region_cases_are_reproducible_from_their_seed_and_the_default_seed_is_0():
    """Same seed, same cases; the default is seed 0 (the signature's), and seed 1 gives other cases."""
    default = [_key(c) for c in region_cases(12)]
    assert default == [_key(c) for c in region_cases(12, seed=0)] == [_key(c) for c in region_cases(12)]
    assert default != [_key(c) for c in region_cases(12, seed=1)]


def test_region_cases_draw_one_and_two_dimensional_loops_of_every_kind_with_rates_a_in_half_to_2(cases):
    """n in {1, 2}; every kind appears; a_i drawn in [0.5, 2] and reaching both ends of that range."""
    assert {len(c.a) for c in cases} == {1, 2}
    assert {c.name.split(" #")[0] for c in cases} == {"at_zero", "poly", "sin", "tanh", "expm1"}
    a = [ai for c in cases for ai in c.a]
    assert 0.5 <= min(a) < 0.51 and 1.99 < max(a) <= 2.0


def test_region_case_state_symbols_are_named_x_i():
    """The state is the vector symbol x: its entries (the labels a refuted certificate uses) are x for one
    state, x_0 and x_1 for two."""
    names = {tuple(s.name() for s in ca.vertsplit(c.arguments()[2])) for c in region_cases(12, seed=3)}
    assert names == {("x",), ("x_0", "x_1")}


def test_region_case_W_is_evaluated_at_60_digits():
    """W at a point carries 60 digits: its mantissa has at most the 203 bits of 60 decimal digits and more than
    the 199 of 59 digits, and it agrees with a 100-digit evaluation of ``sum 2 x (-a sin x) + gamma x^2`` to that
    precision."""
    case = next(c for c in region_cases(6, seed=0) if c.g == "sin")
    points = [[0.3, -0.7], [0.11, 0.5], [-0.9, 0.25], [0.6, -0.45], [1.7, 0.1], [-0.05, 2.0]]
    values = [case.W(p[:len(case.a)]) for p in points]
    assert mpmath.libmp.dps_to_prec(59) == 199 < max(v.bc for v in values) <= mpmath.libmp.dps_to_prec(60) == 203
    with mpmath.workdps(100):
        for p, value in zip(points, values):
            reference = sum(2 * mpmath.mpf(v) * (-mpmath.mpf(a) * mpmath.sin(v)) + mpmath.mpf(case.gamma) * v * v
                            for v, a in zip(p, case.a))
            assert abs(value - reference) <= mpmath.mpf(10) ** -58 * abs(reference)


def test_polynomial_truth_counts_a_zero_margin_as_holding():
    """``V' <= -gamma V`` holds with equality where ``gamma - 2 a + 2 b x = 0``: for a = 1.5, b = 0.25,
    gamma = 1, W = x^2 (x / 2 - 2) is <= 0 on [-1, 4] (zero at 4) and > 0 just beyond; for a = 1, b = 0,
    gamma = 2, W = 0 everywhere."""
    assert _poly_holds((1.5,), (0.25,), 1.0, [-1.0], [4.0])
    assert not _poly_holds((1.5,), (0.25,), 1.0, [-1.0], [4.5])
    assert _poly_holds((1.0, 1.0), (0.0, 0.25), 2.0, [-3.0, -1.0], [3.0, 0.0])
    assert not _poly_holds((1.0, 1.0), (0.0, 0.25), 2.0, [-3.0, -1.0], [3.0, 1.0])


def test_cases_failing_at_zero_sit_at_beyond_and_well_beyond_2_a(cases):
    """gamma / (2 min a) is exactly 1 (at the boundary), 1 + 1e-6 (just beyond) or 1.1 (well beyond), each
    drawn; the quadratic term b x^2 is of the order of a x on the box (|b| max|end| below 10, N(0, 1) times
    U(0.5, 2)); the box is drawn alike on both sides (each end scale * U(0.5, 2)): |log(upper / -lower)| below
    log 4 with median near 0."""
    at_zero = _of_kind(cases, "at_zero")
    ratios = [Fraction(c.gamma) / (2 * Fraction(min(c.a))) for c in at_zero]
    assert Fraction(1) in ratios and all(r >= 1 for r in ratios)
    assert {round(float(r) - 1, 12) for r in ratios} == {0.0, 1e-6, 0.1}
    products = [abs(b) * max(-lo, hi) for c in at_zero for b, lo, hi in zip(c.b, c.lower, c.upper)]
    assert max(products) < 10 and np.median(products) > 0.3
    logs = [math.log(hi / -lo) for c in at_zero for lo, hi in zip(c.lower, c.upper)]
    assert max(abs(v) for v in logs) <= math.log(4) and abs(float(np.median(logs))) < 0.15


def test_polynomial_cases_fail_just_inside_or_outside_the_box_on_either_side(cases):
    """Exact failure point p_i = (2 a_i - gamma) / (2 b_i): gamma / min a in [0, 1.5] (spanning it); b of both
    signs; the end on p's side at p (1 + r) with |r| in [1e-8, 0.1] spanning it, r of both signs, drawn per
    component (two-dimensional cases mix the signs, never repeat |r|); the other end at |p| times 0.3..3
    (spanning it, per component); |p| in [1e-170, 1e160] reaching within half a decade of both; both truths."""
    poly = _of_kind(cases, "poly")
    spans = [c.gamma / min(c.a) for c in poly]
    assert 0 <= min(spans) < 0.05 and 1.45 < max(spans) <= 1.5
    assert {True, False} == {c.holds for c in poly} == {b > 0 for c in poly for b in c.b}
    offsets, others, exponents, mixed = [], [], [], 0
    for c in poly:
        r, o = [], []
        for a, b, lo, hi in zip(c.a, c.b, c.lower, c.upper):
            p = _failure_point(a, b, c.gamma)
            near, far = (hi, lo) if p > 0 else (lo, hi)
            r.append(float(Fraction(float(near)) / p - 1))
            o.append(float(Fraction(float(far)) / -p))
            exponents.append(math.log10(abs(float(p))))
        if len(r) == 2:
            assert abs(abs(r[0]) / abs(r[1]) - 1) > 1e-6 and o[0] != o[1], c
            mixed += (r[0] > 0) != (r[1] > 0)
        offsets += r
        others += o
    magnitudes = [abs(v) for v in offsets]
    assert 1e-8 * (1 - 1e-6) <= min(magnitudes) < 1e-7 and 0.05 < max(magnitudes) <= 0.1 * (1 + 1e-9)
    assert min(offsets) < 0 < max(offsets) and mixed > 0
    assert 0.3 <= min(others) < 0.32 and 2.9 < max(others) <= 3.0
    assert -170 <= min(exponents) < -169.5 and 159.5 < max(exponents) <= 160


def test_transcendental_cases_sit_within_1e_minus_5_to_1e_minus_1_of_the_critical_rate(cases):
    """For g = sin, tanh, expm1 the critical rate is 2 min_i a_i min(g(e) / e) over the ends e (g(x) / x is
    monotone on each side), computed here in double precision: gamma = critical (1 + r) with |r| in
    [1e-5, 0.1], spanning it, of both signs, and the claim holds exactly when r < 0. The box: upper = width in
    [0.2, 2.5], lower = -width * [0.5, 1], both spanned and drawn per component."""
    transcendental = _of_kind(cases, "sin", "tanh", "expm1")
    offsets = []
    for c in transcendental:
        f = FUNCTIONS[c.g]
        critical = 2 * min(a * min(f(e) / e for e in (lo, hi)) for a, lo, hi in zip(c.a, c.lower, c.upper))
        offsets.append(c.gamma / critical - 1)
        assert c.holds == (offsets[-1] < 0), c
    magnitudes = [abs(v) for v in offsets]
    assert 1e-5 * (1 - 1e-9) <= min(magnitudes) < 1.2e-5 and 0.09 < max(magnitudes) <= 0.1 * (1 + 1e-9)
    assert min(offsets) < -0.09 and max(offsets) > 0.09
    widths = [hi for c in transcendental for hi in c.upper]
    assert 0.2 <= min(widths) < 0.21 and 2.49 < max(widths) <= 2.5
    shares = [[-lo / hi for lo, hi in zip(c.lower, c.upper)] for c in transcendental]
    flat = [s for pair in shares for s in pair]
    assert 0.5 <= min(flat) < 0.51 and 0.99 < max(flat) <= 1.0
    assert all(pair[0] != pair[1] for pair in shares if len(pair) == 2)
