"""Soundness of uvsym verify: borderline claims with known truth never come back proved when false
or refuted when true, at scales from 1e-170 to 1e160; each finding of the soundness review has
its regression here; bad inputs get typed errors. (A larger sample: benchmarks/soundness.py.)"""

from __future__ import annotations

import math
import subprocess
import sys
import time
from fractions import Fraction

import casadi as ca
import numpy as np
import pytest
import sympy as sp

from uvsym.errors import UvsymError, VerificationError
from uvsym.testing import assert_checked, assert_proved, assert_refuted
from uvsym.verify import (
    Certificate,
    identity,
    lyapunov_decrease,
    prove_identity,
    region_decrease,
    synthesis,
    synthesize_observer_gain,
)
from uvsym.verify.borderline import identity_cases, linear_cases, region_cases
from uvsym.verify.interval import IntervalFunction
from uvsym.verify.lyapunov import discrete_lyapunov_decrease


def _unsound(status: str, holds: bool) -> bool:
    return (status == "proved" and not holds) or (status == "refuted" and holds)


def test_borderline_region_claims_are_never_decided_wrongly():
    outcomes = []
    for case in region_cases(36, seed=11):
        certificate = region_decrease(case.name, *case.arguments(), max_boxes=20_000)
        assert not _unsound(certificate.status, case.holds), (case, certificate)
        if certificate.status == "refuted":  # the counterexample violates the claim by the case's own formula
            assert case.W(list(certificate.counterexample["x"].values())) > 0
        outcomes.append(certificate.status)
    rate = outcomes.count("inconclusive") / len(outcomes)
    print(f"region claims: {len(outcomes)} cases, inconclusive rate {rate:.2f}")
    assert rate < 0.5 and "proved" in outcomes and "refuted" in outcomes


def test_borderline_linear_claims_are_never_decided_wrongly():
    statuses = []
    for case in linear_cases(60, seed=12):
        continuous = lyapunov_decrease(case.name, [case.A], case.gamma, "one matrix")
        discrete = discrete_lyapunov_decrease(case.name, case.A, case.rho, "one matrix")
        assert not _unsound(continuous.status, case.holds), (case, continuous)
        assert not _unsound(discrete.status, case.holds_discrete), (case, discrete)
        statuses += [continuous.status, discrete.status]
    assert statuses.count("inconclusive") == 0 and {"proved", "refuted"} <= set(statuses)


def test_false_identities_of_every_class_are_never_proved():
    for case in identity_cases(10, seed=13):
        certificate = prove_identity(case.kind, case.lhs, case.rhs, case.inputs, "all x", symbolic_seconds=1.0)
        assert not _unsound(certificate.status, case.holds), (case.kind, certificate)


def test_region_claim_failing_near_the_equilibrium_at_any_scale():
    """Finding (a): x' = -x + b x^2 fails for x beyond s (b = 0.5 / s, gamma = 1): inside the cube
    the interval Hessian is indefinite; at 1e-170 it used to be proved, at 1e160 to raise."""
    for scale in (1e-170, 1e-20, 1.0, 1e20, 1e160):
        x = ca.SX.sym("x")
        certificate = region_decrease(f"scale {scale:g}", x * x, -x + (0.5 / scale) * x ** 2, x, 1.0,
                                      [-3 * scale], [3 * scale], 2.5 * scale, max_boxes=20_000)
        assert certificate.status in ("refuted", "inconclusive"), (scale, certificate)
        if certificate.status == "refuted":
            point = list(certificate.counterexample["x"].values())[0] / scale
            assert 2 * point * (-point + 0.5 * point ** 2) + point ** 2 > 0  # W / s^2 at the point


def test_region_claim_with_a_domain_violation_is_not_proved():
    """Finding (b): sqrt(x) is NaN for x < 0: V' is undefined on half the box."""
    x = ca.SX.sym("x")
    certificate = region_decrease("sqrt", x * x, -x - 0.01 * ca.sqrt(x), x, 0.5, [-1.0], [1.0], 0.1)
    assert certificate.status == "inconclusive" and "undefined" in certificate.reason
    logged = region_decrease("log1p", x * x, -x + 0.01 * x * ca.log1p(x), x, 0.5, [-2.0], [1.0], 0.1)
    assert logged.status != "proved"


