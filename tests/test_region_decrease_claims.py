"""region_decrease's certificates on one-state and two-state claims small enough to follow by hand.

Every claim here uses V = x^T x, so V' = 2 x^T f(x) and W = V' + gamma x^T x; the box counts follow from the
module docstring's search (a box inside the cube |x|_inf <= rho is not counted, a box is proved when W's upper
bound on it is negative, otherwise its centre is checked and it is bisected), worked out in each test.
"""

import time

import casadi as ca
import numpy as np
import pytest

from uvsym.verify import region
from uvsym.verify.region import region_decrease


def _one_state():
    x = ca.SX.sym("x", 1)
    return x, ca.dot(x, x)


def test_a_proved_claim_records_its_boxes_cube_and_pivot():
    # f = -x, gamma = 0: W = -2 x^2 on [-1, 1], cube |x| <= 1/4. Counted boxes: [-1, 1], its halves [-1, 0] and
    # [0, 1] (W = 0 at 0: not proved), their halves (4; [-1, -1/2], [1/2, 1] proved), then [-1/2, -1/4] and
    # [1/4, 1/2] proved ([-1/4, 0] and [0, 1/4] lie in the cube): 1 + 2 + 4 + 2 = 9. Hessian -4 exactly, so the
    # LDL^T of -(Hc + 0 I) = [4] has the pivot 4; the worst box bound is W(1/4) = -1/8.
    x, V = _one_state()
    started = time.perf_counter()
    proved = region_decrease("f = -x", V, -x, x, 0.0, [-1], [1], 0.25)
    elapsed = time.perf_counter() - started
    assert proved.status == "proved"
    assert proved.set == "-1 <= x <= 1"
    assert proved.details == {"boxes": 9, "cube_half_side": 0.25, "cube_hessian_pivot": 4.0}
    assert proved.margin == pytest.approx(0.125, rel=1e-12)
    assert proved.method == ("interval branch-and-bound over the CasADi graph (outward rounding, 9 boxes) outside "
                             "|x|_inf <= 0.25; inside it Taylor with the interval Hessian, exact rational LDL^T")
    # the time is that of this call: positive and within the time measured around it
    assert 0 < proved.seconds <= elapsed


def test_a_push_at_the_equilibrium_is_refuted_next_to_it_with_a_negative_margin():
    # f = -x + 1/2, gamma = 1/2: W = 2x(1/2 - x) + x^2/2 = x - 3x^2/2, positive on (0, 2/3); grad W(0) = 1
    x, V = _one_state()
    refuted = region_decrease("pushed", V, -x + 0.5, x, 0.5, [-1], [1], 0.1, expected="refuted")
    assert refuted.status == "refuted" and refuted.as_expected
    assert refuted.method == "W = V' + gamma x'x > 0 at a point near the equilibrium (interval evaluation)"
    assert refuted.details == {}  # found before any branch-and-bound
    example = refuted.counterexample
    (point,) = example["x"].values()
    assert 0 < point < 2 / 3 and list(example["x"]) == ["x"]
    W = point - 1.5 * point**2
    assert example["V_dot"] == pytest.approx(2 * point * (0.5 - point), abs=1e-15)
    assert example["gamma"] == 0.5
    assert example["bound"] == pytest.approx(-0.5 * point**2, rel=1e-15)
    # the margin of a refuted claim is minus how far W exceeds 0 there
    assert refuted.margin == pytest.approx(-W, rel=1e-9) and refuted.margin < 0


def test_a_quadratic_term_far_out_is_refuted_by_the_first_box_centre():
    # f = -x + x^2, gamma = 0: W = 2x^2 (x - 1); grad W(0) = 0, W''(0) = -4 (no point near 0), the cube holds.
    # The first box [-1, 4] is not proved and its centre 3/2 has W = 9/4 > 0: one box.
    x, V = _one_state()
    refuted = region_decrease("far term", V, -x + x**2, x, 0.0, [-1], [4], 0.1)
    assert refuted.status == "refuted"
    assert refuted.method == "interval branch-and-bound over the CasADi graph (outward rounding)"
    assert refuted.details == {"boxes": 1}
    assert refuted.counterexample == {"x": {"x": 1.5}, "V_dot": pytest.approx(2.25, rel=1e-12), "gamma": 0.0,
                                      "bound": 0.0}
    assert refuted.margin == pytest.approx(-2.25, rel=1e-12)


