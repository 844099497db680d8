"""Actuator configurations (seeds/000 sec. 2.3) and the docking AUV's B against eq. 27."""

import numpy as np
import pytest

import uvsym
from uvsym.errors import ConfigurationError
from uvsym.models import fixed_thrusters, identifiability, vectored_thrusters

DEG = np.pi / 180


def test_fixed_thruster_columns_are_force_and_moment():
    alpha = np.array([30.0, -30.0]) * DEG
    r_h = np.array([[-0.4, 0.2, 0.05], [-0.4, -0.2, 0.05]])
    r_v = np.array([[0.3, 0.0, 0.0]])
    B = fixed_thrusters(alpha, r_h, r_v).B
    for i, (a, r) in enumerate(zip(alpha, r_h)):
        e = np.array([np.cos(a), np.sin(a), 0.0])
        np.testing.assert_allclose(B[:, i], np.r_[e, np.cross(r, e)], atol=1e-15)
    np.testing.assert_allclose(B[:, 2], np.r_[0, 0, 1, np.cross(r_v[0], [0, 0, 1])], atol=1e-15)


@pytest.mark.parametrize(("k", "vertical", "expected"), [
    (3, 3, True), (2, 2, True), (3, 1, True), (4, 2, False), (3, 4, False),
])
def test_fixed_thruster_counting_rule(k, vertical, expected):
    """Identifiable only when k <= 3 horizontal and m - k <= 3 vertical (paper's planar layout:
    horizontal thrusters in the plane z = 0, so they act on X, Y, N only)."""
    rng = np.random.default_rng(k * 10 + vertical)
    r_h = rng.uniform(-1, 1, (k, 3)) * [1, 1, 0]
    config = fixed_thrusters(rng.uniform(-np.pi, np.pi, k), r_h, rng.uniform(-1, 1, (vertical, 3)))
    report = identifiability(config)
    assert report.all_identifiable is expected
    if not expected:
        bad_group = "horizontal" if k > 3 else "vertical"
        reasons = [r for r in report.reasons if r]
        assert reasons and all(f"{bad_group} inputs for 3 equations" in r for r in reasons)
        good = range(k, k + vertical) if k > 3 else range(k)
        assert all(report.identifiable[i] for i in good)


def test_out_of_plane_horizontal_thrusters_can_be_identifiable():
    """Beyond the paper's count: 4 horizontal thrusters at different heights also act on K and M."""
    rng = np.random.default_rng(42)
    config = fixed_thrusters(rng.uniform(-np.pi, np.pi, 4), rng.uniform(-1, 1, (4, 3)), rng.uniform(-1, 1, (2, 3)))
    report = identifiability(config)
    assert report.rank == 6 and report.all_identifiable


def test_vectored_thrusters_total_inputs_at_most_six():
    rng = np.random.default_rng(1)
    positions = rng.uniform(-1, 1, (3, 3))
    ex, ez = rng.uniform(0, np.pi, 3), rng.uniform(0.3, 2.8, 3)
    six = vectored_thrusters(ex, ez, positions, ["both", "ex", "none"])
    assert six.B.shape == (6, 6) and identifiability(six).all_identifiable
    seven = vectored_thrusters(ex, ez, positions, ["both", "both", "none"])
    report = identifiability(seven)
    assert report.rank == 6 and not report.all_identifiable
    assert any("7 all inputs for 6 equations" in r for r in report.reasons)


def test_vectored_direction_matches_paper_definition():
    config = vectored_thrusters([0.3], [1.1], [[0.5, 0.1, -0.2]], ["none"])
    e = np.array([np.sin(1.1) * np.cos(0.3), np.sin(1.1) * np.sin(0.3), np.cos(1.1)])
    np.testing.assert_allclose(config.B[:, 0], np.r_[e, np.cross([0.5, 0.1, -0.2], e)], atol=1e-15)


def test_redundant_pair_names_its_partner():
    config = fixed_thrusters([0.0, 0.0], [[-0.5, 0.0, 0.0], [0.5, 0.0, 0.0]], [])
    report = identifiability(config)
    assert report.identifiable == (False, False)
    assert "T_h1 can be traded against T_h2" in report.reasons[0]


@pytest.mark.parametrize(("call", "message"), [
    (lambda: fixed_thrusters([0.0, 1.0], [[0, 0, 0]], []), "need 2 finite positions"),
    (lambda: fixed_thrusters([np.nan], [[0, 0, 0]], []), "must be finite"),
    (lambda: vectored_thrusters([0.0], [1.0], [[0, 0, 0]], ["yaw"]), "free_angles\\[0\\] = 'yaw'"),
    (lambda: vectored_thrusters([0.0, 1.0], [1.0], [[0, 0, 0]], ["ex"]), "need 2 entries"),
])
def test_bad_configuration_is_a_configuration_error(call, message):
    with pytest.raises(ConfigurationError, match=message):
        call()


# The core paper's eq. 27, as printed: which entries of B (rows X..N, columns X, delta_e,
# delta_ru, delta_rd) are non-zero.
EQ27 = np.array([[1, 0, 0, 0], [0, 0, 1, 1], [0, 1, 0, 0], [0, 0, 1, 1], [0, 1, 0, 0], [0, 0, 1, 1]], bool)


@pytest.mark.parametrize("nu", [[1.5, 0, 0, 0, 0, 0], [1.2, 0.1, -0.05, 0.02, 0.01, 0.03]])
def test_docking_auv_input_matrix_has_eq27_structure(nu):
    model = uvsym.vehicle("docking_auv")
    B = np.array(model.B(eta=np.zeros(6), nu=nu, u=[20.0, 0.01, 0.02, -0.01], V_c=0, beta_c=0)["B"])
    assert B.shape == (6, 4)
    np.testing.assert_array_equal(np.abs(B) > 1e-12 * np.max(np.abs(B)), EQ27)
    assert B[0, 0] == 1.0
    assert B[1, 2] == pytest.approx(B[1, 3]) and B[5, 2] == pytest.approx(B[5, 3])
    assert B[3, 2] == pytest.approx(-B[3, 3])  # upper and lower rudders roll opposite ways
    identity = identifiability(uvsym.models.ActuatorConfiguration("docking", B, model.input_labels, ()))
    assert identity.all_identifiable


def test_docking_auv_input_matrix_is_the_derivative_of_tau():
    model = uvsym.vehicle("docking_auv")
    args = dict(eta=np.zeros(6), nu=[1.4, 0.05, 0.0, 0.0, 0.0, 0.02], V_c=0.2, beta_c=1.0)
    u0 = np.array([15.0, 0.02, -0.03, 0.01])
    B = np.array(model.B(u=u0, **args)["B"])
    for j in range(4):
        step = np.eye(4)[j] * 1e-4
        diff = (np.array(model.tau(u=u0 + step, **args)["tau"]) - np.array(model.tau(u=u0 - step, **args)["tau"]))
        np.testing.assert_allclose(diff.ravel() / 2e-4, B[:, j], rtol=1e-7, atol=1e-10)
