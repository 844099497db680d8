"""Plants as Systems: signals, operating points, linearisation and sampling checked independently
(hand-computed numbers, central finite differences, scipy's solve_ivp and cont2discrete)."""

import math

import casadi as ca
import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.signal import cont2discrete

import uvsym
from uvsym.errors import ModelError, UnknownNameError
from uvsym.systems import plant, plant_names, signals, system

PLANT_SIGNALS = {
    "induction_motor": (("i_sq", "i_sd", "lambda_rq", "lambda_rd", "omega_m"), ("A", "A", "Wb", "Wb", "rad/s"),
                        ("u_sq", "u_sd"), ("V", "V"), 5, ("i_sq", "i_sd", "omega_m")),
    "quadrotor": (("phi", "theta", "psi", "p", "q", "r", "z", "w"),
                  ("rad", "rad", "rad", "rad/s", "rad/s", "rad/s", "m", "m/s"),
                  ("Vf", "Vb", "Vr", "Vl"), ("V",) * 4, 1, ("phi", "theta", "psi", "p", "q", "r", "z", "w")),
    "rov_yaw": (("psi", "r"), ("rad", "rad/s"), ("u",), ("-",), 1, ("psi",)),
}
PLANTS = list(PLANT_SIGNALS)


def _f(sys, x, u, d=None):
    d = np.zeros(sys.d.size) if d is None else d
    return np.asarray(sys.f(x, u, d, sys.p0), dtype=float).ravel()


def _away_from_op(sys, seed=0):
    """A point near the operating point but generic (every term of f active), and d != 0."""
    rng = np.random.default_rng(seed)
    scale = np.maximum(np.abs(sys.x_op), 0.3)
    return (sys.x_op + 0.1 * scale * rng.standard_normal(sys.x.size),
            sys.u_op + 0.1 * np.maximum(np.abs(sys.u_op), 0.5) * rng.standard_normal(sys.u.size),
            0.05 * rng.standard_normal(sys.d.size))


@pytest.mark.parametrize("name", PLANTS)
def test_signals_sizes_names_units(name):
    sys = plant(name)
    x_names, x_units, u_names, u_units, n_d, y_names = PLANT_SIGNALS[name]
    assert sys.x.names == x_names and sys.x.units == x_units
    assert sys.u.names == u_names and sys.u.units == u_units
    assert sys.d.size == n_d and sys.y.names == y_names and not sys.discrete
    for group in (sys.x, sys.u, sys.d, sys.y):
        assert all(group.units) and all(group.descriptions), group.names
    assert sys.source and sys.constants is not None and all(p.unit for p in sys.constants.values())


@pytest.mark.parametrize("name", PLANTS)
def test_operating_point_is_an_equilibrium(name):
    sys = plant(name)
    f0 = _f(sys, sys.x_op, sys.u_op)
    # relative to the largest single term of f there: B u_op (motor), m g / m (quadrotor), 1 (rov)
    lin = sys.linearize()
    scale = max(1.0, np.max(np.abs(lin.B @ sys.u_op)), np.max(np.abs(lin.A @ sys.x_op)))
    assert np.max(np.abs(f0)) <= 1e-9 * scale
    assert np.allclose(lin.f0, f0)


@pytest.mark.parametrize("name", PLANTS)
def test_linearize_matches_central_differences(name):
    sys = plant(name)
    x0, u0, d0 = _away_from_op(sys)
    lin = sys.linearize(x0, u0, d0)
    for J, point, which in ((lin.A, x0, 0), (lin.B, u0, 1), (lin.E, d0, 2)):
        fd = np.zeros_like(J)
        for j in range(point.size):
            h = 1e-6 * max(1.0, abs(point[j]))
            args = [x0.copy(), u0.copy(), d0.copy()]
            args[which][j] += h
            plus = _f(sys, *args)
            args[which][j] -= 2 * h
            fd[:, j] = (plus - _f(sys, *args)) / (2 * h)
        assert np.allclose(J, fd, rtol=1e-6, atol=1e-6 * max(1.0, np.max(np.abs(J))))
    y = lambda x: np.asarray(sys.h(x, u0, sys.p0), dtype=float).ravel()  # noqa: E731
    C_fd = np.column_stack([(y(x0 + e * 1e-6) - y(x0 - e * 1e-6)) / 2e-6 for e in np.eye(sys.x.size)])
    assert np.allclose(lin.C, C_fd, atol=1e-8) and not lin.D.any()


