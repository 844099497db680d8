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
    with pytest.raises(SimulationError, match=r"diverged: its signals are non-finite from t = \d"):
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
