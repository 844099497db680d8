"""Counterexamples near the equilibrium and input validation of ``region_decrease``.

``_equilibrium_counterexample`` walks from x = 0 along the gradient of W = V' + gamma x'x at 0 (when it is
not 0) and along the top eigenvector of its Hessian (when that eigenvalue is > 0), each direction scaled
so that its largest entry relative to ``scale`` is 1, at steps t = 1/2, 1/4, ..., 2^-39, both signs (+t
first). Every W below is a polynomial whose sign along those points is worked out by hand, so the point
returned (or None) is known exactly; no W is close to 0 at any point tried, so outward rounding decides nothing.
"""

import re

import casadi as ca
import numpy as np
import pytest

from uvsym.errors import VerificationError
from uvsym.verify.interval import Intervals
from uvsym.verify.region import _Decrease, _equilibrium_counterexample, _inputs, region_decrease


def _search(W: ca.SX, x: ca.SX, scale) -> np.ndarray | None:
    """The near-equilibrium counterexample of W (with W's own gradient and Hessian at 0)."""
    decrease = _Decrease(W, x)
    _, gradient, hessian = decrease.at_equilibrium()
    return _equilibrium_counterexample(decrease, gradient, hessian, np.asarray(scale, dtype=float))


def _exact(lo, hi) -> Intervals:
    """Bounds of one box (1, m) lo..hi, smooth and defined."""
    lo, hi = np.atleast_2d(np.asarray(lo, dtype=float)), np.atleast_2d(np.asarray(hi, dtype=float))
    return Intervals(lo, hi, np.ones(1, dtype=bool), np.ones(1, dtype=bool))


# ---- the gradient direction -------------------------------------------------------------------------------------

def test_a_linear_w_is_refuted_along_its_gradient_at_the_first_step():
    """W = x1 + 2 x2: grad (1, 2), Hessian 0. Direction (1, 2) / max(|1|/1, |2|/1) = (0.5, 1); at t = 1/2 the
    point (0.25, 0.5) has W = 1.25 > 0 and comes first."""
    x = ca.SX.sym("x", 2)
    point = _search(x[0] + 2 * x[1], x, [1.0, 1.0])
    np.testing.assert_array_equal(point, [0.25, 0.5])


def test_the_gradient_direction_is_scaled_by_the_box_not_by_its_length():
    """W = x1 + 2 x2 with scale (4, 1): direction (1, 2) / max(1/4, 2/1) = (0.5, 1); first point (0.25, 0.5)."""
    x = ca.SX.sym("x", 2)
    point = _search(x[0] + 2 * x[1], x, [4.0, 1.0])
    np.testing.assert_array_equal(point, [0.25, 0.5])


def test_the_minus_side_is_returned_when_only_it_is_positive():
    """W = x - 8 x^3, scale 2: grad 1, Hessian 0, direction 1 / (1/2) = 2. At t = 1/2 the points are 1 and -1:
    W(1) = -7, W(-1) = 7 > 0, so -1 (the second point) is the counterexample."""
    x = ca.SX.sym("x")
    point = _search(x - 8 * x ** 3, x, [2.0])
    np.testing.assert_array_equal(point, [-1.0])


def test_a_huge_but_finite_gradient_still_gives_its_counterexample():
    """W = 7e307 x: the gradient bounds sum to 1.4e308 (finite); their midpoint 7e307 gives direction 1 and
    W(1/2) = 3.5e307 > 0."""
    x = ca.SX.sym("x")
    point = _search(7e307 * x, x, [1.0])
    np.testing.assert_array_equal(point, [0.5])


# ---- the Hessian direction --------------------------------------------------------------------------------------

def test_a_positive_curvature_is_refuted_at_half_the_scale():
    """W = x1^2 (two states, scale (2, 1)): grad 0, Hessian diag(2, 0), top eigenvector +-(1, 0), scaled to
    +-(2, 0); at t = 1/2 both +-(1, 0) have W = 1 > 0, the first is returned (its sign follows the eigenvector)."""
    x = ca.SX.sym("x", 2)
    point = _search(x[0] ** 2, x, [2.0, 1.0])
    assert point is not None
    np.testing.assert_array_equal(np.abs(point), [1.0, 0.0])


def test_an_eigenvalue_of_exactly_one_is_used():
    """W = x^2 / 2: Hessian 1 (> 0), W(1/2) = 1/8 > 0."""
    x = ca.SX.sym("x")
    point = _search(0.5 * x ** 2, x, [1.0])
    assert point is not None
    np.testing.assert_array_equal(np.abs(point), [0.5])


