"""Physical properties every vehicle model must have, checked over random states."""

import casadi as ca
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import uvsym
from uvsym.models.rigid_body import coriolis_from_mass

NAMES = uvsym.vehicle_names()
speeds = st.floats(-3, 3, allow_nan=False)
rates = st.floats(-1, 1, allow_nan=False)


def velocity(dof):
    if dof == 6:
        return st.tuples(speeds, speeds, speeds, rates, rates, rates).map(np.array)
    return st.tuples(speeds, speeds, rates).map(np.array)


@pytest.mark.parametrize("name", NAMES)
def test_mass_matrix_is_symmetric_positive_definite(name):
    M = uvsym.vehicle(name).M
    np.testing.assert_allclose(M, M.T, atol=1e-12 * np.max(np.abs(M)))
    assert np.min(np.linalg.eigvalsh(M)) > 0


@pytest.mark.parametrize("name", NAMES)
@settings(max_examples=60, deadline=None)
@given(data=st.data())
def test_coriolis_does_no_work(name, data):
    """nu^T C(nu) nu = 0: the Coriolis term, at zero current, is orthogonal to nu."""
    model = uvsym.vehicle(name)
    nu = data.draw(velocity(model.dof))
    term = np.array(model.terms(eta=np.zeros(model.dof), nu=nu, V_c=0, beta_c=0)["coriolis"]).ravel()
    assert abs(nu @ term) <= 1e-10 * max(1.0, np.linalg.norm(nu) * np.linalg.norm(term))


@settings(max_examples=100, deadline=None)
@given(st.lists(st.floats(0.1, 100), min_size=6, max_size=6), velocity(6))
def test_coriolis_from_any_spd_mass_is_skew(diagonal, nu):
    rng = np.random.default_rng(int(sum(diagonal) * 1000) % 2**32)
    A = rng.normal(size=(6, 6))
    M = A @ A.T + np.diag(diagonal)
    C = coriolis_from_mass(M, nu)
    np.testing.assert_allclose(C + C.T, 0, atol=1e-9 * np.max(np.abs(M)) * (1 + np.max(np.abs(nu))))
    nu_s = ca.SX.sym("nu", 6)
    C_sym = ca.Function("C", [nu_s], [coriolis_from_mass(M, nu_s)])
    np.testing.assert_allclose(np.array(C_sym(nu)), C, atol=1e-12 * np.max(np.abs(M)))


@pytest.mark.parametrize("name", NAMES)
def test_kinetic_energy_is_conserved_without_damping_restoring_and_input(name):
    """M nu_dot = -C(nu) nu alone conserves 0.5 nu^T M nu along an accurate integration."""
    model = uvsym.vehicle(name)
    nu = ca.SX.sym("nu", model.dof)
    coriolis = model.terms(ca.SX.zeros(model.dof), nu, 0, 0)[model.term_names.index("coriolis")]
    ode = -ca.solve(ca.DM(model.M), coriolis)
    F = ca.integrator("F", "cvodes", {"x": nu, "ode": ode}, 0, np.linspace(1, 20, 20),
                      {"abstol": 1e-12, "reltol": 1e-12})
    nu0 = np.array([1.5, 0.3, -0.2, 0.2, -0.1, 0.3][: model.dof]) if model.dof == 6 else np.array([1.5, 0.3, 0.3])
    trajectory = np.array(F(x0=nu0)["xf"])
    energy = 0.5 * np.einsum("it,ij,jt->t", trajectory, model.M, trajectory)
    e0 = 0.5 * nu0 @ model.M @ nu0
    assert np.max(np.abs(energy - e0)) / e0 < 1e-8
    assert np.max(np.abs(trajectory - nu0[:, None])) > 1e-3  # it did move: the check is not vacuous


