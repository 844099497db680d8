"""The bounds inside ``uvsym.verify.region``: the upper bound of W on boxes (plain interval and mean-value
forms), the exact Hessian certificate on the cube around the equilibrium, the halving of that cube, and the
branch-and-bound's bookkeeping (box count, worst bound, progress fractions, the point or box it stops at).

Every W is a small polynomial (or |.|, sqrt) whose bounds on the boxes used are worked out by hand in the
test's docstring; the functions are called directly, one to three states, a handful of boxes each.
"""

import warnings
from fractions import Fraction

import casadi as ca
import numpy as np
import pytest

from uvsym.errors import VerificationError
from uvsym.verify.region import _cube_certificate, _Decrease, _taylor_cube


def _one(expression):
    """_Decrease of W(x) = expression(x) for one state x."""
    x = ca.SX.sym("x")
    return _Decrease(expression(x), x)


def _box(*bounds):
    """One box (1, n) as lo, hi arrays from (lo_i, hi_i) pairs."""
    return np.array([[b[0] for b in bounds]], dtype=float), np.array([[b[1] for b in bounds]], dtype=float)


# ---------------------------------------------------------------- _Decrease: names and upper bounds


@pytest.mark.parametrize("part, name", [("W", "W"), ("grad", "grad_W"), ("hess", "hess_W")])
def test_each_interval_function_of_W_names_itself_in_its_errors(part, name):
    """A reversed box given to W, its gradient or its Hessian is a VerificationError that starts with that
    function's name (W, grad_W, hess_W), so a failure says which of the three it came from."""
    decrease = _one(lambda x: -x * x)
    with pytest.raises(VerificationError) as error:
        getattr(decrease, part)(np.array([[1.0]]), np.array([[0.0]]))
    assert str(error.value).startswith(f"{name}: a box has a lower bound above its upper bound")


def test_upper_bound_takes_the_mean_value_form_when_it_is_lower():
    """W = x^2 - 4 x on [1.5, 2.5]. Plain: [2.25, 6.25] - [6, 10] gives hi 0.25. Mean value around the centre
    c = 2: W(2) = -4, |W'| = |2 x - 4| <= 1 on the box, half-width 0.5, so -4 + 0.5 = -3.5 (the true maximum is
    -3.75 at both ends). The bound is -3.5 up to the upward roundings."""
    bound = _one(lambda x: x * x - 4 * x).upper_bound(*_box((1.5, 2.5)))
    assert bound.shape == (1,)
    assert -3.5 <= bound[0] <= -3.5 + 1e-12


def test_upper_bound_keeps_the_plain_form_where_W_has_a_kink_in_the_box():
    """W = -1 + |a| + 2 c - c - c (summed left to right), two boxes with c in [-1, 1]. For a in [1, 2] W is
    smooth: plain -1 + [1, 2] + [-4, 4] gives 5, mean value W(1.5, 0) + 1 * 0.5 + 0 * 1 = 1. For a in [-1, 1]
    |a| has its kink inside, so only the plain form counts: -1 + [0, 1] + [-4, 4] gives 4 (the mean-value
    form, -1 + 1 * 1 + 0 * 1 = 0, is not used)."""
    v = ca.SX.sym("v", 2)
    decrease = _Decrease(-1 + ca.fabs(v[0]) + 2 * v[1] - v[1] - v[1], v)
    bound = decrease.upper_bound(np.array([[1.0, -1.0], [-1.0, -1.0]]), np.array([[2.0, 1.0], [1.0, 1.0]]))
    assert bound.shape == (2,)
    assert 1.0 <= bound[0] <= 1.0 + 1e-12
    assert 4.0 <= bound[1] <= 4.0 + 1e-12


def test_upper_bound_adds_the_full_slope_times_a_half_width_of_exactly_one():
    """W = x - 3 on [0, h], h = 2 - 2^-52 (the largest double below 2): the centre is 1 - 2^-53 and the rounded
    half-width is exactly 1, which must still count (slope 1 times 1). The bound may not drop below the true
    maximum W(h) = h - 3 = -(1 + 2^-52)."""
    h = 2 - 2.0**-52
    bound = _one(lambda x: x - 3).upper_bound(*_box((0.0, h)))
    assert -(1 + 2.0**-52) <= bound[0] <= -1 + 1e-12