def test_a_huge_but_finite_curvature_still_gives_its_counterexample():
    """W = 3.5e307 x1^2 (two states): Hessian diag(7e307, 0), finite with its transpose added; W(+-1/2, 0) =
    8.75e306 > 0."""
    x = ca.SX.sym("x", 2)
    point = _search(3.5e307 * x[0] ** 2, x, [1.0, 1.0])
    assert point is not None
    np.testing.assert_array_equal(np.abs(point), [0.5, 0.0])


def test_a_positive_curvature_seen_only_at_the_last_step_is_found_there():
    """W = x^2 - 2^79 x^4 = x^2 (1 - 2^79 x^2) > 0 iff x^2 < 2^-79: at t = 2^-39, 2^79 t^2 = 2 (W < 0); at
    t = 2^-40 it is 1/2 (W > 0) but the walk stops at 2^-39: None."""
    x = ca.SX.sym("x")
    assert _search(x ** 2 - 2.0 ** 79 * x ** 4, x, [1.0]) is None


def test_the_last_step_is_two_to_the_minus_39():
    """W = x^2 - 2^77 x^4 > 0 iff x^2 < 2^-77: t = 2^-38 gives 2^77 t^2 = 2 (W < 0), t = 2^-39 gives 1/2: the
    point is +-2^-39."""
    x = ca.SX.sym("x")
    point = _search(x ** 2 - 2.0 ** 77 * x ** 4, x, [1.0])
    assert point is not None
    np.testing.assert_array_equal(np.abs(point), [2.0 ** -39])


def test_no_direction_when_the_gradient_is_zero_and_the_curvature_not_positive():
    """W = -x^2 + 4 x^3 is > 0 at x = 1/2 (W = 1/4), but grad 0 and Hessian -2 < 0 offer no direction: None
    (the branch-and-bound finds such points)."""
    x = ca.SX.sym("x")
    assert _search(-x ** 2 + 4 * x ** 3, x, [1.0]) is None


def test_no_direction_when_the_curvature_is_zero():
    """W = x^3: grad 0, Hessian 0 (not > 0): None, although W(1/2) = 1/8 > 0."""
    x = ca.SX.sym("x")
    assert _search(x ** 3, x, [1.0]) is None


# ---- undefined derivatives --------------------------------------------------------------------------------------

def test_an_undefined_hessian_gives_no_counterexample_even_with_a_gradient():
    """A finite gradient 1 with a Hessian bounded only by (-inf, inf) (undefined): no counterexample, although
    W = x has W(1/2) > 0 along the gradient."""
    x = ca.SX.sym("x")
    decrease = _Decrease(x, x)
    assert _equilibrium_counterexample(decrease, _exact([1.0], [1.0]), _exact([-np.inf], [np.inf]),
                                       np.ones(1)) is None


def test_an_undefined_gradient_gives_no_counterexample_even_with_a_curvature():
    """Gradient bounded by (-inf, inf), Hessian 2: no counterexample although W = x^2 > 0 away from 0."""
    x = ca.SX.sym("x")
    decrease = _Decrease(x ** 2, x)
    assert _equilibrium_counterexample(decrease, _exact([-np.inf], [np.inf]), _exact([2.0], [2.0]),
                                       np.ones(1)) is None


def test_an_undefined_gradient_raises_no_floating_point_error():
    """inf + (-inf) in the midpoint of an undefined gradient is expected: it must not raise even when the
    caller makes invalid operations raise."""
    x = ca.SX.sym("x")
    decrease = _Decrease(x ** 2, x)
    with np.errstate(invalid="raise"):
        assert _equilibrium_counterexample(decrease, _exact([-np.inf], [np.inf]), _exact([np.inf], [-np.inf]),
                                           np.ones(1)) is None


def test_region_decrease_reports_the_near_equilibrium_point():
    """V = x^2 / 2, x' = x (unstable): V' = x^2, W = 2 x^2 with gamma = 1; the box [-1, 2] has scale 1, so the
    counterexample is x = +-1/2 with V' = 1/4 and bound -1/4, refuted near the equilibrium."""
    x = ca.SX.sym("x")
    certificate = region_decrease("unstable lag", 0.5 * x ** 2, x, x, 1.0, [-1.0], [2.0], 0.1, labels=("q",))
    assert certificate.status == "refuted"
    assert certificate.method.startswith("W = V' + gamma x'x > 0 at a point near the equilibrium")
    example = certificate.counterexample
    assert abs(example["x"]["q"]) == 0.5
    assert example["V_dot"] == 0.25
    assert example["bound"] == -0.25
    assert certificate.margin == pytest.approx(-0.5, rel=1e-12)  # -(a lower bound of W = 1/2), rounded outward
    assert certificate.margin >= -0.5