@pytest.mark.parametrize(("name", "dt", "steps", "start"), [
    ("induction_motor", 1e-4, 4, {}), ("quadrotor", 0.01, 1, {}),
    ("rov_yaw", 0.01, 4, {"r": 0.4}),  # r kept away from 0, where |r| r has a kink that costs RK4 its order
])
def test_rk4_step_matches_solve_ivp(name, dt, steps, start):
    sys = plant(name)
    x0, u0, d0 = _away_from_op(sys, seed=1)
    x0[sys.x.indices(start)] = list(start.values())
    x1 = np.asarray(sys.discretize(dt, "rk4", steps).f(x0, u0, d0, sys.p0), dtype=float).ravel()
    exact = solve_ivp(lambda _t, x: _f(sys, x, u0, d0), (0, dt), x0, method="DOP853", rtol=1e-12, atol=1e-12)
    assert np.allclose(x1, exact.y[:, -1], rtol=1e-7, atol=1e-9)


def _linear_system():
    A = np.array([[0.0, 1.0, 0.0], [-2.0, -0.3, 0.5], [0.0, 0.0, -1.5]])
    B, E, G = np.array([[0.0], [1.0], [0.2]]), np.array([[0.1], [0.0], [1.0]]), np.array([[0.0], [0.0], [3.0]])
    sys = system("linear", "three states, affine in a parameter",
                 x=signals(("a", "m"), ("b", "m/s"), ("c", "-"), group="state"),
                 u=signals(("f", "N"), group="input"), d=signals(("w", "N"), group="disturbance"),
                 p=signals(("k", "-"), group="parameter"), p0=[0.7],
                 rhs=lambda x, u, d, p: ca.mtimes(ca.DM(A), x) + ca.mtimes(ca.DM(B), u) + ca.mtimes(ca.DM(E), d)
                 + ca.mtimes(ca.DM(G), p))
    return sys, A, np.hstack([B, E, G])


def test_zoh_equals_scipy_cont2discrete():
    sys, A, BEG = _linear_system()
    dt = 0.05
    Ad, BEGd, *_ = cont2discrete((A, BEG, np.eye(3), np.zeros((3, 3))), dt, method="zoh")
    discrete = sys.discretize(dt)
    lin = discrete.linearize(np.zeros(3), [0.0], [0.0])
    assert discrete.dt == dt and discrete.discrete
    assert np.allclose(lin.A, Ad, rtol=0, atol=1e-12)
    assert np.allclose(np.hstack([lin.B, lin.E]), BEGd[:, :2], rtol=0, atol=1e-12)
    assert np.allclose(lin.f0, BEGd[:, 2] * 0.7, rtol=0, atol=1e-12)  # the affine term Gd G p


# --- induction motor -------------------------------------------------------------------------------

def test_motor_coefficients_match_the_msl_data_by_hand():
    # MSL IM_SquirrelCageData, by hand: Lm = 3 sqrt(1 - 0.0667)/(2 pi 50), Ls = Lr = 3/(2 pi 50)
    Lm, Ls, Rs, Rr, J, n_p = 3 * math.sqrt(1 - 0.0667) / (100 * math.pi), 3 / (100 * math.pi), 0.03, 0.04, 0.29, 2
    delta = 1 - Lm**2 / Ls**2
    expected = {"delta": (delta, 0.0667, 4), "alpha": (Rr / Ls, 4.189, 3), "beta": (Lm / (delta * Ls**2), 1516.7, 1),
                "gamma": (Lm**2 * Rr / (delta * Ls**3) + Rs / (delta * Ls), 105.7, 1),
                "mu": (n_p * Lm / (J * Ls), 6.663, 3)}
    got = plant("induction_motor").extras["coefficients"]
    for name, (by_hand, published, digits) in expected.items():
        assert round(by_hand, digits) == published, name
        assert got[name] == pytest.approx(by_hand, rel=1e-8), name


