"""Construction and calls of :class:`uvsym.verify.interval.IntervalFunction`: which Functions it accepts (and the
messages naming what it rejects), the shapes and dtypes of the boxes it takes, how ``defined`` accumulates over
the operations, the whole-line bounds of an operation outside its domain and the kink of ``if_else_zero``.

Expected values come from the mathematics (exact integer products, the domain of sqrt, where a conditional
jumps); every test builds its own Function (no shared fixture), so that each is credited with the code it runs.
"""

from __future__ import annotations

import re
import warnings

import casadi as ca
import numpy as np
import pytest

from uvsym.errors import VerificationError
from uvsym.verify.interval import IntervalFunction

BIG = np.finfo(float).max


def function_of(build, n: int = 2, name: str = "f") -> ca.Function:
    x = ca.SX.sym("x", n)
    return ca.Function(name, [x], [build(x)])


# --- Functions it accepts, and the messages for the ones it rejects ----------------------------------------------

def test_an_mx_function_is_rejected_with_a_message_saying_to_expand_it():
    x = ca.MX.sym("x", 2)
    with pytest.raises(VerificationError, match=re.escape(
            "g: interval evaluation needs an SX Function (expand MX first)")):
        IntervalFunction(ca.Function("g", [x], [x[0] * x[1]]))


@pytest.mark.parametrize("n_in, n_out", [(2, 1), (1, 2), (2, 2)])
def test_a_function_needs_exactly_one_input_and_one_output(n_in, n_out):
    inputs = [ca.SX.sym(f"x{i}", 2) for i in range(n_in)]
    outputs = [inputs[0][0] + i for i in range(n_out)]
    with pytest.raises(VerificationError, match=re.escape(
            f"h: interval evaluation takes one input and one output, got {n_in} and {n_out}")):
        IntervalFunction(ca.Function("h", inputs, outputs))


def test_a_sparse_input_is_rejected():
    x = ca.SX.sym("x", ca.Sparsity.diag(2))  # 2 nonzeros of a 2 x 2 matrix
    with pytest.raises(VerificationError, match=re.escape("s: the input must be dense")):
        IntervalFunction(ca.Function("s", [x], [x[0, 0] + x[1, 1]]))


def test_every_unsupported_operation_is_named_once_sorted_and_comma_separated():
    f = function_of(lambda x: ca.erf(x[0]) + ca.atan2(x[0], x[1]) + ca.erf(x[1]), name="u")
    with pytest.raises(VerificationError, match=re.escape(
            "u: interval evaluation does not support the operation(s) atan2, erf") + "$"):
        IntervalFunction(f)


def test_the_output_sparsity_places_the_bound_columns_in_the_output():
    """Output (x0, structural 0, x1): two bound columns, at rows 0 and 2 of a 3-vector."""
    x = ca.SX.sym("x", 2)
    out = ca.SX(3, 1)
    out[0], out[2] = x[0], x[1]
    f = IntervalFunction(ca.Function("f", [x], [out]))
    assert (f.sparsity_out.size1(), f.sparsity_out.size2()) == (3, 1)
    assert list(f.sparsity_out.row()) == [0, 2]
    bounds = f([1.0, 2.0], [3.0, 4.0])
    dense_lo = np.zeros(3)
    dense_lo[list(f.sparsity_out.row())] = bounds.lo[0]
    assert dense_lo.tolist() == [1.0, 0.0, 2.0]


# --- the boxes a call takes -------------------------------------------------------------------------------------

@pytest.mark.parametrize("lo, hi", [
    ([[0.0, 0.0]], [[1.0, 1.0], [2.0, 2.0]]),  # one lower bound, two upper bounds
    ([[0.0, 0.0, 0.0]], [[1.0, 1.0, 1.0]]),  # three coordinates for a function of two
    ([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]),  # the same as single boxes
])
def test_boxes_of_the_wrong_shape_are_rejected_with_both_shapes(lo, hi):
    f = IntervalFunction(function_of(lambda x: x[0] + x[1], name="b"))
    shapes = f"{np.atleast_2d(lo).shape} and {np.atleast_2d(hi).shape}"
    with pytest.raises(VerificationError, match=re.escape(
            f"b: boxes must be (k, 2) lower and upper bounds, got {shapes}") + "$"):
        f(lo, hi)


