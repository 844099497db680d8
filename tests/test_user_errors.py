"""The mistakes a new user makes get typed errors that name the problem."""

import json
import math

import casadi as ca
import numpy as np
import pytest

import uvsym
from uvsym.cli import main
from uvsym.codegen.estimators import exported_observer
from uvsym.codegen.package import write_package
from uvsym.errors import (
    CodegenError,
    ModelError,
    ObserverError,
    SimulationError,
    UnknownNameError,
    UvsymError,
    WiringError,
)
from uvsym.observers.luenberger import luenberger_observer
from uvsym.sim import block, pid, simulate_system
from uvsym.systems import signals, system
from uvsym.verify import synthesize_observer_gain

X = signals(("pos", "m"), ("vel", "m/s"), group="state")
U = signals(("force", "N"), group="input")


def _spring():
    return system("spring", "mass-spring-damper", x=X, u=U, rhs=lambda x, u, d, p: [x[1], -x[0] - 0.5 * x[1] + u[0]])


def test_a_plain_list_is_an_expression_and_math_functions_are_caught():
    assert _spring().f([1.0, 2.0], [0.5], [], []).full().ravel().tolist() == [2.0, -1.0 - 1.0 + 0.5]
    with pytest.raises(ModelError, match="NaN constant.*ca.sin"):
        system("bad", "d", x=X, u=U, rhs=lambda x, u, d, p: ca.vertcat(x[1], -math.sin(x[0]) + u[0]))
    with pytest.raises(ModelError, match="must return a CasADi expression"):
        system("bad", "d", x=X, u=U, rhs=lambda x, u, d, p: "x'")


def test_names_that_cannot_name_c_functions_are_refused_before_casadi_sees_them():
    with pytest.raises(WiringError, match="block name 'my-ctrl'"):
        block("my-ctrl", step=lambda s, r: (s, r), reads="a", publishes="b")
    with pytest.raises(ObserverError, match="observer name 'a__b'"):
        luenberger_observer(_spring(), np.ones((2, 2)), 0.1, name="a__b")


def test_gain_synthesis_certifies_or_refuses():
    lin = uvsym.plant("otter3dof").linearize()
    design = synthesize_observer_gain(lin.A, lin.C, decay=2.0)  # the optimum used to sit on the boundary
    assert design.certificate.status == "proved"
    assert np.linalg.eigvals(lin.A - design.L @ lin.C).real.max() < -2.0
    for bad in (float("nan"), -5.0):
        with pytest.raises(UvsymError, match="decay must be a finite rate >= 0"):
            synthesize_observer_gain(lin.A, lin.C, decay=bad)


def test_files_where_folders_are_expected(tmp_path):
    afile = tmp_path / "a_file"
    afile.write_text("mine")
    obs = luenberger_observer(_spring(), [[1.0, 0.0], [0.0, 1.0]], 0.1)
    with pytest.raises(CodegenError, match="a_file is a file, not a folder"):
        write_package(afile / "pkg", [exported_observer(obs)], "spring_obs")
    assert main(["report", "models", "--out", str(afile)]) == 2
    assert afile.read_text() == "mine"


def test_codegen_takes_a_sets_own_options_typed(tmp_path, capsys):
    assert main(["codegen", "motor-luenberger", "-o", str(tmp_path / "a"), "--decay", "30", "--dt=2e-4"]) == 0
    manifest = json.loads((tmp_path / "a" / "manifest.json").read_text())
    assert "decay 30 1/s" in manifest["description"] and "step 0.0002 s" in manifest["description"]
    assert main(["codegen", "motor-luenberger", "-o", str(tmp_path / "b"), "--decay", "fast"]) == 2
    assert "--decay takes a float" in capsys.readouterr().err
    assert main(["codegen", "motor-luenberger", "-o", str(tmp_path / "c"), "--colour", "red"]) == 2
    assert "its options: --decay, --dt" in capsys.readouterr().err


def test_a_diverging_loop_says_when_and_results_name_unknown_signals():
    plant = _spring()
    unstable = pid("c", measured="pos", reference=1.0, kp=-50.0, output="force", dt=0.01)
    with pytest.raises(SimulationError, match=r"diverged: [a-z_]+\.\w+ \((nan|-?inf)\) is non-finite from t = \d"):
        simulate_system(plant, [unstable], duration=200.0, dt=0.01, x0=[0.0, 0.0])
    result = simulate_system(plant, [pid("c", measured="pos", reference=1.0, kp=5.0, ki=1.0, output="force",
                                         dt=0.01)], duration=1.0, dt=0.01, x0=[0.0, 0.0])
    with pytest.raises(UnknownNameError, match="no signal 'ctrl'; signals: x, y"):
        result["ctrl"]
    with pytest.raises(KeyError):  # still a KeyError for code that catches one
        result["x"]["position"]