def test_motor_operating_point_by_hand():
    sys = plant("induction_motor")
    Ls, Lm, I0 = 3 / (100 * math.pi), 3 * math.sqrt(1 - 0.0667) / (100 * math.pi), 30.0
    assert sys.x_op == pytest.approx([0, I0, 0, Lm * I0, 250.0], rel=1e-8)
    assert sys.u_op == pytest.approx([500 * Ls * I0, 0.03 * I0], rel=1e-8)  # u_sq = omega_s Ls I0


def test_motor_disturbance_is_a_rotor_resistance_change():
    nominal, d_Rr = plant("induction_motor"), 0.008
    x, u, _ = _away_from_op(nominal, seed=2)
    warmer = plant("induction_motor", Rr=0.04 + d_Rr)
    assert np.allclose(_f(nominal, x, u, d_Rr * x), _f(warmer, x, u), rtol=1e-10, atol=1e-8)


def test_motor_printed_typo_changes_only_flux_rows():
    consistent, printed = plant("induction_motor"), plant("induction_motor", printed_typo=True)
    x, u, d = _away_from_op(consistent, seed=3)
    beta, n_p = consistent.extras["coefficients"]["beta"], 2.0
    difference = _f(printed, x, u, d) - _f(consistent, x, u, d)
    expected = n_p * (beta - 1) * x[4] * np.array([0, 0, x[3], -x[2], 0])
    assert np.allclose(difference, expected, rtol=1e-9)
    assert abs(_f(printed, printed.x_op, printed.u_op)[2]) > 1e3  # the printed form has no such equilibrium


def test_motor_rejects_leakage_free_inductances():
    with pytest.raises(ModelError, match="delta"):
        plant("induction_motor", Lm=0.01)


# --- quadrotor -------------------------------------------------------------------------------------

def test_quadrotor_inertias_reproduce_config_hover():
    J = plant("quadrotor").extras["inertias"]
    section = 1.91e-6 + 2.85 / 4 * (7.75 * 0.0254) ** 2
    assert J["Jp"] == J["Jr"] == pytest.approx(2 * section) and J["Jy"] == pytest.approx(4 * section)
    assert round(J["Jp"], 5) == 0.05522 and round(J["Jy"], 5) == 0.11044


def test_quadrotor_linearization_has_the_hover_structure():
    lin = plant("quadrotor").linearize()
    arm, Kf, Kt, m = 0.19685, 0.1188, 0.0036, 2.85
    Jp = 2 * (1.91e-6 + m / 4 * arm**2)
    A = np.zeros((8, 8))
    A[0, 3] = A[1, 4] = A[2, 5] = A[6, 7] = 1.0
    B = np.zeros((8, 4))
    B[3] = arm * Kf / Jp * np.array([0, 0, -1, 1])      # roll: left minus right
    B[4] = arm * Kf / Jp * np.array([1, -1, 0, 0])      # pitch: front minus back (Quanser's pitch row)
    B[5] = Kt / (2 * Jp) * np.array([1, 1, -1, -1])   # yaw: Jy = 2 Jp
    B[7] = -Kf / m
    E = np.zeros((8, 1))
    E[5] = 1 / (2 * Jp)
    assert np.allclose(lin.A, A, atol=1e-12) and np.allclose(lin.B, B, rtol=1e-12)
    assert np.allclose(lin.E, E, rtol=1e-12) and np.allclose(lin.C, np.eye(8))