def test_integer_bounds_are_taken_as_floats_so_products_do_not_wrap_around():
    """x0 x1 with both in [-(2^32 + 1), -1] (box 0) or in [1, 2^32 + 1] (box 1): the product reaches
    (2^32 + 1)^2 > 2^63, which int64 arithmetic would wrap to 2^33 + 1; the bounds are given as Python ints."""
    m = 2 ** 32 + 1
    f = IntervalFunction(function_of(lambda x: x[0] * x[1]))
    bounds = f([[-m, -m], [1, 1]], [[-1, -1], [m, m]])
    for box in range(2):
        assert bounds.lo[box, 0] <= 1 and bounds.hi[box, 0] >= m * m  # float vs int compares exactly
        assert bounds.hi[box, 0] <= 1.0000001 * m * m


def test_an_overflowing_product_gives_bounds_without_a_numpy_warning():
    """[1e200, 1e201]^2 lies above the largest double: lo is the largest double, hi is inf, and no warning."""
    f = IntervalFunction(function_of(lambda x: x[0] * x[1]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        bounds = f([1e200, 1e200], [1e201, 1e201])
    assert (bounds.lo[0, 0], bounds.hi[0, 0]) == (BIG, np.inf)


# --- defined: accumulated over every operation ------------------------------------------------------------------

@pytest.mark.parametrize("order", [0, 1])
def test_a_box_outside_one_domain_stays_undefined_whatever_comes_after(order):
    """(sqrt(x0), log(x1)) in either order: each box leaves exactly one of the two domains."""
    parts = [lambda x: ca.sqrt(x[0]), lambda x: ca.log(x[1])]
    f = IntervalFunction(function_of(lambda x: ca.vertcat(parts[order](x), parts[1 - order](x))))
    # x0 in [-1, 1] (sqrt undefined), x1 in [1, 2]; x0 in [1, 2], x1 in [-1, 1] (log undefined); both inside
    bounds = f([[-1.0, 1.0], [1.0, -1.0], [1.0, 1.0]], [[1.0, 2.0], [2.0, 1.0], [2.0, 2.0]])
    assert bounds.defined.tolist() == [False, False, True]


@pytest.mark.parametrize("constant", [np.inf, -np.inf, np.nan])
def test_a_non_finite_constant_makes_every_box_undefined(constant):
    f = IntervalFunction(function_of(lambda x: x[0] + constant * x[1]))
    assert f([[0.0, 0.0], [1.0, 1.0]], [[1.0, 1.0], [2.0, 2.0]]).defined.tolist() == [False, False]


def test_an_operation_outside_its_domain_has_the_whole_real_line_as_bounds():
    """sqrt over [-1, 4] and log over [-1, 4]: both bounds are infinite, as the module docstring promises;
    over [1, 4] they are finite, about [1, 2] and [0, log 4]."""
    f = IntervalFunction(function_of(lambda x: ca.vertcat(ca.sqrt(x[0]), ca.log(x[1]))))
    bounds = f([[-1.0, -1.0], [1.0, 1.0]], [[4.0, 4.0], [4.0, 4.0]])
    assert bounds.lo[0].tolist() == [-np.inf, -np.inf] and bounds.hi[0].tolist() == [np.inf, np.inf]
    assert np.allclose(bounds.lo[1], [1.0, 0.0]) and np.allclose(bounds.hi[1], [2.0, np.log(4.0)])


# --- the kink of if_else_zero -----------------------------------------------------------------------------------

def test_if_else_zero_is_non_smooth_exactly_where_its_condition_may_be_both_zero_and_nonzero():
    """if_else(x0, x1, 0) (one if_else_zero) is x1 where x0 != 0, else 0: it jumps at x0 = 0, so a box of x0 is
    smooth iff it holds no 0 (surely true) or is [0, 0] (surely false); [0, 1] and [-1, 0] touch the jump."""
    f = IntervalFunction(function_of(lambda x: ca.if_else(x[0], x[1], 0)))
    x0 = [(1.0, 2.0), (-2.0, -1.0), (0.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (-1.0, 1.0)]
    bounds = f([[a, 3.0] for a, _ in x0], [[b, 4.0] for _, b in x0])
    assert bounds.smooth.tolist() == [True, True, True, False, False, False]
    assert bounds.lo[:, 0].tolist() == [3.0, 3.0, 0.0, 0.0, 0.0, 0.0]
    assert bounds.hi[:, 0].tolist() == [4.0, 4.0, 0.0, 4.0, 4.0, 4.0]