def test_upper_bound_is_infinite_and_silent_where_the_mean_value_products_overflow():
    """W = 1e300 x on [1, 3e10]: both forms overflow (3e310 > the largest double), so the bound is +inf, and
    the overflow inside the mean-value form raises no floating-point warning."""
    decrease = _one(lambda x: 1e300 * x)
    with np.errstate(all="warn"), warnings.catch_warnings():
        warnings.simplefilter("error")
        bound = decrease.upper_bound(*_box((1.0, 3e10)))
    assert bound[0] == np.inf


# ---------------------------------------------------------------- the Hessian certificate on the cube


def test_cube_certificate_pivot_is_minus_the_largest_second_derivative_in_one_state():
    """W = -x^2 + x^3 / 3 on |x| <= 1/4: W'' = -2 + 2 x lies in [-5/2, -3/2], centre -2, radius 1/2, so
    -(centre + radius) = 3/2 = -max W'' (less the outward rounding of the interval Hessian, an ulp or so)."""
    proved, pivot = _cube_certificate(_one(lambda x: -x * x + x**3 / 3), 0.25)
    assert proved is True
    assert Fraction(3, 2) - Fraction(1, 2**40) < pivot <= Fraction(3, 2)


def test_cube_certificate_puts_the_radius_on_the_diagonal_only():
    """W = -x^2 + x^3 / 3 - y^2 on |x|, |y| <= 1/4: the Hessian is diag([-5/2, -3/2], -2), off-diagonal 0, and
    the Frobenius radius 1/2 (only one entry has width 1), so -(Hc + r I) = diag(3/2, 3/2): both LDL^T pivots
    3/2. A radius on the off-diagonal entries too would lower the second pivot to 3/2 - (1/4) / (3/2) = 4/3."""
    v = ca.SX.sym("v", 2)
    proved, pivot = _cube_certificate(_Decrease(-v[0] * v[0] + v[0] ** 3 / 3 - v[1] * v[1], v), 0.25)
    assert proved is True
    assert Fraction(3, 2) - Fraction(1, 2**40) < pivot <= Fraction(3, 2)


def test_cube_certificate_is_not_proved_where_a_hessian_bound_overflows():
    """W = -x^2 - exp(x) on |x| <= 1000: W'' = -2 - exp(x) lies in [-2 - e^1000, -2 - e^-1000]; e^1000 is beyond
    the doubles, so the lower bound is -inf (the upper one finite) and nothing is proved (no pivot)."""
    assert _cube_certificate(_one(lambda x: -x * x - ca.exp(x)), 1000.0) == (False, None)


# ---------------------------------------------------------------- halving the cube


def test_taylor_cube_halves_rho_until_the_hessian_is_negative_definite():
    """W = -x^2 + 16 x^3, rho = 1: W'' = -2 + 96 x on |x| <= s is negative definite exactly when 96 s < 2,
    s < 1/48; the halvings 1, 1/2, ..., 1/32 fail and 1/64 holds, with pivot 2 - 96/64 = 1/2."""
    cube, pivot, why = _taylor_cube(_one(lambda x: -x * x + 16 * x**3), 1.0)
    assert (cube, why) == (1 / 64, "")
    assert Fraction(1, 2) - Fraction(1, 2**40) < pivot <= Fraction(1, 2)


def test_taylor_cube_gives_up_after_six_halvings():
    """W = -x^2 + 32 x^3: W'' = -2 + 192 x needs s < 1/96, below the smallest cube tried, 1 / 2^6 = 1/64."""
    cube, pivot, why = _taylor_cube(_one(lambda x: -x * x + 32 * x**3), 1.0)
    assert (cube, pivot) == (1 / 64, None)
    assert why == "the interval Hessian of W is not negative definite on |x|_inf <= 0.015625"


def test_taylor_cube_needs_W_itself_to_vanish_at_zero_not_only_its_gradient():
    """W = 1 - x^2: grad W(0) = 0 but W(0) = 1, so the Taylor argument does not apply (although W'' = -2 < 0);
    the smallest cube is reported, 0.5 / 2^6."""
    cube, pivot, why = _taylor_cube(_one(lambda x: 1 - x * x), 0.5)
    assert (cube, pivot) == (0.5 / 64, None)
    assert why.startswith("W or its gradient at x = 0 is not exactly 0 in interval arithmetic")
