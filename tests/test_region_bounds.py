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
from uvsym.verify import region
from uvsym.verify.region import _branch_and_bound, _cube_certificate, _Decrease, _taylor_cube


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


def test_upper_bound_skips_the_gradient_when_no_box_is_smooth_and_defined():
    """The same W on two boxes with a in [-1, 1] (kink inside, defined) and c in [-1, 1] or [0, 1]: the
    mean-value form could serve none of them, so grad W is never evaluated; the plain bounds are 4 and 2
    (-1 + [0, 1] + [-4, 4], -1 + [0, 1] + [-2, 2])."""
    v = ca.SX.sym("v", 2)
    decrease = _Decrease(-1 + ca.fabs(v[0]) + 2 * v[1] - v[1] - v[1], v)
    gradient, calls = decrease.grad, []
    decrease.grad = lambda lo, hi: calls.append(len(lo)) or gradient(lo, hi)
    bound = decrease.upper_bound(np.array([[-1.0, -1.0], [-1.0, 0.0]]), np.array([[1.0, 1.0], [1.0, 1.0]]))
    assert calls == []
    assert 4.0 <= bound[0] <= 4.0 + 1e-12 and 2.0 <= bound[1] <= 2.0 + 1e-12


def test_upper_bound_adds_the_full_slope_times_a_half_width_of_exactly_one():
    """W = x - 3 on [0, h], h = 2 - 2^-52 (the largest double below 2): the centre is 1 - 2^-53 and the rounded
    half-width is exactly 1, which must still count (slope 1 times 1). The bound may not drop below the true
    maximum W(h) = h - 3 = -(1 + 2^-52)."""
    h = 2 - 2.0**-52
    bound = _one(lambda x: x - 3).upper_bound(*_box((0.0, h)))
    assert -(1 + 2.0**-52) <= bound[0] <= -1 + 1e-12


def test_upper_bound_skips_sides_of_width_zero_in_the_mean_value_form():
    """W = -1 + a b^2 + 2 c - c - c (summed left to right) on a = 0, b = 1e200, c in [-1, 1]: the plain form gives
    -1 + 0 + [-4, 4], hi 3. dW/db = 2 a b = 0 and dW/dc = 0, dW/da = b^2 = 1e400 overflows to an unbounded
    interval, but a does not vary (width 0), so the mean-value form is W(0, 1e200, 0) = -1 plus nothing: -1."""
    v = ca.SX.sym("v", 3)
    decrease = _Decrease(-1 + v[0] * v[1] * v[1] + 2 * v[2] - v[2] - v[2], v)
    bound = decrease.upper_bound(*_box((0.0, 0.0), (1e200, 1e200), (-1.0, 1.0)))
    assert -1.0 <= bound[0] <= -1.0 + 1e-12


def test_a_box_one_ulp_wide_whose_centre_rounds_to_its_lower_end_keeps_its_half_width():
    """W = 1e20 (x - 1) on [1, 1 + 2^-52]: the centre 1 + 2^-53 rounds (to even) onto the lower end, where W is 0, yet
    the box has width: the bound must hold at the upper end, 1e20 2^-52 = 22,204.46... exactly."""
    v = ca.SX.sym("v")
    hi = np.nextafter(1.0, 2.0)
    assert 0.5 * (1.0 + hi) == 1.0
    bound = _Decrease(1e20 * (v - 1), v).upper_bound(*_box((1.0, hi)))
    assert Fraction(bound[0]) >= Fraction(1e20) * (Fraction(hi) - 1)


def test_upper_bound_is_infinite_and_silent_where_the_mean_value_products_overflow():
    """W = 1e300 x on [1, 3e10]: both forms overflow (3e310 > the largest double), so the bound is +inf, and
    the overflow inside the mean-value form raises no floating-point warning."""
    decrease = _one(lambda x: 1e300 * x)
    with np.errstate(all="warn"), warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
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


# ---------------------------------------------------------------- branch-and-bound bookkeeping