@pytest.mark.parametrize("g", [ca.sin, ca.tanh, lambda v: ca.exp(v) - 1])
def test_transcendental_loops_are_proved_at_the_equilibrium(g):
    """Library results at 0 are exact (sin 0 = 0, exp 0 = 1), so W(0) = 0 and the Taylor cube applies."""
    x = ca.SX.sym("x")
    assert_proved(region_decrease("g", x * x, -g(x), x, 0.5, [-1.0], [1.0], 0.2))


def test_claim_failing_far_from_the_origin_is_refuted_even_when_the_cube_fails():
    """gamma = 2 a: W = 2 b x^3 has a zero Hessian at 0, the cube never certifies; the
    branch-and-bound still finds where W > 0."""
    x = ca.SX.sym("x")
    refuted = region_decrease("cubic", x * x, -x + 0.3 * x ** 2, x, 2.0, [-1.0], [1.0], 0.5, expected="refuted")
    assert_refuted(refuted)
    point = refuted.counterexample["x"]["x"]
    assert point > 0 and 0.6 * point ** 3 > 0


def test_companion_matrix_of_a_repeated_root_is_decided_exactly():
    """(s + 1)^8: numpy's eigenvalues scatter by ~0.02 around -1; the claim holds for gamma < 1."""
    coefficients = np.poly(-np.ones(8))
    A = np.zeros((8, 8))
    A[0, :], A[1:, :-1] = -coefficients[1:], np.eye(7)
    assert max(np.linalg.eigvals(A).real) > -0.99  # what used to refute the true claim
    assert_proved(lyapunov_decrease("(s+1)^8", [A], 0.99, "one matrix"))
    assert_refuted(lyapunov_decrease("(s+1)^8", [A], 1.0, "one matrix"))
    assert_refuted(discrete_lyapunov_decrease("(s+1)^8 sampled", A, 1.0, "one matrix"))
    assert_proved(discrete_lyapunov_decrease("(s+1)^8 sampled", A, 1.01, "one matrix"))


def test_synthesis_certifies_the_exact_closed_loop():
    A = np.array([[0.0, 1.0], [-2.0, -0.1]])
    C = np.array([[1.0, 0.0]])
    design = synthesize_observer_gain(A, C, decay=1.0)
    assert "exact" in design.certificate.set
    # independent oracle: the closed loop in exact rationals, its trace and determinant (2 x 2: Hurwitz
    # at rate 1 iff tr(A + I) < 0 and det(A + I) > 0)
    F = [[Fraction(float(A[i][j])) - sum(Fraction(float(design.L[i][k])) * Fraction(float(C[k][j]))
                                         for k in range(1)) + (1 if i == j else 0) for j in range(2)] for i in range(2)]
    assert F[0][0] + F[1][1] < 0 and F[0][0] * F[1][1] - F[0][1] * F[1][0] > 0


def test_synthesis_reaches_a_rate_just_below_an_unobservable_mode_and_says_what_it_tried_beyond():
    """The mode at -1 is not seen by C: A - L C keeps it, so every rate below 1 1/s is reachable (decay 0 too) and
    none above; the LMI is ``A'P + PA - C'Y' - YC + 2 rate P < 0``, feasible exactly for rate < 1."""
    A, C = np.diag([-1.0, 0.5]), np.array([[0.0, 1.0]])
    for decay in (0.0, 0.8):
        L = synthesize_observer_gain(A, C, decay=decay).L
        assert max(np.linalg.eigvals(A - L @ C).real) <= -decay
    with pytest.raises(UvsymError, match=r"^no observer gain with decay 1.2 1/s: the LMI at 1.212 1/s: "
                                         r"infeasible and at 1.2 1/s: infeasible$"):
        synthesize_observer_gain(A, C, decay=1.2)


def test_a_jump_that_every_derivative_misses_is_never_proved():
    """W = V' + gamma x'x with x' = -x + c (ceil x - floor x): CasADi's derivatives of ceil and floor are 0, so the
    Hessian of W is -2 + 2 gamma everywhere, yet W = 2 c x - (2 - gamma) x^2 > 0 for 0 < x < 2 c / (2 - gamma)."""
    x, c, gamma = ca.SX.sym("x"), 1e-9, 0.5
    certificate = region_decrease("jump", x * x, -x + c * (ca.ceil(x) - ca.floor(x)), x, gamma, [-1.0], [1.0], 0.1,
                                  max_boxes=20_000)
    point = 1e-12
    assert 2 * point * (-point + c * (math.ceil(point) - math.floor(point))) + gamma * point ** 2 > 0
    assert certificate.status != "proved"