def test_quadrotor_attitude_zoh_rate_rows():
    lin = plant("quadrotor").linearize()
    attitude = system("hover_attitude", "linear attitude part at hover", x=plant("quadrotor").x.select(
        ["phi", "theta", "psi", "p", "q", "r"]), u=plant("quadrotor").u,
        rhs=lambda x, u, d, p: ca.mtimes(ca.DM(lin.A[:6, :6]), x) + ca.mtimes(ca.DM(lin.B[:6]), u))
    H = attitude.discretize(0.01).linearize().B
    assert round(H[4, 0], 6) == 4.235e-3 and round(H[3, 3], 6) == 4.235e-3   # pitch and roll rate rows
    assert round(H[5, 0], 7) == 3.260e-4 and round(H[5, 2], 7) == -3.260e-4  # yaw rate row
    assert H[1, 0] == pytest.approx(4.235e-3 * 0.01 / 2, rel=1e-3)            # angle row: b dt^2 / 2


# --- ROV heading ------------------------------------------------------------------------------------

def test_rov_full_thrust_steady_yaw_rate():
    sys = plant("rov_yaw")
    # 0.45 r^2 + 0.023 r = 0.2  =>  r = (-0.023 + sqrt(0.023^2 + 4 * 0.45 * 0.2)) / 0.9
    r_ss = (-0.023 + math.sqrt(0.023**2 + 0.36)) / 0.9
    assert r_ss == pytest.approx(0.641601, abs=1e-6)
    run = solve_ivp(lambda _t, x: _f(sys, x, [1.0]), (0, 20), [0.0, 0.0], rtol=1e-10, atol=1e-12)
    assert run.y[1, -1] == pytest.approx(r_ss, rel=1e-8)
    assert sys.u_min.tolist() == [-1.0] and sys.u_max.tolist() == [1.0]
    assert sys.x_op[0] == pytest.approx(math.radians(150))


# --- registry ---------------------------------------------------------------------------------------

def test_registry_lists_plants_then_vehicles_and_caches():
    assert plant_names() == PLANTS + uvsym.vehicle_names()
    assert uvsym.plant is plant and plant("quadrotor") is plant("quadrotor")
    usv = plant("otter3dof")
    assert usv.x.names == ("x", "y", "psi", "u", "v", "r") and usv.u.names == ("T_L", "T_R")
    assert plant("quadrotor", m=3.0).extras["trim_voltage"] == pytest.approx(3.0 * 9.81 / (4 * 0.1188))


def test_unknown_plant_lists_known_names():
    with pytest.raises(UnknownNameError, match="induction_motor, quadrotor, rov_yaw, remus100"):
        plant("quadcopter")


# --- bad input ----------------------------------------------------------------------------------------

def test_rhs_of_the_wrong_size():
    with pytest.raises(ModelError, match="rhs gives 1 entries"):
        system("bad", "", x=signals(("a", "m"), ("b", "m/s")), u=signals(("f", "N")), rhs=lambda x, u, d, p: x[0])


@pytest.mark.parametrize(("name", "parameter"), [("quadrotor", "m"), ("induction_motor", "Rr"), ("rov_yaw", "m66")])
def test_non_finite_override_names_the_parameter(name, parameter):
    with pytest.raises(ModelError, match=f"{name}: parameter '{parameter}' must be finite"):
        plant(name, **{parameter: math.nan})


def test_unknown_signal_names():
    sys = plant("rov_yaw")
    with pytest.raises(UnknownNameError, match="no state named 'yaw'; known: psi, r"):
        sys.x.index("yaw")
    with pytest.raises(UnknownNameError, match="'rate'"):
        sys.linearize(x0={"psi": 0.0, "rate": 0.0})
    assert sys.linearize(x0={"psi": 1.0, "r": 0.5}).x0.tolist() == [1.0, 0.5]


def test_jacobian_not_finite_names_the_entry():
    root = system("root", "x' = sqrt(x)", x=signals(("s", "m")), u=signals(("f", "N")),
                  rhs=lambda x, u, d, p: ca.sqrt(x) + u)
    with pytest.raises(ModelError, match=r"A is not finite .*d s / d s"):
        root.linearize([0.0], [0.0])
    assert root.linearize([4.0], [0.0]).A[0, 0] == pytest.approx(0.25)