@pytest.mark.parametrize("name", NAMES)
def test_jacobians_match_finite_differences(name):
    model = uvsym.vehicle(name)
    rng = np.random.default_rng(7)
    n, m = model.dof, model.n_inputs
    eta, nu, u = ca.SX.sym("eta", n), ca.SX.sym("nu", n), ca.SX.sym("u", m)
    z = ca.vertcat(eta, nu, u)
    out = model.nu_dot(eta, nu, u, 0.3, 0.5)
    jac = ca.Function("jacobian_nu_dot", [z], [ca.jacobian(out, z)])
    value = ca.Function("f", [z], [out])
    scale = np.r_[np.full(n, 0.3), np.full(n, 0.5), 0.5 * model.u_max]
    for _ in range(5):
        z0 = rng.uniform(-1, 1, 2 * n + m) * scale
        z0[n] += 1.0  # cruise forward: away from the kinks of |.| at zero
        J = np.array(jac(z0))
        h = 1e-6 * np.maximum(1.0, np.abs(z0))
        J_fd = np.column_stack([(np.array(value(z0 + h[k] * np.eye(len(z0))[k]))
                                 - np.array(value(z0 - h[k] * np.eye(len(z0))[k]))).ravel() / (2 * h[k])
                                for k in range(len(z0))])
        np.testing.assert_allclose(J, J_fd, rtol=1e-5, atol=1e-6 * max(1.0, np.max(np.abs(J))))


@pytest.mark.parametrize("name", NAMES)
def test_jacobian_is_finite_at_rest(name):
    """Observers linearise at rest; the speed regularisation keeps every derivative finite there."""
    model = uvsym.vehicle(name)
    n, m = model.dof, model.n_inputs
    eta, nu, u = ca.SX.sym("eta", n), ca.SX.sym("nu", n), ca.SX.sym("u", m)
    jacobian = ca.jacobian(model.nu_dot(eta, nu, u, 0, 0), ca.vertcat(eta, nu, u))
    jac = ca.Function("jacobian_nu_dot", [eta, nu, u], [jacobian])
    assert np.all(np.isfinite(np.array(jac(np.zeros(n), np.zeros(n), np.zeros(m)))))


@pytest.mark.parametrize("name", NAMES)
def test_equation_of_motion_is_consistent(name):
    """M nu_dot + h(eta, nu) = tau(eta, nu, u) at zero current, from the separately built Functions."""
    model = uvsym.vehicle(name)
    rng = np.random.default_rng(3)
    for _ in range(5):
        eta = rng.uniform(-0.5, 0.5, model.dof)
        nu = rng.uniform(-0.5, 0.5, model.dof) + np.eye(model.dof)[0]
        u = rng.uniform(-0.8, 0.8, model.n_inputs) * model.u_max
        nu_dot = np.array(model.nu_dot(eta=eta, nu=nu, u=u, V_c=0, beta_c=0)["nu_dot"]).ravel()
        h = np.array(model.h(eta=eta, nu=nu)["h"]).ravel()
        tau = np.array(model.tau(eta=eta, nu=nu, u=u, V_c=0, beta_c=0)["tau"]).ravel()
        np.testing.assert_allclose(model.M @ nu_dot + h, tau, atol=1e-9 * max(1.0, np.max(np.abs(tau))))


@pytest.mark.parametrize("name", NAMES)
def test_inputs_saturate(name):
    model = uvsym.vehicle(name)
    eta, nu = np.zeros(model.dof), np.eye(model.dof)[0]
    at_limit = model.tau(eta=eta, nu=nu, u=model.u_max, V_c=0, beta_c=0)["tau"]
    beyond = model.tau(eta=eta, nu=nu, u=3 * model.u_max, V_c=0, beta_c=0)["tau"]
    np.testing.assert_array_equal(np.array(at_limit), np.array(beyond))
    inside = model.tau(eta=eta, nu=nu, u=0.5 * model.u_max, V_c=0, beta_c=0)["tau"]
    assert np.max(np.abs(np.array(inside) - np.array(at_limit))) > 0