def test_a_loop_whose_equilibrium_is_not_at_zero_gets_no_taylor_cube():
    """V = x^2 + x has V' = (2 x + 1) x' != 0 at x = 0 for x' = -x - 0.01: the cube argument needs W(0) = 0 and a
    zero gradient there; W < 0 on the rest of the box, so the claim is left open with that reason."""
    x = ca.SX.sym("x")
    certificate = region_decrease("offset", x * x + x, -x - 0.01, x, 0.01, [-0.001], [1.0], 0.0005,
                                  max_boxes=20_000)
    assert certificate.status == "inconclusive"
    assert certificate.reason.startswith("W or its gradient at x = 0 is not exactly 0 in interval arithmetic (is x = 0 "
                                         "an equilibrium of the loop?); no counterexample outside it")


def test_identity_findings():
    x = ca.SX.sym("x")
    relative = prove_identity("1e-13", x * (1 + 1e-13), x, [x], "all x")
    assert relative.status == "checked" and not relative.proved  # sampling is evidence, not a proof
    far = x + ca.if_else(ca.fabs(x) > 1e6, 1e-3 * x, 0)
    assert prove_identity("far", far, x, [x], "all x").status == "refuted"
    spot = x + ca.if_else(ca.fabs(x - 7) < 0.01, 1, 0)
    assert prove_identity("near 7", spot, x, [x], "all x").status != "proved"
    assert_refuted(prove_identity("near 7, box", spot, x, [x], "6.99 <= x <= 7.01", box=([6.99], [7.01])))
    masked = prove_identity("masked", ca.vertcat(1e9 * x, x * (1 + 1e-6)), ca.vertcat(1e9 * x, x), [x], "all x")
    assert_refuted(masked)
    assert masked.counterexample["entry"] == 1
    started = time.perf_counter()
    tanh = prove_identity("1 - tanh", 1 - ca.tanh(x + 100), 2 / (ca.exp(2 * (x + 100)) + 1), [x], "all x",
                          symbolic_seconds=1.0)
    assert tanh.status != "refuted" and time.perf_counter() - started < 20
    assert_checked(tanh)
    assert_proved(prove_identity("rational", (x ** 2 - 1) / (x - 1), x + 1, [x], "x != 1"))
    # 0.1 * 3 is 0.3000000000000000166... exactly, not the double 0.30000000000000004: never "proved"
    y = ca.SX.sym("y")
    assert prove_identity("folded", 0.1 * (y * (3 * x)), 0.30000000000000004 * x * y, [x, y], "all").status != "proved"


def test_assert_proved_refuses_checked_evidence():
    with pytest.raises(AssertionError, match="not proved"):
        assert_proved(Certificate("claim", "set", "sampled", "checked"))


