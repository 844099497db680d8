"""uvsym's models against Fossen's Python Vehicle Simulator, case by case, to 1e-9 relative."""

import numpy as np
import pytest

import uvsym

TOL = 1e-9


def cases(reference, name):
    return [(name, case) for case in reference[name]["cases"]]


def assert_close(actual, expected, what):
    """|actual - expected| <= TOL * max|expected| for every component."""
    expected = np.asarray(expected, dtype=float)
    actual = np.asarray(actual, dtype=float).ravel()
    scale = max(np.max(np.abs(expected)), 1e-300)
    np.testing.assert_allclose(actual, expected, rtol=0, atol=TOL * scale, err_msg=what)


@pytest.mark.parametrize("name", ["remus100", "torpedo", "otter"])
def test_accelerations_match_reference(reference, name):
    model = uvsym.vehicle(name)
    assert len(reference[name]["cases"]) >= 4
    for case in reference[name]["cases"]:
        nu_dot = model.nu_dot(eta=case["eta"], nu=case["nu"], u=case["u_actual"],
                              V_c=case["V_c"], beta_c=case["beta_c_rad"])["nu_dot"]
        assert_close(nu_dot, case["nu_dot"], f"{name}/{case['name']} nu_dot")


@pytest.mark.parametrize("name", ["remus100", "torpedo", "otter"])
def test_kinematics_and_euler_step_match_reference(reference, name):
    model = uvsym.vehicle(name)
    for case in reference[name]["cases"]:
        x = np.r_[case["eta"], case["nu"]]
        x_dot = np.array(model.f(x=x, u=case["u_actual"], p=[case["V_c"], case["beta_c_rad"]])["x_dot"]).ravel()
        assert_close(x_dot[:6], case["eta_dot"], f"{name}/{case['name']} eta_dot")
        nu_next = np.array(case["nu"]) + case["sampleTime"] * x_dot[6:]
        assert_close(nu_next, case["nu_next"], f"{name}/{case['name']} nu_next")


@pytest.mark.parametrize("name", ["remus100", "otter"])
def test_actuator_rates_match_reference(reference, name):
    model = uvsym.vehicle(name)
    for case in reference[name]["cases"]:
        rate = model.actuator_rate(u=case["u_actual"], u_cmd=case["u_control"])["u_dot"]
        assert_close(rate, case["u_actual_dot"], f"{name}/{case['name']} u_dot")


def test_reference_mass_matrices(reference):
    for name in ("remus100", "torpedo", "otter"):
        np.testing.assert_allclose(uvsym.vehicle(name).M, reference[name]["constants_default"]["M"],
                                   rtol=1e-12, atol=1e-12)


def test_hull_terms_match_reference_pieces(reference):
    """The named hull terms equal the reference's intermediate forces (with their sign)."""
    model = uvsym.vehicle("remus100")
    case = reference["remus100"]["cases"][0]
    inter = case["intermediate"]
    terms = model.terms(eta=case["eta"], nu=case["nu"], V_c=case["V_c"], beta_c=case["beta_c_rad"])
    assert_close(-np.array(terms["lift_drag"]), inter["tau_liftdrag"], "lift_drag")
    assert_close(-np.array(terms["crossflow"]), inter["tau_crossflow"], "crossflow")
    assert_close(terms["restoring"], inter["g"], "restoring")
    nu_r = np.array(inter["nu_r"])
    assert_close(terms["coriolis"], np.array(inter["C"]) @ nu_r, "coriolis")
    assert_close(terms["damping"], np.array(inter["D"]) @ nu_r, "damping")
    tau = model.tau(eta=case["eta"], nu=case["nu"], u=case["u_actual"], V_c=case["V_c"], beta_c=case["beta_c_rad"])
    assert_close(tau["tau"], inter["tau"], "tau")
