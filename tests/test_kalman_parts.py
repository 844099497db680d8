"""The Gaussian filters' parts (uvsym.observers.kalman): covariance and argument checks, the guarded
Cholesky factor, and the efficiency-augmented system, with values worked out by hand or by numpy."""

import re

import casadi as ca
import numpy as np
import pytest

from uvsym.errors import ArgumentError, CovarianceError, ObserverError
from uvsym.observers.kalman import check_covariance, checked_inputs, cholesky, efficiency_augmented
from uvsym.systems.signals import signals
from uvsym.systems.system import system


def evaluated(expr) -> np.ndarray:
    return np.array(ca.evalf(ca.densify(expr)))


def toy_plant():
    """x = (a m, b m/s), u = (f N, g N), d = (w N): a' = b, b' = -a + f + 2 g + w; y = a + g."""
    return system("toy", "a' = b, b' = -a + f + 2 g + w", x=signals(("a", "m"), ("b", "m/s"), group="state"),
                  u=signals(("f", "N"), ("g", "N"), group="input"), d=signals(("w", "N"), group="disturbance"),
                  rhs=lambda x, u, d, p: ca.vertcat(x[1], -x[0] + u[0] + 2 * u[1] + d[0]),
                  y=signals(("y_a", "m"), group="output"), output=lambda x, u, p: x[0] + u[1],
                  u_op=[1.0, 2.0], constants={"k": 3.0}, source="written for the tests")


# --- check_covariance ------------------------------------------------------------------------------------------------


def test_a_covariance_that_is_not_numbers_is_refused_naming_it():
    with pytest.raises(CovarianceError) as info:
        check_covariance("abc", 2, "kf: Q")
    assert str(info.value) == "kf: Q must be numbers, got 'abc'"


def test_an_integer_covariance_comes_back_as_floats():
    M = check_covariance([[2, 1], [1, 2]], 2, "Q")
    assert M.dtype == np.float64 and M.tolist() == [[2.0, 1.0], [1.0, 2.0]]


def test_a_scalar_variance_fills_the_diagonal_of_any_size():
    np.testing.assert_array_equal(check_covariance(2.0, 3, "Q"), 2.0 * np.eye(3))


def test_a_vector_of_the_wrong_length_is_refused_with_its_shape():
    with pytest.raises(CovarianceError) as info:
        check_covariance([1.0, 2.0, 3.0], 2, "P0")
    assert str(info.value) == "P0 must be (2, 2) (or 2 variances), got shape (3, 3)"


def test_an_asymmetry_at_the_tolerance_is_accepted_and_above_it_refused():
    # |M - M^T| max = 1e-12 = 1e-12 * max(1, max|M|) with max|M| = 1: accepted, not symmetrised
    np.testing.assert_array_equal(check_covariance([[1.0, 1e-12], [0.0, 1.0]], 2, "Q"), [[1.0, 1e-12], [0.0, 1.0]])
    with pytest.raises(CovarianceError) as info:
        check_covariance([[1.0, 1.5e-12], [0.0, 1.0]], 2, "Q")
    assert str(info.value) == "Q is not symmetric (max |M - M^T| = 1.5e-12)"


def test_the_symmetry_tolerance_grows_with_the_largest_entry():
    # tolerance 1e-12 * 1e6 = 1e-6 > 1e-8
    M = check_covariance([[1e6, 1e-8], [0.0, 1e6]], 2, "Q")
    assert M[0, 1] == 1e-8


# --- checked_inputs --------------------------------------------------------------------------------------------------


def test_a_filter_name_that_cannot_name_c_functions_is_refused_as_an_observer_name():
    with pytest.raises(ObserverError) as info:
        checked_inputs(toy_plant(), "1kf", 0.1, 1.0, 1.0, 1.0, None)
    assert str(info.value).startswith("observer name '1kf' must start with a letter")