def test_bad_inputs_get_typed_errors_naming_the_argument():
    x, p = ca.SX.sym("x", 2), ca.SX.sym("p")
    V, f = ca.dot(x, x), -x
    box = ([-1.0, -1.0], [1.0, 1.0])
    cases = [
        (lambda: region_decrease("c", V, f, x, 0.5, [np.nan, -1], [1, 1], 0.1), "lower"),
        (lambda: region_decrease("c", V, f, x, 0.5, [-1, -1, -1], [1, 1], 0.1), "lower"),
        (lambda: region_decrease("c", V, f, x, np.inf, *box, 0.1), "gamma"),
        (lambda: region_decrease("c", V, f, x, 0.5, *box, np.nan), "rho"),
        (lambda: region_decrease("c", V, -x * p, x, 0.5, *box, 0.1), "free symbol"),
        (lambda: region_decrease("c", [1.0], f, x, 0.5, *box, 0.1), "V must be"),
        (lambda: lyapunov_decrease("c", [np.array([[np.nan, 0], [0, -1.0]])], 0.5, "s"), r"vertices\[0\]"),
        (lambda: lyapunov_decrease("c", np.eye(2), 0.5, "s"), "list of matrices"),
        (lambda: lyapunov_decrease("c", [np.eye(2), np.eye(3)], 0.5, "s"), r"vertices\[1\]"),
        (lambda: lyapunov_decrease("c", [[[1.0, 2.0]]], 0.5, "s"), r"vertices\[0\]"),
        (lambda: lyapunov_decrease("c", [-np.eye(2)], np.nan, "s"), "gamma"),
        (lambda: lyapunov_decrease("c", [], 0.5, "s"), "non-empty"),
        (lambda: discrete_lyapunov_decrease("c", [[0.5, np.inf], [0, 0.5]], 1.0, "s"), "Ad"),
        (lambda: discrete_lyapunov_decrease("c", np.eye(2) / 2, -1.0, "s"), "rho"),
        (lambda: prove_identity("c", x, ca.vertcat(x, x), [x], "s"), "same shape"),
        (lambda: prove_identity("c", x * p, x, [x], "s"), "p"),
        (lambda: prove_identity("c", x, x, [x[0] + 1], "s"), "symbols only"),
        (lambda: prove_identity("c", x, x, [x], "s", box=([0, np.nan], [1, 1])), "box"),
        (lambda: synthesize_observer_gain([[np.nan]], [[1.0]], 1.0), "^A has entries that are not finite"),
        (lambda: synthesize_observer_gain(np.eye(2), np.ones((1, 3)), 1.0), "columns"),
        (lambda: synthesize_observer_gain(-np.eye(2), np.ones((1, 2)), np.nan), "decay"),
        (lambda: synthesize_observer_gain(-np.eye(2), np.ones((1, 2)), -0.5), "decay must be a finite rate >= 0"),
        (lambda: synthesize_observer_gain([[-1.0]], [[np.inf]], 1.0), "^C has entries that are not finite"),
        (lambda: IntervalFunction(ca.Function("f", [x], [x]))([[np.nan, 0]], [[1, 1]]), "NaN"),
        (lambda: Certificate("c", "s", "m", "maybe"), "status"),
    ]
    for call, message in cases:
        with pytest.raises(VerificationError, match=message):
            call()


def _failure_point(a: float, b: float, gamma: float) -> Fraction:
    """Where ``W_i / x^2 = gamma - 2 a + 2 b x`` (for ``x' = -a x + b x^2``, ``V = x^2``) changes sign."""
    return (2 * Fraction(a) - Fraction(gamma)) / (2 * Fraction(b))


def test_borderline_region_cases_have_the_truth_and_the_scales_they_promise():
    """Truth by W at the ends of each side (exact rationals for the polynomial loops, where W_i / x^2 is affine
    in x; the double-precision definition ``2 x x' + gamma x^2`` for the others, decided with a margin of 1e-5),
    the failure point within 1e-8..1e-1 of a box end, scales spanning 1e-170..1e160, a Taylor cube inside the box."""
    cases = region_cases(240, seed=5)
    functions = {"sin": math.sin, "tanh": math.tanh, "expm1": math.expm1}
    scales = []
    for case in cases:
        kind = case.name.split(" #")[0]
        ends = [(i, float(e)) for i in range(len(case.a)) for e in (case.lower[i], case.upper[i])]
        assert all(lo < 0 < hi for lo, hi in zip(case.lower, case.upper)), case
        assert 0 < case.rho < min(min(-case.lower), min(case.upper)), case
        if case.g == "poly":
            W = [2 * Fraction(e) * (-Fraction(case.a[i]) * Fraction(e) + Fraction(case.b[i]) * Fraction(e) ** 2)
                 + Fraction(case.gamma) * Fraction(e) ** 2 for i, e in ends]
        else:
            W = [2 * e * (-case.a[i] * functions[case.g](e)) + case.gamma * e * e for i, e in ends]
            assert case.b == (0.0,) * len(case.a) and all(abs(w) > 1e-7 * e * e for w, (_, e) in zip(W, ends))
        assert case.holds == all(w <= 0 for w in W), case
        if kind == "at_zero":  # gamma >= 2 a: W_i ~ (gamma - 2 a) x^2 + 2 b x^3 > 0 on one side of 0
            assert case.gamma >= 2 * min(case.a) and not case.holds, case
        elif kind == "poly":
            for i, (a, b) in enumerate(zip(case.a, case.b)):
                point = _failure_point(a, b, case.gamma)
                end = Fraction(float(case.upper[i] if point > 0 else case.lower[i]))
                assert 0.99e-8 <= abs(end / point - 1) <= 0.101, (case, i)
                scales.append(abs(float(point)))
    assert {"at_zero", "poly", "sin", "tanh", "expm1"} == {case.name.split(" #")[0] for case in cases}
    assert {True, False} == {case.holds for case in cases}
    assert 1e-170 <= min(scales) < 1e-150 and 1e140 < max(scales) <= 1e160