CLAIM = "W = V' + gamma x'x stays negative on the whole test box"


class _Bar:
    """Stands in for ProgressBar: keeps the label and every fraction drawn."""

    def __init__(self, label):
        self.label, self.fractions, self.closed = label, [], False

    def __call__(self, fraction):
        self.fractions.append(fraction)

    def close(self):
        self.closed = True


@pytest.fixture
def bars(monkeypatch):
    """The progress bars the search opens (in order), recorded instead of drawn."""
    opened = []

    def bar(label):
        opened.append(_Bar(label))
        return opened[-1]

    monkeypatch.setattr(region, "ProgressBar", bar)
    return opened


def _search(expression, lower, upper, cube, max_boxes=50, batch=8192):
    """_branch_and_bound of W(x) = expression(x), one state labelled x, on [lower, upper] outside |x| <= cube."""
    return _branch_and_bound(_one(expression), np.array([lower], dtype=float), np.array([upper], dtype=float),
                             cube, np.array([1.0]), max_boxes, batch, CLAIM, ("x",))


def test_search_one_box_at_a_time_counts_boxes_and_reports_progress_in_fractions_of_the_box(bars):
    """W = -x^2 on [-1, 3] outside |x| <= 1/4, one box per batch (breadth first, left halves first). Boxes
    holding 0 have the upper bound 0 (not < 0) and are halved; the others are proved by the plain form.
    [-1, 3], [-1, 1] undecided; [1, 3] proved (1/2 of the box); [-1, 0], [0, 1] undecided; [-1, -1/2] proved
    (5/8); [-1/2, 0], [0, 1/2] undecided; [1/2, 1], [-1/2, -1/4] proved; [-1/4, 0], [0, 1/4] inside the cube;
    [1/4, 1/2] proved: 11 boxes outside the cube, the worst bound -sq(1/4) = -1/16 (on [-1/2, -1/4] and
    [1/4, 1/2]). The bar is drawn after each undecided box: 0, 0, 1/2, 1/2, 5/8, 5/8."""
    search = _search(lambda x: -x * x, -1, 3, 0.25, batch=1)
    assert search["boxes"] == 11 and set(search) == {"boxes", "worst"}
    assert -1 / 16 <= search["worst"] <= -1 / 16 + 1e-12
    (bar,) = bars
    assert bar.label == "branch-and-bound W = V' + gamma x'x stays negative on the"
    assert bar.fractions == [0.0, 0.0, 0.5, 0.5, 0.625, 0.625]
    assert bar.closed


def test_search_counts_boxes_on_the_cube_s_boundary_as_settled(bars):
    """W = -x^2 + 2 x - x - x (summed left to right: 2 x - x - x is 0, but its plain interval is not) on
    [-1/2, 3/2] outside |x| <= 1/2, one box per batch. [-1/2, 3/2]: plain hi 4, mean value -1/4 + 3 * 1 > 0,
    halved. [-1/2, 1/2] lies in the cube (its ends on the cube's faces): half the box settled. [1/2, 3/2]:
    mean value -1 + 3 / 2 > 0, halved, drawn at 1/2. [1/2, 1]: -9/16 + 2 / 4 = -1/16; [1, 3/2]:
    -25/16 + 3 / 4 = -13/16. 4 boxes, worst -1/16, drawn 0 and 1/2."""
    search = _search(lambda x: -x * x + 2 * x - x - x, -0.5, 1.5, 0.5, batch=1)
    assert search["boxes"] == 4 and set(search) == {"boxes", "worst"}
    assert -1 / 16 <= search["worst"] <= -1 / 16 + 1e-12
    assert bars[0].fractions == [0.0, 0.5]