def test_an_undefined_centre_ends_the_search_as_inconclusive():
    # f = -x sqrt(1 - x), gamma = 1: W = -2 x^2 sqrt(1 - x) + x^2, W''(0) = -2; sqrt(1 - x) is undefined
    # right of 1, so the first box [-1, 5] is not proved and its centre 2 is undefined: one box.
    x, V = _one_state()
    result = region_decrease("sqrt", V, -x * ca.sqrt(1 - x), x, 1.0, [-1], [5], 0.5)
    assert result.status == "inconclusive"
    assert result.method == "interval branch-and-bound over the CasADi graph"
    assert result.reason == "V' may be undefined (an operation at or beyond its domain) at 2 <= x <= 2"
    assert result.details == {"boxes": 1}


def test_a_search_out_of_boxes_names_the_open_box_in_every_state():
    # f = -x in two states, gamma = 0: W = -2|x|^2 is 0 at the centre of the whole box, which is not proved
    # (W(0) = 0); with max_boxes = 0 the search stops after that one box.
    y = ca.SX.sym("y", 2)
    result = region_decrease("open", ca.dot(y, y), -y, y, 0.0, [-1, -2], [1, 2], 0.1, labels=("a (m)", "b (rad)"),
                             max_boxes=0)
    assert result.status == "inconclusive"
    assert result.set == "-1 <= a (m) <= 1, -2 <= b (rad) <= 2"
    assert result.method == "interval branch-and-bound over the CasADi graph"
    assert result.reason == "1 boxes without a decision; e.g. -1 <= a (m) <= 1, -2 <= b (rad) <= 2"
    assert result.details == {"boxes": 1}


def test_a_flat_equilibrium_is_inconclusive_after_the_search_outside_the_cube():
    # f = -x^3, gamma = 0: W = -2 x^4 < 0 except at 0, but W''(0) = 0, so no cube down to 1/2 / 2^6 = 1/128 is
    # certified and that smallest cube is left out. Counted boxes: [-1, 1]; the two boxes touching 0 of widths
    # 1, 1/2, ..., 1/64 (not proved: W = 0 at 0), 14; their siblings [w, 2w] and [-2w, -w] for w = 1/2 .. 1/128,
    # proved, 14: 29 in all.
    x, V = _one_state()
    result = region_decrease("flat", V, -x**3, x, 0.0, [-1], [1], 0.5)
    assert result.status == "inconclusive"
    assert result.method == "interval Hessian on a cube around the equilibrium"
    assert result.reason == ("the interval Hessian of W is not negative definite on |x|_inf <= 0.0078125; "
                             "no counterexample outside it (29 boxes)")
    assert result.details == {"boxes": 29}


def test_bounds_at_the_equilibrium_are_one_row():
    # W = -x0^2 - 3 x1^2 + x0 x1: W(0) = 0, grad W(0) = 0, Hessian [[-2, 1], [1, -6]] (vec, 1 row of 4)
    x = ca.SX.sym("x", 2)
    value, gradient, hessian = region._Decrease(-x[0] ** 2 - 3 * x[1] ** 2 + x[0] * x[1], x).at_equilibrium()
    for bounds, expected in ((value, [[0.0]]), (gradient, [[0.0, 0.0]]), (hessian, [[-2.0, 1.0, 1.0, -6.0]])):
        assert np.array_equal(bounds.lo, expected) and np.array_equal(bounds.hi, expected)
        assert bounds.defined.shape == (1,)


def test_the_search_gets_the_documented_default_budget(monkeypatch):
    # help(region_decrease) shows max_boxes = 2_000_000 and batch = 8192: the search must get exactly those
    seen = {}
    search = region._branch_and_bound

    def spy(decrease, lower, upper, cube, scale, max_boxes, batch, claim, labels):
        seen.update(max_boxes=max_boxes, batch=batch)
        return search(decrease, lower, upper, cube, scale, max_boxes, batch, claim, labels)

    monkeypatch.setattr(region, "_branch_and_bound", spy)
    x, V = _one_state()
    assert region_decrease("f = -x", V, -x, x, 0.0, [-1], [1], 0.25).status == "proved"
    assert seen == {"max_boxes": 2_000_000, "batch": 8192}