def test_region_case_arguments_and_W_follow_the_loop_they_name():
    """V = x^T x and x' = -a g(x) + b x^2 evaluated at a point; W = 2 x x' + gamma x^2 there, by hand."""
    point = [0.3, -0.7]
    for case in region_cases(6, seed=2):
        V, x_dot, x, gamma, lower, upper, rho = case.arguments()
        assert (gamma, rho) == (case.gamma, case.rho) and np.array_equal(lower, case.lower)
        assert np.array_equal(upper, case.upper) and x.shape == (len(case.a), 1)
        p = point[:len(case.a)]
        g = {"poly": lambda v: v, "sin": math.sin, "tanh": math.tanh, "expm1": math.expm1}[case.g]
        expected = [-a * g(v) + b * v * v for v, a, b in zip(p, case.a, case.b)]
        values = ca.Function("f", [x], [V, x_dot])(p)
        assert float(values[0]) == pytest.approx(sum(v * v for v in p), rel=1e-15)
        assert np.asarray(values[1]).ravel() == pytest.approx(expected, rel=1e-14)
        by_hand = sum(2 * v * e + case.gamma * v * v for v, e in zip(p, expected))
        assert float(case.W(p)) == pytest.approx(by_hand, rel=1e-12, abs=1e-15)


def test_borderline_linear_cases_sit_at_their_exact_spectra():
    """Eigenvalues from the characteristic polynomial in exact rationals (sympy), not from the generator:
    rho within 1e-6 of the spectral radius, gamma within 1e-2 of the slowest rate, and the truth of both claims."""
    import sympy

    for case in linear_cases(9, seed=5):
        matrix = sympy.Matrix([[sympy.Rational(Fraction(float(v))) for v in row] for row in case.A])
        roots = sympy.roots(matrix.charpoly().as_expr())
        assert sum(roots.values()) == len(case.A) and all(root.is_rational for root in roots), case.name
        spectral, top = max(abs(root) for root in roots), max(roots)
        gamma, rho = sympy.Rational(Fraction(case.gamma)), sympy.Rational(Fraction(case.rho))
        assert case.holds == bool(top < -gamma) and case.holds_discrete == bool(spectral < rho), case.name
        assert abs(rho - spectral) <= sympy.Rational(1, 10 ** 6) * spectral if spectral else rho == sympy.Rational(1, 2)
        margin = sympy.Rational(101, 10 ** 4)  # the largest shift, 1e-2, and the rounding of gamma to a double
        assert abs(gamma + top) <= margin * abs(top) if top else abs(gamma) <= margin


def test_borderline_identity_cases_are_reproducible_and_false_where_they_say():
    """The same seed gives the same expressions; each false class differs from x where its docstring says
    (relative error 1e-15..1e-11 at x = 1, far only beyond 1e5..1e7, in the small entry beside a large one)."""
    cases = identity_cases(10, seed=4)
    assert [str(c.lhs) for c in cases] == [str(c.lhs) for c in identity_cases(10, seed=4)]
    assert [c.kind for c in cases] == ["relative", "far", "spot", "masked", "cancelling"] * 2
    for case in cases:
        f = ca.Function("f", case.inputs, [case.lhs, case.rhs])
        assert case.holds == (case.kind == "cancelling")
        if case.kind == "relative":
            lhs, rhs = (float(v) for v in f(1.0))
            assert rhs == 1.0 and 0.5e-15 <= lhs - 1 <= 1.1e-11
        elif case.kind == "far":  # x (1 + c (x / T)^20), c in 1e-3..1, T in 1e5..1e7: c / T^20 from x = 1e9
            ratio = float(f(1e9)[0]) / 1e9 - 1
            assert 1e-3 * 1e40 <= ratio <= 1e80 and ratio * 1e-100 <= 1e-20  # (1e4 / 1e9)^20 = 1e-100
        elif case.kind == "masked":
            lhs, rhs = (np.asarray(v).ravel() for v in f(1.0))
            assert lhs[0] == rhs[0] >= 1e6 and 1e-9 <= lhs[1] - rhs[1] <= 1e-3