# ---- input validation -------------------------------------------------------------------------------------------

def _call(V=None, x_dot=None, x=None, gamma=1.0, lower=(-1.0,), upper=(1.0,), rho=0.1, labels=None):
    """region_decrease on a one-state claim (V = x^2, x' = -x unless given)."""
    s = ca.SX.sym("s")
    x = s if x is None else x
    V = s ** 2 if V is None else V
    x_dot = -s if x_dot is None else x_dot
    return region_decrease("claim", V, x_dot, x, gamma, lower, upper, rho, labels=labels)


@pytest.mark.parametrize("which", ["V", "x_dot", "x"])
def test_a_non_sx_argument_is_named_with_its_type(which):
    m = ca.MX.sym("m")
    with pytest.raises(VerificationError, match=rf"^{which} must be a CasADi SX expression, got MX$"):
        _call(**{which: m})


def test_x_must_be_a_column_of_symbols():
    message = "^x must be a column vector of SX symbols$"
    row = ca.SX.sym("r", 1, 2)
    with pytest.raises(VerificationError, match=message):  # a row of symbols
        _call(V=row[0] ** 2, x_dot=-row.T, x=row)
    s = ca.SX.sym("s")
    with pytest.raises(VerificationError, match=message):  # a column, not all symbols
        _call(V=s ** 2, x_dot=ca.vertcat(-s, -s), x=ca.vertcat(s, 2 * s))


def test_free_symbols_of_v_and_x_dot_are_listed():
    s, a, b = ca.SX.sym("s"), ca.SX.sym("a"), ca.SX.sym("b")
    expected = re.escape("V and x_dot may depend on x only; free symbol(s) a, b (substitute their values first)")
    with pytest.raises(VerificationError, match=f"^{expected}$"):
        _call(V=b * s ** 2, x_dot=-a * s, x=s)
    with pytest.raises(VerificationError, match=re.escape("free symbol(s) b (")):  # in V only
        _call(V=b * s ** 2, x_dot=-s, x=s)


def test_a_mis_sized_x_dot_is_rejected_with_both_shapes():
    s = ca.SX.sym("s")
    expected = re.escape("V must be scalar and x_dot have 1 entries, got (1, 1) and (2, 1)")
    with pytest.raises(VerificationError, match=f"^{expected}$"):
        _call(V=s ** 2, x_dot=ca.vertcat(-s, -s), x=s)


@pytest.mark.parametrize("which", ["lower", "upper"])
def test_a_non_numeric_bound_is_named(which):
    with pytest.raises(VerificationError, match=rf"^{which} must be 1 numbers, got 'abc'$"):
        _call(**{which: "abc"})
    with pytest.raises(VerificationError, match=rf"^{which} must be 1 finite numbers \(like x\), got \[inf\]$"):
        _call(**{which: [np.inf]})


@pytest.mark.parametrize("lower, upper", [([0.0], [1.0]), ([-1.0], [0.0])])
def test_the_box_must_hold_zero_strictly_inside(lower, upper):
    with pytest.raises(VerificationError, match=r"^the box must hold the equilibrium x = 0 inside: lower "):
        _call(lower=lower, upper=upper)


def test_gamma_and_rho_must_be_numbers():
    with pytest.raises(VerificationError, match=r"^gamma and rho must be numbers, got 'abc' and 0\.1$"):
        _call(gamma="abc")


def _validated(gamma=1.0, rho=0.1, lower=(-1.0,), upper=(1.0,)):
    s = ca.SX.sym("s")
    return _inputs(s ** 2, -s, s, gamma, lower, upper, rho, None)


def test_gamma_zero_is_accepted():
    gamma, lower, upper, rho, labels = _validated(gamma=0)
    assert (gamma, rho, labels) == (0.0, 0.1, ("s",))
    np.testing.assert_array_equal(lower, [-1.0])
    np.testing.assert_array_equal(upper, [1.0])


@pytest.mark.parametrize("rho", [0.0, 0.5])
def test_rho_must_be_strictly_between_zero_and_the_smallest_half_width(rho):
    """Box [-0.5, 2]: the smallest half-width is 0.5, so 0 and 0.5 are both out."""
    with pytest.raises(VerificationError, match=rf"^rho must satisfy 0 < rho < the box's half-widths, got {rho}$"):
        _validated(rho=rho, lower=(-0.5,), upper=(2.0,))
    assert _validated(rho=0.4999, lower=(-0.5,), upper=(2.0,))[3] == 0.4999


def test_labels_must_match_x():
    with pytest.raises(VerificationError, match=r"^labels must have 1 entries, like x, got 2$"):
        _call(labels=("a", "b"))