def test_search_sums_the_shares_of_the_boxes_proved_together(bars):
    """W = -x^2 on [-1, 1] outside |x| <= 1/4, all boxes of a level in one batch: [-1, 1]; [-1, 0], [0, 1];
    then [-1, -1/2] and [1/2, 1] are proved together (1/4 + 1/4 of the box) while [0, 1/2], [-1/2, 0] are
    halved; the last level is proved or in the cube. 1 + 2 + 4 + 2 = 9 boxes, drawn at 0, 0, 1/2."""
    search = _search(lambda x: -x * x, -1, 1, 0.25)
    assert search["boxes"] == 9 and set(search) == {"boxes", "worst"}
    assert -1 / 16 <= search["worst"] <= -1 / 16 + 1e-12
    assert bars[0].fractions == [0.0, 0.0, 0.5]


@pytest.mark.parametrize("max_boxes, expected", [(6, {"boxes": 7, "open": "0 <= x <= 0.5"}), (7, {"boxes": 9})])
def test_search_stops_once_more_than_max_boxes_were_bounded(bars, max_boxes, expected):
    """The previous search bounds 1, 3, 7, 9 boxes in its four batches. With max_boxes 6 it stops after the
    third (7 > 6), naming the first undecided box of that batch, [0, 1/2] (the batch is [-1, -1/2], [0, 1/2],
    [-1/2, 0], [1/2, 1]); with max_boxes 7 it goes on (7 is not more than 7) and proves the claim."""
    search = _search(lambda x: -x * x, -1, 1, 0.25, max_boxes=max_boxes)
    assert {key: search[key] for key in expected} == expected
    assert set(search) == set(expected) | ({"worst"} if "open" not in expected else set())


def test_search_halves_each_box_along_its_widest_side_relative_to_the_scale(bars):
    """W = -a^2 - b^2 on a in [-1, 1], b in [-2, 2] with scale (1, 4): relative widths (2, 1), so the first box
    is halved along a. Stopped after that (3 boxes > max_boxes 1), the first open box is its left half."""
    v = ca.SX.sym("v", 2)
    search = _branch_and_bound(_Decrease(-v[0] * v[0] - v[1] * v[1], v), np.array([-1.0, -2.0]),
                               np.array([1.0, 2.0]), 0.25, np.array([1.0, 4.0]), 1, 8192, CLAIM, ("a", "b"))
    assert search == {"boxes": 3, "open": "-1 <= a <= 0, -2 <= b <= 2"}


def test_search_returns_the_box_centre_where_W_is_positive(bars):
    """W = 3/4 - (x - 1)^2 on [-1, 3]: the first box is not proved and W(1) = 3/4 > 0 at its centre."""
    search = _search(lambda x: 0.75 - (x - 1) ** 2, -1, 3, 0.25, max_boxes=20)
    assert search["boxes"] == 1 and search["counterexample"].tolist() == [1.0]


def test_search_returns_the_first_centre_where_W_may_be_undefined(bars):
    """W = -x^2 - sqrt(1 - x) on [-1, 3]: the box reaches x > 1 (undefined), its centre 1 does not (W = -1).
    Halves [-1, 1] (defined, upper bound 0, centre 0 with W = -1) and [1, 3] (undefined, centre 2 too): the
    search stops at x = 2 after 3 boxes."""
    search = _search(lambda x: -x * x - ca.sqrt(1 - x), -1, 3, 0.25, max_boxes=20)
    assert search["boxes"] == 3 and search["undefined"].tolist() == [2.0]


def test_search_does_not_count_an_upper_bound_of_exactly_zero_as_proved(bars):
    """W = -|x| on [-1, 1] outside |x| <= 1/4: every box with an end at 0 has the exact upper bound 0 (|.| and
    negation are exact), which does not prove W < 0; they are halved down to the cube. Boxes: [-1, 1];
    [-1, 0], [0, 1]; [-1, -1/2] and [1/2, 1] proved, [0, 1/2], [-1/2, 0] halved; [-1/2, -1/4] and [1/4, 1/2]
    proved with bound -1/4: 9 boxes, worst -1/4."""
    search = _search(lambda x: -ca.fabs(x), -1, 1, 0.25)
    assert search["boxes"] == 9 and set(search) == {"boxes", "worst"}
    assert -0.25 <= search["worst"] <= -0.25 + 1e-12