def test_symbolic_step_limits_its_own_cpu_time_and_tells_how_each_entry_vanished(monkeypatch):
    """``_symbolic_outcome`` (run here in-process, its CPU limit recorded rather than set): the limit is
    ``ceil(seconds)`` beyond the CPU time already used; (x+1)^2 - x^2 - 2x - 1 vanishes by rational
    arithmetic, sin^2 + cos^2 - 1 only by simplification, x - 1 not at all."""
    limits, sent = [], []
    monkeypatch.setattr(identity.resource, "setrlimit", lambda kind, pair: limits.append((kind, pair)))
    monkeypatch.setattr(identity.resource, "getrlimit", lambda kind: (kind, identity.resource.RLIM_INFINITY))
    monkeypatch.setattr(identity.time, "process_time", lambda: 100.7)

    class Channel:
        send = sent.append

    x = sp.Symbol("x", real=True)
    polynomial, trigonometric = (x + 1) ** 2 - x**2 - 2 * x - 1, sp.sin(x) ** 2 + sp.cos(x) ** 2 - 1
    for entries in ([polynomial], [polynomial, trigonometric], [polynomial, x - 1]):
        identity._symbolic_outcome(entries, Channel, 2.5)
    assert sent == ["exact", "simplify", ""]
    assert limits == [(identity.resource.RLIMIT_CPU, (3 + 100, identity.resource.RLIM_INFINITY))] * 3


@pytest.mark.parametrize("hard, soft", [(500, 103), (101, 101)])
def test_symbolic_step_keeps_a_finite_hard_cpu_limit_it_inherited(monkeypatch, hard, soft):
    """Under a batch job's ``ulimit -t`` (a finite hard limit, which no process may raise) the child sets its soft
    limit to ceil(seconds) beyond the CPU time used, capped at the hard limit, and keeps the hard limit."""
    limits = []
    monkeypatch.setattr(identity.resource, "setrlimit", lambda kind, pair: limits.append(pair))
    monkeypatch.setattr(identity.resource, "getrlimit", lambda kind: (hard, hard))
    monkeypatch.setattr(identity.time, "process_time", lambda: 100.7)
    identity._symbolic_outcome([sp.Integer(0)], type("Channel", (), {"send": staticmethod(lambda how: None)}), 2.5)
    assert limits == [(soft, hard)]


_UNDER_A_HARD_LIMIT = """
import resource, sys
import casadi as ca
from uvsym.verify.identity import prove_identity
resource.setrlimit(resource.RLIMIT_CPU, (10_000, 10_000))
x = ca.SX.sym("x")
claim = prove_identity("square", (x + 1) ** 2, x**2 + 2 * x + 1, [x], "all real x")
sys.stdout.write(claim.status + " " + claim.method)
"""


