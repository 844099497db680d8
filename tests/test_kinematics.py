import math

import casadi as ca
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uvsym.errors import KinematicsError
from uvsym.kinematics import Hmtrx, J, Rzyx, Smtrx, Tzyx, ssa

finite = st.floats(-10, 10, allow_nan=False)
angle = st.floats(-math.pi, math.pi, allow_nan=False)
pitch = st.floats(-1.5, 1.5, allow_nan=False)


@given(st.lists(finite, min_size=3, max_size=3), st.lists(finite, min_size=3, max_size=3))
def test_smtrx_is_the_cross_product(a, b):
    np.testing.assert_allclose(Smtrx(a) @ np.array(b), np.cross(a, b), atol=1e-12)


@given(angle, pitch, angle)
def test_rzyx_is_a_rotation(phi, theta, psi):
    R = Rzyx(phi, theta, psi)
    np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-12)
    assert np.linalg.det(R) == pytest.approx(1.0, abs=1e-12)


@given(angle, pitch, angle)
def test_rzyx_composes_elementary_rotations(phi, theta, psi):
    c, s = math.cos, math.sin
    Rz = np.array([[c(psi), -s(psi), 0], [s(psi), c(psi), 0], [0, 0, 1]])
    Ry = np.array([[c(theta), 0, s(theta)], [0, 1, 0], [-s(theta), 0, c(theta)]])
    Rx = np.array([[1, 0, 0], [0, c(phi), -s(phi)], [0, s(phi), c(phi)]])
    np.testing.assert_allclose(Rzyx(phi, theta, psi), Rz @ Ry @ Rx, atol=1e-12)


@given(angle, pitch, angle)
@settings(max_examples=50)
def test_tzyx_maps_body_rates_to_euler_rates(phi, theta, psi):
    # Angular velocity from Euler rates: w = Rx^T (e1 phi_dot) + Rx^T Ry^T (e2 theta_dot) + ... ; T inverts it.
    c, s = math.cos, math.sin
    T_inv = np.array([[1, 0, -s(theta)], [0, c(phi), c(theta) * s(phi)], [0, -s(phi), c(theta) * c(phi)]])
    np.testing.assert_allclose(Tzyx(phi, theta) @ T_inv, np.eye(3), atol=1e-9)


@pytest.mark.parametrize("theta", [math.pi / 2, -math.pi / 2, 3 * math.pi / 2])
def test_tzyx_singular_pitch_raises(theta):
    with pytest.raises(KinematicsError, match="singular"):
        Tzyx(0.1, theta)
    with pytest.raises(KinematicsError):
        J([0, 0, 0, 0.1, theta, 0])


def test_generic_over_types():
    eta = np.array([1.0, 2.0, 3.0, 0.1, -0.2, 0.3])
    numeric = J(eta)
    sym = ca.SX.sym("eta", 6)
    via_sx = np.array(ca.Function("J", [sym], [J(sym)])(eta))
    via_mx = np.array(ca.Function("J", [m := ca.MX.sym("eta", 6)], [J(m)])(eta))
    via_dm = np.array(J(ca.DM(eta)))
    for other in (via_sx, via_mx, via_dm):
        np.testing.assert_allclose(other, numeric, atol=1e-15)
    assert isinstance(J(sym), ca.SX) and isinstance(numeric, np.ndarray)


@given(st.lists(finite, min_size=3, max_size=3))
def test_hmtrx_inverse_is_h_of_minus_r(r):
    np.testing.assert_allclose(Hmtrx(r) @ Hmtrx(-np.array(r)), np.eye(6), atol=1e-12)


@given(st.floats(-1e3, 1e3, allow_nan=False))
def test_ssa_range_and_equivalence(a):
    wrapped = float(ssa(a))
    assert -math.pi <= wrapped < math.pi
    turns = (a - wrapped) / (2 * math.pi)
    assert turns == pytest.approx(round(turns), abs=1e-9)


def test_ssa_symbolic_matches_numeric():
    a = ca.SX.sym("a")
    f = ca.Function("ssa", [a], [ssa(a)])
    values = np.array([-7.0, -math.pi, 0.0, 3.0, math.pi, 9.5])
    np.testing.assert_allclose(np.array(f(values.reshape(1, -1))).ravel(), ssa(values), atol=1e-12)
    assert ssa(math.pi) == pytest.approx(-math.pi)


def test_wrong_size_vector_is_a_kinematics_error():
    with pytest.raises(KinematicsError, match="3 entries"):
        Smtrx([1.0, 2.0])