@pytest.mark.parametrize("which", ["Q", "R", "P0"])
def test_each_covariance_is_named_with_the_filter_when_refused(which):
    given = {"Q": 1.0, "R": 1.0, "P0": 1.0, which: -1.0}
    with pytest.raises(CovarianceError) as info:
        checked_inputs(toy_plant(), "kf", 0.1, given["Q"], given["R"], given["P0"], None)
    assert str(info.value).startswith(f"kf: {which} is indefinite (smallest eigenvalue -1")


def test_an_initial_state_of_the_wrong_size_is_refused_naming_it():
    with pytest.raises(ObserverError) as info:
        checked_inputs(toy_plant(), "kf", 0.1, 1.0, 1.0, 1.0, [1.0, 2.0, 3.0])
    assert str(info.value) == "kf: x0 must have 2 entries (a, b), got 3"


# --- cholesky --------------------------------------------------------------------------------------------------------


def test_the_factor_is_that_of_the_jittered_matrix_and_the_margin_the_smallest_pivot():
    A = np.array([[4.0, 2.0, 0.0], [2.0, 2.0, 0.0], [0.0, 0.0, 9.0]])
    factor, margin = cholesky(ca.SX(ca.DM(A)))
    # numpy's factor of A + 1e-12 diag(A) (the documented jitter); without it L_00 = 2 would be 5e-13 off
    np.testing.assert_allclose(evaluated(factor), np.linalg.cholesky(A + 1e-12 * np.diag(np.diag(A))),
                               rtol=1e-14, atol=0)
    # relative pivots: 4/4, (2 - 2^2/4)/2 = 1/2, 9/9: the middle one, not the last
    assert abs(float(ca.evalf(margin)) - 0.5) < 1e-11


def test_a_zero_matrix_has_margin_zero_and_the_diagonal_fallback():
    factor, margin = cholesky(ca.SX(ca.DM.zeros(2, 2)))
    assert float(ca.evalf(margin)) == 0.0  # not positive definite: margin not > 0
    np.testing.assert_array_equal(evaluated(factor), np.eye(2))  # diag(sqrt(|0| + 1))


# --- efficiency_augmented --------------------------------------------------------------------------------------------


def test_two_efficiencies_scale_their_own_inputs():
    plant = toy_plant()
    augmented = efficiency_augmented(plant, ("f", "g"))
    x = [1.0, 3.0, 0.5, 0.25]  # a, b, alpha_f, alpha_g
    got = np.asarray(augmented.f(x, [4.0, 8.0], [1.0], [])).ravel()
    # b' = -1 + 0.5 * 4 + 2 * (0.25 * 8) + 1 = 6; alphas constant
    np.testing.assert_allclose(got, [3.0, 6.0, 0.0, 0.0], rtol=0, atol=1e-15)
    assert float(augmented.h(x, [4.0, 8.0], [])) == 1.0 + 0.25 * 8.0
    assert augmented.x.names[2:] == ("alpha_f", "alpha_g") and augmented.x.units[2:] == ("-", "-")


def test_the_augmented_system_keeps_the_plants_data_and_describes_itself():
    plant = toy_plant()
    augmented = efficiency_augmented(plant, ("f", "g"))
    assert augmented.name == "toy_efficiency"
    assert augmented.description == "a' = b, b' = -a + f + 2 g + w; efficiencies of f, g as random-walk states"
    assert augmented.u_op.tolist() == [1.0, 2.0]
    assert augmented.constants == {"k": 3.0} and augmented.source == "written for the tests"
    assert str(augmented.f.sx_in(2)) == "d"  # the disturbance symbol is named as its argument


def test_the_augmented_functions_name_themselves_in_their_errors():
    augmented = efficiency_augmented(toy_plant(), ("f",))
    with pytest.raises(ArgumentError, match="^" + re.escape("toy_efficiency.f: takes 4 arguments")):
        augmented.f([0.0, 0.0, 1.0], [0.0, 0.0], [0.0])
    with pytest.raises(ArgumentError, match="^" + re.escape("toy_efficiency.h: takes 3 arguments")):
        augmented.h([0.0, 0.0, 1.0], [0.0, 0.0])