def test_an_identity_is_still_proved_under_a_finite_hard_cpu_limit():
    """A process started under ``ulimit -Ht`` (the hard CPU limit finite) still proves (x+1)^2 = x^2 + 2x + 1 by
    exact rational arithmetic: the symbolic child keeps the limit instead of failing to raise it."""
    done = subprocess.run([sys.executable, "-c", _UNDER_A_HARD_LIMIT], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("proved "), done.stdout


def test_synthesis_keeps_equalities_on_P_and_names_its_claim():
    """With P = diag(p1, p2) and Y = (y1, p1 - 2 p2) the LMI of A below is diag(2 r p1 - 2 y1, (2 r - 0.2) p2) < 0:
    feasible for r < 0.1 (by hand), so rate 0.05 is reached with P diagonal, where the unconstrained optimum is not.
    Without a claim the certificate says "observer error decays"."""
    A, C = np.array([[0.0, 1.0], [-2.0, -0.1]]), np.array([[1.0, 0.0]])
    free = synthesize_observer_gain(A, C, decay=0.05)
    assert abs(free.P[0, 1]) > 1e-3 * np.abs(free.P).max()
    design = synthesize_observer_gain(A, C, decay=0.05, equalities=[lambda P, Y: P[0, 1] == 0])
    assert abs(design.P[0, 1]) <= 1e-6 * np.abs(design.P).max()
    assert max(np.linalg.eigvals(A - design.L @ C).real) <= -0.05
    assert design.certificate.claim == "observer error decays"


def test_exact_zero_sees_through_a_piecewise_atom():
    """A Piecewise (what a CasADi comparison or if_else becomes) is one atom P: P (x + 1) - P x - P = 0 by
    distributivity whatever P is, and P (x + 1) - P x = P is not identically zero."""
    x = sp.Symbol("x")
    P = sp.Piecewise((x, x < 1), (0, True))
    assert identity.exact_zero(P * (x + 1) - P * x - P)
    assert not identity.exact_zero(P * (x + 1) - P * x)


def test_synthesis_falls_back_to_the_rate_itself_and_still_certifies_it():
    """A = diag(-1, 0.5), C = (0, 1): the mode -1 is unseen, so rate 0.995 is reachable but 1 % more (1.005) is not
    (by hand: the LMI's x1 entry is 2 (rate - 1) p1). The fallback LMI at 0.995 itself must still leave a strict
    margin for the exact re-check: the certified closed loop has both eigenvalues at or below -0.995."""
    A, C = np.diag([-1.0, 0.5]), np.array([[0.0, 1.0]])
    design = synthesize_observer_gain(A, C, decay=0.995)
    assert design.certificate.status == "proved"
    assert max(np.linalg.eigvals(A - design.L @ C).real) <= -0.995


@pytest.mark.parametrize("reason, shown", [("", "exact test of A - L C"), ("too close to call", "too close to call")])
def test_an_uncertified_gain_says_why_or_else_how_it_was_checked(monkeypatch, reason, shown):
    """When the exact re-check does not prove the decay, the error shows the certificate's reason, or its method
    when it gives no reason."""
    monkeypatch.setattr(synthesis, "lyapunov_decrease", lambda claim, vertices, decay, where: Certificate(
        claim, where, "exact test of A - L C", "inconclusive", reason=reason))
    with pytest.raises(UvsymError, match=rf"^the synthesised gain could not be certified at decay 1 1/s "
                                         rf"\(inconclusive: {shown}\)$"):
        synthesize_observer_gain(np.array([[0.0, 1.0], [-2.0, -0.1]]), np.array([[1.0, 0.0]]), decay=1.0)


def test_synthesis_scalar_optimum_matches_the_closed_form():
    # n = p = 1, A = 0, C = c: minimise P + |Y| s.t. P >= 1, 2 d P - 2 c Y <= -1e-6 with d = 1.01 + 1e-6,
    # so P = 1 and L = Y = (d + 5e-7) / c.
    # L is then rounded to GAIN_DIGITS (5) significant digits: 101000.15 -> 101000.
    c = 1e-5
    design = synthesize_observer_gain([[0.0]], [[c]], decay=1.0)
    assert design.P[0, 0] == pytest.approx(1.0, abs=1e-6)
    assert design.L[0, 0] == 101000.0


def test_a_rounded_gain_is_kept_only_where_it_certifies():
    """At decay 0 with an unobservable mode at 0.5 - l2, the optimum l2 = 0.5 + 5e-7 rounds to 0.5, a closed-loop
    eigenvalue at exactly 0: the solver's own gain is returned (strictly stable); at decay 0.8 the rounded one."""
    A, C = np.diag([-1.0, 0.5]), np.array([[0.0, 1.0]])
    edge = synthesize_observer_gain(A, C, decay=0.0).L
    assert edge[1, 0] > 0.5 and edge[1, 0] != round(edge[1, 0], 4)
    inside = synthesize_observer_gain(A, C, decay=0.8).L
    assert inside[1, 0] == float(f"{inside[1, 0]:.5g}") and inside[1, 0] > 1.3


def test_synthesis_diagonal_optimum_is_the_frobenius_minimiser():
    # C = I, A = diag(2, 0): with P = I the LMI asks Y + Y^T >= 2 diag(A + d) + 1e-6 I, whose least Frobenius
    # norm is Y = diag(a_i + d + 5e-7); d = 1.01 + 1e-6. The spectral norm would leave Y[1, 1] free.
    design = synthesize_observer_gain(np.diag([2.0, 0.0]), np.eye(2), decay=1.0)
    np.testing.assert_allclose(design.L, np.diag([3.0100015, 1.0100015]), atol=1e-4)
    np.testing.assert_array_equal(design.P, design.P.T)  # P is a symmetric variable, not symmetrised by the solver


def test_synthesis_passes_P_and_Y_to_the_equality_constraints():
    # Y fixed at 5 by an equality: 2 d P <= 10 - 1e-6 allows P = 1, so L = Y / P = 5.
    design = synthesize_observer_gain([[0.0]], [[1.0]], decay=1.0, equalities=[lambda P, Y: Y == 5.0])
    assert design.L[0, 0] == pytest.approx(5.0, abs=1e-5)


def test_synthesis_names_the_columns_C_must_have_from_the_rows_of_A():
    with pytest.raises(VerificationError, match=r"C have 2 columns; got A \(2, 3\)"):
        synthesize_observer_gain(np.ones((2, 3)), np.ones((1, 3)), 1.0)


def _patched_solve(monkeypatch, after):
    """Replace cvxpy's Problem.solve by the real one followed by ``after(problem)``."""
    import cvxpy as cp

    real = cp.Problem.solve

    def solve(self, *args, **kwargs):
        result = real(self, *args, **kwargs)
        after(self)
        return result

    monkeypatch.setattr(cp.Problem, "solve", solve)


def test_synthesis_silences_only_the_inaccurate_solution_warning(monkeypatch):
    import warnings

    inaccurate = "Solution may be inaccurate. Try another solver."
    _patched_solve(monkeypatch, lambda problem: warnings.warn(inaccurate, stacklevel=2))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        synthesize_observer_gain([[-1.0]], [[1.0]], decay=0.5)
    calls = []  # warn in the synthesis' own (first) solve only: the certificate may solve more problems

    def other_warning(problem):
        calls.append(problem)
        if len(calls) == 1:
            warnings.warn("something else", UserWarning, stacklevel=2)

    _patched_solve(monkeypatch, other_warning)
    with pytest.warns(UserWarning, match="something else"):
        synthesize_observer_gain([[-1.0]], [[1.0]], decay=0.5)


def test_synthesis_accepts_an_optimal_inaccurate_solution(monkeypatch):
    def inaccurate(problem):
        problem._status = "optimal_inaccurate"

    _patched_solve(monkeypatch, inaccurate)
    design = synthesize_observer_gain([[-1.0]], [[1.0]], decay=0.5)
    assert design.certificate.status == "proved"


def test_synthesis_rejects_a_solution_with_values_but_no_optimal_status(monkeypatch):
    def limited(problem):
        problem._status = "user_limit"

    _patched_solve(monkeypatch, limited)
    with pytest.raises(UvsymError, match="no observer gain with decay 0.5 1/s: the LMI at .*user_limit"):
        synthesize_observer_gain([[-1.0]], [[1.0]], decay=0.5)


def test_synthesis_names_a_non_finite_gain(monkeypatch):
    monkeypatch.setattr(synthesis.np.linalg, "solve", lambda a, b: np.full_like(b, np.nan))
    with pytest.raises(UvsymError, match="^L has entries that are not finite"):
        synthesize_observer_gain([[-1.0]], [[1.0]], decay=0.5)


def test_synthesis_keeps_P_symmetric_under_an_equality_on_one_entry():
    # A = -2 I is stable at the rate asked, so Y = 0; P >= I with P[0, 1] = 1/2 and least trace is
    # [[3/2, 1/2], [1/2, 3/2]] ((p1 - 1)(p2 - 1) >= 1/4 at p1 = p2). A non-symmetric P would let P[1, 0] cancel it.
    design = synthesize_observer_gain(-2 * np.eye(2), np.eye(2), decay=0.5, equalities=[lambda P, Y: P[0, 1] == 0.5])
    np.testing.assert_allclose(design.P, [[1.5, 0.5], [0.5, 1.5]], atol=1e-5)
    np.testing.assert_allclose(design.L, np.zeros((2, 2)), atol=1e-5)