def test_plant_json_summary_has_its_operating_point(capsys):
    assert main(["models", "show", "induction_motor", "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["operating_point"]["x"]["omega_m"] == 250.0 and summary["operating_point"]["u"]["u_sd"] > 0


def test_observers_refuse_shared_names_and_bad_runs():
    from uvsym.observers.base import observer

    with pytest.raises(ObserverError, match=r"names \['a'\] stand in more than one"):
        observer("o", step=lambda s, y, u, p: (s, s), state=signals(("a", "-")), reads_y=signals(("a", "-")),
                 reads_u=signals(), publishes=signals(("b", "-")), dt=0.1)
    obs = observer("o", step=lambda s, y, u, p: (0.5 * s + y, s), state=signals(("a", "-")),
                   reads_y=signals(("b", "-")), reads_u=signals(), publishes=signals(("c", "-")), dt=0.1)
    with pytest.raises(ObserverError, match="at least one sample"):
        obs.run(np.zeros((0, 1)), np.zeros((0, 0)))
    with pytest.raises(ObserverError, match="s0 must be 1 finite"):
        obs.run(np.zeros((3, 1)), np.zeros((3, 0)), s0=[np.nan])
    with pytest.raises(ObserverError, match="NaN constant"):
        observer("o", step=lambda s, y, u, p: (s * math.nan, s), state=signals(("a", "-")),
                 reads_y=signals(("b", "-")), reads_u=signals(), publishes=signals(("c", "-")), dt=0.1)


def test_gain_synthesis_falls_back_to_the_rate_itself():
    A, C = np.diag([-1.0, 2.0]), np.array([[0.0, 1.0]])  # the first mode is unobservable, at rate 1
    design = synthesize_observer_gain(A, C, decay=0.995)  # 1 % more is infeasible, the rate itself is not
    assert design.certificate.status == "proved"
    with pytest.raises(UvsymError, match="at 1.515 1/s: infeasible and at 1.5 1/s: infeasible"):
        synthesize_observer_gain(A, C, decay=1.5)


def test_shared_plants_cannot_be_changed_by_one_user():
    motor = uvsym.plant("induction_motor")
    with pytest.raises(ValueError):
        motor.x_op[0] = 99.0
    assert uvsym.plant("otter", rp=np.array([0.05, 0.0, -0.3])).name == "otter"  # an array override is hashed


# --- Functions of a Model, System or Observer are called through a checked layer -----------------

def test_model_functions_name_the_argument_and_agree_with_the_raw_function():
    from uvsym.errors import ArgumentError, KinematicsError

    model = uvsym.vehicle("docking_auv")
    x, u = np.linspace(0.1, 1.2, 12), np.array([10.0, 0.1, -0.1, 0.05])
    assert isinstance(model.f, ca.Function) and not isinstance(model.f.raw, type(model.f))
    np.testing.assert_array_equal(np.asarray(model.f(x, u, [0.2, 0.3])), np.asarray(model.f.raw(x, u, [0.2, 0.3])))
    np.testing.assert_array_equal(np.asarray(model.f(x=x, u=u, p=[0.2, 0.3])["x_dot"]),
                                  np.asarray(model.f.raw(x, u, [0.2, 0.3])))
    with pytest.raises(ArgumentError, match=r"docking_auv.f: argument x has 11 entries .* expected 12"):
        model.f(x[:11], u, [0.0, 0.0])
    with pytest.raises(ArgumentError, match="unknown argument 'uu'; its arguments are x, u, p"):
        model.f(x=x, uu=u, p=[0.0, 0.0])
    with pytest.raises(ArgumentError, match=r"takes 3 arguments \(x, u, p\), got 2"):
        model.f(x, u)
    with pytest.raises(ArgumentError, match="argument nu entry v is nan"):
        model.nu_dot(x[:6], [1.0, np.nan, 0, 0, 0, 0], u, 0.0, 0.0)
    with pytest.raises(ArgumentError, match="argument u has 0 entries"):  # CasADi would read [] as zeros
        model.tau(x[:6], x[6:], [], 0.0, 0.0)
    with pytest.raises(ArgumentError, match="argument eta has 6 entries \\(shape \\(2, 3\\)\\)"):
        model.B(np.ones((2, 3)), x[6:], u, 0.0, 0.0)
    with pytest.raises(ArgumentError, match="argument u must be real numbers or a CasADi expression, got str"):
        model.f(x, "thrust", [0.0, 0.0])
    with pytest.raises(ArgumentError, match="argument x must be real numbers or a CasADi expression, got NoneType"):
        model.f(None, u, [0.0, 0.0])  # not read as NaN
    with pytest.raises(ArgumentError, match="argument p must be real numbers or a CasADi expression, got ndarray"):
        model.f(x, u, np.array([0.2, 0.3]) + 1j)  # not cut to its real part
    with pytest.raises(ArgumentError, match=r"output x_dot entry \w+ is -?(inf|nan) at finite arguments .*outside "
                                            r"the equations' domain or overflows double precision"):
        model.f(np.r_[x[:6], 1e200, x[7:]], u, [0.0, 0.0])  # quadratic damping of a 1e200 m/s surge
    pitched_up = x.copy()
    pitched_up[4] = math.pi / 2  # J(eta) is singular: the raw Function gives ~1e15 here
    assert np.abs(np.asarray(model.f.raw(pitched_up, u, [0.0, 0.0]))).max() > 1e12
    with pytest.raises(KinematicsError, match="docking_auv.f: x entry theta.*singular at theta = 90 deg"):
        model.f(pitched_up, u, [0.0, 0.0])
    symbolic = model.f(ca.SX.sym("x", 12), u, [0.0, 0.0])  # symbolic calls are not checked
    assert isinstance(symbolic, ca.SX) and symbolic.shape == (12, 1)


def test_system_and_observer_functions_are_checked_and_keep_their_api():
    from uvsym.errors import ArgumentError
    from uvsym.observers.base import observer

    plant = _spring()
    assert float(plant.f([1.0, 2.0], [0.5], [], [])[1]) == -1.0 - 1.0 + 0.5  # the hand-derived value
    with pytest.raises(ArgumentError, match="spring.f: argument x entry vel is inf"):
        plant.f([1.0, math.inf], [0.5], [], [])
    with pytest.raises(ArgumentError, match="spring.h: argument u has 2 entries"):
        plant.h([1.0, 2.0], [0.5, 0.1], [])
    with pytest.raises(ArgumentError, match=r"root.f: output x_dot entry vel is nan at finite arguments"):
        system("root", "sqrt", x=X, u=U, rhs=lambda x, u, d, p: [x[1], ca.sqrt(x[0])]).f([-1.0, 0.0], [0.0], [], [])
    obs = observer("o", step=lambda s, y, u, p: (0.5 * s + y, s), state=signals(("a", "-")),
                   reads_y=signals(("b", "-")), reads_u=signals(), publishes=signals(("c", "-")), dt=0.1)
    s_next, out = obs.step([1.0], [2.0], [], [])
    assert float(s_next) == 2.5 and float(out) == 1.0
    with pytest.raises(ArgumentError, match="o.o_step: argument y entry b is nan"):
        obs.step([1.0], [math.nan], [], [])
    with pytest.raises(ArgumentError, match="unknown argument 'why'"):
        obs.step(s=[1.0], why=[2.0], u=[], p=[])
    S, _ = obs.run(np.ones((3, 1)), np.zeros((3, 0)), s0=[0.0])  # runs on the unchecked Function
    np.testing.assert_allclose(S.ravel(), [0.0, 1.0, 1.5, 1.75])


def test_actuator_observers_and_gain_design_refuse_the_wrong_objects():
    from uvsym.errors import ArgumentError
    from uvsym.observers import actuator_observer
    from uvsym.observers.gains import design_gains

    with pytest.raises(ObserverError, match=r"model must be a uvsym Model, got str .*uvsym.vehicle\('otter3dof'\)"):
        actuator_observer("otter3dof", "bias")
    model = uvsym.vehicle("otter3dof")
    obs = actuator_observer(model, "proportional", form="momentum")
    with pytest.raises(ObserverError, match="pass the observer, not its .function"):
        design_gains(obs.function, 1.0, [1.0, 1.0, 1.0])
    with pytest.raises(ObserverError, match="zero in every channel.*Remark 2"):
        design_gains(obs, 1.0, [0.0, 0.0, 0.0])
    with pytest.raises(ObserverError, match="tau_d must have 3 finite entries"):
        design_gains(obs, 1.0, [1.0, math.nan, 1.0])
    with pytest.raises(ObserverError, match="time_constant must be positive"):
        design_gains(obs, "1", [1.0, 1.0, 1.0])
    design = design_gains(obs, 2.0, [100.0, 0.0, 5.0])  # momentum form: rate k_i tau_d,i^2 (hand derivation)
    assert design.unobservable == (1,)
    np.testing.assert_allclose(design.K[[0, 2]], [1 / (2.0 * 100.0**2), 1 / (2.0 * 5.0**2)])
    with pytest.raises(ArgumentError, match="otter3dof.proportional_observer: argument K has 2 entries"):
        obs.function(np.zeros(3), np.zeros(3), np.zeros(3), np.ones(3), np.ones(2))


def test_a_wired_run_too_large_to_hold_is_refused_with_the_figures_before_allocating():
    from uvsym.sim.run import available_memory

    available = available_memory()
    if available is None:
        pytest.skip("this system does not say how much memory it has")
    samples = 10 ** math.ceil(math.log10(available / 8))  # >= 8 bytes a sample: more than is available
    controller = pid("c", measured="pos", reference=1.0, kp=5.0, output="force", dt=0.01)
    figures = r"needs at least [\d.]+ [KMGTPE]iB of memory, [\d.]+ [KMGTPE]iB are available"
    with pytest.raises(SimulationError, match=figures):
        simulate_system(_spring(), [controller], duration=0.01 * samples, dt=0.01, x0=[0.0, 0.0])
    with pytest.raises(SimulationError, match=r"1e\+14 samples, more than 1e\+12"):
        simulate_system(_spring(), [controller], duration=1e12, dt=0.01, x0=[0.0, 0.0])


def _cases_of_the_api():
    """(call, error type, message) for bad arguments of the Python API a user meets first."""
    from uvsym.errors import FaultError, ModelError, ObserverError, SimulationError, VerificationError
    from uvsym.faults import SensorFault
    from uvsym.observers import actuator_observer
    from uvsym.observers.gains import design_gains
    from uvsym.sim import lqr_gain, pid, simulate_system
    from uvsym.sim.result import Signal, SimResult
    from uvsym.systems import plant
    from uvsym.systems.discretize import zoh_matrices
    from uvsym.verify.uio import exact_zoh

    rov = plant("rov_yaw")
    heading = pid("c", measured="psi", reference=0.0, kp=1.0, output="u", dt=0.1)
    row = Signal(np.zeros((2, 1)), ("a",), ("m",))
    return [
        (lambda: uvsym.vehicle("otter", rp=["a", "b", "c"]), ModelError, "parameter 'rp' must be a number or a list"),
        (lambda: uvsym.vehicle("otter", mp={"a": 1}), ModelError, "parameter 'mp' must be a number or a list"),
        (lambda: uvsym.vehicle("otter", mp=1e300), ModelError, r"cannot be built with mp=1e\+300"),
        (lambda: plant("rov_yaw", m66=[1, "x"]), ModelError, "parameter 'm66' must be a number or a list"),
        (lambda: rov.discretize("0.1"), ModelError, r"sample period dt \(s\) must be a finite number, got '0.1'"),
        (lambda: pid("c", measured="psi", kp="5", output="u", dt=0.1), ModelError, "pid c: kp must be a finite"),
        (lambda: pid("c", measured="psi", kp=5.0, output="u", dt=0.1, limits=(1.0,)), ModelError,
         r"limits must be \(lo, hi\)"),
        (lambda: simulate_system(rov, [heading], duration=1.0, dt=0.1, x0=[0, 0], seed=-1), SimulationError,
         "seed must be an integer >= 0"),
        (lambda: design_gains(actuator_observer(uvsym.vehicle("docking_auv"), "bias", "momentum"), 1e-300),
         ObserverError, "time_constant 1e-300 s is outside"),
        (lambda: lqr_gain(np.eye(2), np.ones((2, 1)), np.diag([1.0, -1.0]), np.eye(1)), ModelError,
         "Q must be positive semi-definite"),
        (lambda: lqr_gain(np.eye(2), np.ones((2, 1)), np.eye(2), np.zeros((1, 1))), ModelError,
         "R must be positive definite"),
        (lambda: zoh_matrices(np.eye(2), np.ones((2, 1)), -1), ModelError, r"dt \(s\) must be positive"),
        (lambda: exact_zoh(np.zeros((2, 2)), np.ones((2, 1)), -1), VerificationError, "dt must be positive"),
        (lambda: SimResult(np.array([0.0, np.nan]), {"x": row}, {}), SimulationError, r"t must be finite"),
        (lambda: SimResult(np.array([1.0, 0.0]), {"x": row}, {}), SimulationError, "never decreasing"),
        (lambda: SensorFault(0, "bias"), FaultError, "a bias sensor fault of 0 changes nothing"),
    ]


@pytest.mark.parametrize("index", range(16))
def test_bad_arguments_of_the_api_get_typed_errors_naming_them(index):
    call, error, message = _cases_of_the_api()[index]
    with pytest.raises(error, match=message):
        call()
