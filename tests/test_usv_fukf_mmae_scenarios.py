"""The FUKF-MMAE study as scenario files: the shipped scenario reproduces the study's former
pipeline (the closed loop first, then each bank run on the finished record), the file's numbers
follow from the model, bad fields are named before any run, and the hypothesis-switch detector
decides as its rule says on hand-made series."""

import re

import casadi as ca
import numpy as np
import pytest

import uvsym
from derivations.usv_fukf_mmae import experiment
from derivations.usv_fukf_mmae.scenario import block_table, parsed, read
from uvsym.cli import main
from uvsym.diagnosis.hypotheses import HypothesisSwitch
from uvsym.errors import DiagnosisError, ScenarioError
from uvsym.faults import ActuatorFault, Profile, SensorFault
from uvsym.models.actuators import saturate
from uvsym.observers.ekf import extended_filter
from uvsym.observers.kalman import efficiency_augmented, run_filter
from uvsym.observers.mmae import mmae_bank
from uvsym.observers.ukf import unscented_filter
from uvsym.sim import simulate_system
from uvsym.sim.blocks import block
from uvsym.sim.controllers import Autopilot, LineOfSight, Loop
from uvsym.sim.result import Signal, SimResult
from uvsym.systems.signals import signals
from uvsym.systems.system import system

# The former experiment's settings (its scenario file and tuning), typed as it had them.
DT, DURATION, SEED, ALPHA_D, SPEED = 0.05, 300.0, 3, (6.0, 6.0, 3.0), 1.5
NOISE = {"x": 0.05, "y": 0.05, "psi": 0.0035, "u": 0.02, "v": 0.02, "r": 0.0035}
WAYPOINTS = ((0.0, 0.0), (150.0, 0.0), (150.0, 75.0), (0.0, 75.0), (0.0, 0.0), (60.0, 0.0))
FAULTS = (("T_L", 0.4, 100.0, 150.0), ("T_R", 0.3, 200.0, 250.0))
P0_STD = (0.5, 0.5, 0.05, 0.1, 0.1, 0.05, 0.2)
MODELS = {"nofault": (), "left": ("T_L",), "right": ("T_R",)}


def former_pipeline() -> dict:
    """The study's former code path: disturbance drawn with seed 3 and noise with seed 4, the
    guidance built by hand, the loop simulated, then each bank (filters on the still-water model)
    run on the record. Returns method -> (t, the bank's published rows, its labels)."""
    plant = experiment.disturbed_plant()
    N = int(round(DURATION / DT))
    disturbance = np.asarray(ALPHA_D) * np.random.default_rng(SEED).uniform(-1.0, 1.0, size=(N + 1, 3))
    faults = tuple(ActuatorFault(plant.u.index(u), "loss_of_effectiveness", 1.0 - eff, Profile("step", onset=a, end=b))
                   for u, eff, a, b in FAULTS)
    noise = tuple(SensorFault(plant.y.index(s), "noise", std) for s, std in NOISE.items())
    model = uvsym.vehicle("otter3dof")
    autopilot = Autopilot(speed=Loop(SPEED, feedforward=experiment.surge_damping() * SPEED, kp=100.0, ki=10.0,
                                     i_limit=3.0),
                          heading=Loop(0.0, kp=80.0, ki=4.0, kd=120.0, i_limit=5.0),
                          path=LineOfSight(WAYPOINTS, lookahead=10.0, turn_radius=10.0),
                          outputs={"speed": {"T_L": 0.5, "T_R": 0.5}, "yaw": {"T_L": 1.0, "T_R": -1.0}})

    def step(s, r):
        s_next, u_d, _ = autopilot.law(s, r, DT, model)
        return s_next, saturate(u_d, ca.DM(plant.u_min), ca.DM(plant.u_max))

    guidance = block("guidance", step=step, state=signals(*[(n, "") for n in autopilot.state_labels], group="state"),
                     reads=plant.x.names, publishes=plant.u.names, dt=DT)
    result = simulate_system(plant, [guidance], duration=DURATION, dt=DT, x0=[0.0, 0.0, 0.0, SPEED, 0.0, 0.0],
                             d=disturbance, actuator_faults=faults, sensor_faults=noise, seed=SEED + 1, compiled=False)
    base = uvsym.plant("otter3dof")
    still = system("otter_still", "still water", x=base.x, u=base.u, u_min=base.u_min, u_max=base.u_max,
                   rhs=lambda x, u, d, p: base.f(x, u, [], ca.DM.zeros(base.p.size)))
    Q6 = experiment.process_noise(ALPHA_D, DT, SPEED, 0.0)
    R = np.array(list(NOISE.values())) ** 2
    banks = {}
    for method in ("ukf", "ekf"):
        built = {}
        for name, inputs in MODELS.items():
            n = 6 + len(inputs)
            Q = np.zeros((n, n))
            Q[:6, :6], Q[6:, 6:] = Q6, 0.005 ** 2 * np.eye(len(inputs))
            options = dict(dt=DT, Q=Q, R=R, P0=np.asarray(P0_STD[:n]) ** 2, name=name,
                           x0=np.r_[0.0, 0.0, 0.0, SPEED, 0.0, 0.0, np.ones(len(inputs))])
            augmented = efficiency_augmented(still, inputs) if inputs else still
            built[name] = unscented_filter(augmented, **options) if method == "ukf" else extended_filter(augmented,
                                                                                                        **options)
        obs = mmae_bank(built, name=method, p_min=1e-4, prior=(0.98, 0.01, 0.01), reset=True)
        _, OUT = run_filter(obs, result["y"].values, result["guidance"].values)
        banks[method] = (result.t, OUT, obs.publishes.names)
    return banks


@pytest.fixture(scope="module")
def shipped_run():
    return experiment.run(parsed(read()))


def test_the_shipped_scenario_reproduces_the_former_pipeline(shipped_run):
    """Same arithmetic but for the filters' model (the plant with its current parameters at 0
    instead of a copy with them removed) and R, P0 typed as variances (0.0025 for 0.05^2): the
    banks' rows agree to 1e-9, so the probabilities, estimates and switch times do."""
    for method, (t, OUT, labels) in former_pipeline().items():
        ours = shipped_run[method]
        assert ours.labels == labels
        np.testing.assert_allclose(ours.values, OUT, rtol=0, atol=1e-9)
        p = OUT[:, [labels.index(f"p_{m}") for m in ("left", "right")]]
        for column, (thruster, _, onset, end) in enumerate(FAULTS):
            first = t[np.flatnonzero((t >= onset) & (t < end) & (p[:, column] > 0.9))[0]]
            detected = [e["t"] for e in shipped_run.events if e["detector"] == f"{method}_mmae"
                        and e["event"] == "detected" and e["target"] == thruster]
            assert detected == [pytest.approx(first, abs=1e-9)]


def test_the_files_numbers_follow_from_the_model():
    table = read()
    for name in ("ukf", "ekf"):
        bank = block_table(table, name)
        np.testing.assert_array_equal(np.asarray(bank["q"]), experiment.process_noise((6.0, 6.0, 3.0), 0.05, 1.5, 0.0))
        sensors = [v for v in table["noise"].values() if not isinstance(v, dict)]   # the random force aside
        np.testing.assert_allclose(bank["r"], np.array(sensors) ** 2, rtol=1e-12)
    feedforward = block_table(table, "guidance")["speed_loop"]["feedforward"]
    assert feedforward == experiment.surge_damping() * 1.5
    assert [table["noise"][k]["uniform"] for k in ("tau_u", "tau_v", "tau_r")] == [6.0, 6.0, 3.0]


def _bad(edit) -> str:
    table = read()
    edit(table)
    with pytest.raises(ScenarioError) as info:
        parsed(table)
    return str(info.value)


@pytest.mark.parametrize("edit, field", [
    (lambda t: t["blocks"][1].update(type="mmea"), r"blocks\[1\]\.type: unknown value 'mmea'"),
    (lambda t: t["blocks"][1].update(walk_sd=0.01), r"blocks\[1\]\.walk_sd: unknown field \(did you mean 'walk_std'"),
    (lambda t: t["blocks"][1].update(filter="pf"), r"blocks\[1\]\.filter: unknown value 'pf'"),
    (lambda t: t["blocks"][1]["models"].update(left=["T_X"]), r"blocks\[1\]\.models\.left: "),
    (lambda t: t["blocks"][1].update(prior=[0.5, 0.5]), r"blocks\[1\]\.prior: expected a list of 3 numbers"),
    (lambda t: t["blocks"][1].update(floor=0.4), r"blocks\[1\] \(mmae 'ukf'\): ukf: p_min must be in \(0, 1/3\)"),
    (lambda t: t["blocks"][1].update(q=[1.0, 2.0]), r"blocks\[1\]\.q: expected a finite 6 x 6 matrix"),
    (lambda t: t["blocks"][2].update(alpha=0.5), r"blocks\[2\]: alpha, beta and kappa tune a UKF"),
    (lambda t: t["blocks"][0]["mix"]["speed"].update(T_X=0.5), r"blocks\[0\]\.mix\.speed\.T_X: not an input"),
    (lambda t: t["blocks"][0].update(waypoints=[[0.0, 0.0]]), r"blocks\[0\]\.waypoints: expected a list of at least"),
    (lambda t: t["blocks"][0].update(turn_radius=200.0), r"blocks\[0\]\.turn_radius: 200(\.0)? m is too large"),
    (lambda t: t["blocks"][0]["heading_loop"].update(kq=1.0), r"blocks\[0\]\.heading_loop\.kq: unknown field"),
    (lambda t: t["blocks"][0].pop("speed_loop"), r"blocks\[0\]\.speed_loop: required table"),
    (lambda t: t["noise"].update(tau_x={"uniform": 1.0}),
     r"noise\.tau_x: unknown output or disturbance .*tau_u, tau_v, tau_r"),
    (lambda t: t["noise"].update(tau_u={"uniform": -1.0}), r"noise\.tau_u\.uniform: must be positive"),
    (lambda t: t["noise"].update(tau_u={"unifrom": 1.0}), r"noise\.tau_u\.unifrom: unknown field"),
    (lambda t: t["detectors"][0].update(bank="ukff"), r"detectors\[0\]\.bank: 'ukff' is not an mmae block of the "
                                                      r"scenario \(did you mean 'ukf'\?\)"),
    (lambda t: t["detectors"][0].update(bank="guidance"), r"detectors\[0\]\.bank: 'guidance' is not an mmae block"),
    (lambda t: t["detectors"][0].update(threshold=0.3), r"detectors\[0\]\.threshold: must be in \[0\.5, 1\)"),
    (lambda t: t["detectors"][0].update(dwel=3), r"detectors\[0\]\.dwel: unknown field \(did you mean 'dwell'"),
    (lambda t: t["detectors"][0].update(kind="wobble"), r"detectors\[0\]\.kind: unknown value 'wobble'"),
    (lambda t: t["faults"][0].update(actuator="T_X"), r"faults\[0\]\.actuator: unknown value 'T_X'"),
])
def test_bad_fields_are_named_before_any_run(edit, field):
    assert re.match(field, _bad(edit)), _bad(edit)


def test_a_bank_without_a_no_fault_model_cannot_be_decided():
    def edit(table):
        table["blocks"][1]["models"] = {"left": ["T_L"], "right": ["T_R"]}
        table["blocks"][1]["prior"] = [0.5, 0.5]
    assert re.match(r"detectors\[0\] \(ukf_mmae\): detector ukf_mmae: bank ukf needs exactly one no-fault model",
                    _bad(edit))


def _series(p_left, p_right, alpha_left, dt=0.5) -> SimResult:
    p_left, p_right = np.asarray(p_left, float), np.asarray(p_right, float)
    rows = np.column_stack([1.0 - p_left - p_right, p_left, p_right, alpha_left, np.ones_like(p_left)])
    labels = ("p_nofault", "p_left", "p_right", "left.alpha_T_L_hat", "right.alpha_T_R_hat")
    return SimResult(dt * np.arange(p_left.size), {"bank": Signal(rows, labels, ("-",) * 5)}, {})


MODEL_SET = (("nofault", ()), ("left", ("T_L",)), ("right", ("T_R",)))


def test_the_detector_switches_after_its_dwell_and_identifies_once_the_estimate_settles():
    p_left = [0.0, 0.95, 0.0, 0.95, 0.95, 0.95, 0.95, 0.95, 0.95, 0.2, 0.0, 0.0]
    alpha = [1.0, 0.9, 0.8, 0.7, 0.5, 0.45, 0.44, 0.45, 0.44, 0.44, 1.0, 1.0]
    detector = HypothesisSwitch("d", "bank", MODEL_SET, threshold=0.9, dwell=2, settle=3, resolution=0.02)
    events = [(e.t, e.event, e.target, e.kind, e.value) for e in detector.decide(_series(p_left, [0.0] * 12, alpha))]
    # the lone sample at 0.5 s does not last two samples; 1.5 s and 2 s do; the estimate stays within 0.02 over
    # the three samples ending at 3.5 s (0.45, 0.44, 0.45); at 4.5 s nothing leads (0.8 < 0.9), nofault leads at
    # 5 s and 5.5 s
    assert events == [(2.0, "detected", "T_L", None, None), (2.0, "isolated", "T_L", "proportional", None),
                      (3.5, "identified", "T_L", "proportional", 0.45), (5.5, "cleared", "T_L", None, None)]


def test_the_detector_ignores_the_start_up_and_switches_between_faults():
    p_left = [0.95, 0.95, 0.95, 0.0, 0.0, 0.0]
    p_right = [0.0, 0.0, 0.0, 0.95, 0.95, 0.95]
    detector = HypothesisSwitch("d", "bank", MODEL_SET, dwell=1, settle=50, ignore_before=1.0)
    events = [(e.t, e.event, e.target) for e in detector.decide(_series(p_left, p_right, [1.0] * 6))]
    assert events == [(1.0, "detected", "T_L"), (1.0, "isolated", "T_L"), (1.5, "cleared", "T_L"),
                      (1.5, "detected", "T_R"), (1.5, "isolated", "T_R")]
    with pytest.raises(DiagnosisError, match="threshold must be in"):
        HypothesisSwitch("d", "bank", MODEL_SET, threshold=1.0)
    with pytest.raises(DiagnosisError, match="signal 'bank.p_nofault' is not in the result"):
        HypothesisSwitch("d", "bank", MODEL_SET).decide(SimResult(np.zeros(2), {}, {}))


def test_the_shipped_scenario_is_listed_by_the_cli(capsys):
    assert main(["simulate", "--list"]) == 0
    assert any(line.split()[:2] == ["otter_thruster_faults", "usv-fukf-mmae"]
               for line in capsys.readouterr().out.splitlines())


def test_a_growing_fault_is_identified_again_where_its_estimate_settles():
    alpha = [1.0, 0.8, 0.8, 0.8, 0.7, 0.6, 0.5, 0.4, 0.4, 0.4, 0.41, 0.4]
    detector = HypothesisSwitch("d", "bank", MODEL_SET, settle=3, resolution=0.02)
    events = [(e.t, e.event, e.value) for e in detector.decide(_series([0.95] * 12, [0.0] * 12, alpha))
              if e.event == "identified"]
    assert events == [(1.5, "identified", 0.8), (4.5, "identified", 0.4)]  # 0.41 is within 0.02 of 0.4


def test_random_disturbances_are_bounded_by_their_amplitudes_and_seeded_apart_from_the_noise():
    table = read()
    table["noise"] = {k: v for k, v in table["noise"].items() if not k.startswith("tau_")}
    table["noise"] |= {"tau_u": {"uniform": 6.0}, "tau_r": {"uniform": 3.0}, "tau_v": 0.5}
    table.pop("disturbance_seed")
    table.update(seed=7)
    disturbance = parsed(table).disturbance_noise
    assert disturbance.seed == (7, 1)  # default: its own stream of the noise seed
    draws = disturbance.draws(4000)
    assert draws.shape == (4001, 3) and abs(np.std(draws[:, 1]) - 0.5) < 0.02     # Gaussian tau_v
    assert np.all(np.abs(draws[:, 0]) <= 6.0) and np.max(np.abs(draws[:, 0])) > 5.9
    assert np.all(np.abs(draws[:, 2]) <= 3.0) and abs(np.std(draws[:, 2]) - 3.0 / np.sqrt(3.0)) < 0.05
    table["disturbance_seed"] = 9
    assert not np.allclose(parsed(table).disturbance_noise.draws(10), draws[:11])


def test_the_campaign_covers_both_thrusters_profiles_noise_levels_and_healthy_hours():
    from derivations.usv_fukf_mmae.campaign import CAMPAIGN
    from uvsym.campaign import load_campaign

    runs = load_campaign(CAMPAIGN).runs  # every run's scenario validated here
    faults = [f for r in runs for f in r.scenario["faults"]]
    assert {f["actuator"] for f in faults} == {"T_L", "T_R"}
    assert {f.get("profile", "step") for f in faults} == {"step", "ramp", "intermittent"}
    assert {f["kind"] for f in faults} == {"proportional", "constant"}
    losses = [f["value"] for f in faults if f["kind"] == "proportional"]
    assert min(losses) <= 0.2 and max(losses) >= 0.95
    noise = {r.scenario["noise"]["x"] for r in runs}
    assert noise == {0.05, 0.1, 0.15}
    healthy = sum(r.scenario["duration"] for r in runs if not r.scenario["faults"] and r.scenario["noise"]["x"] == 0.05)
    assert healthy >= 1440.0  # s of healthy runs at the paper's noise (24 min; onsets add more)
    assert all(len(r.scenario["detectors"]) == 5 for r in runs)


def test_the_autopilot_clamps_its_commands_to_the_limits_it_is_given():
    table = read()
    table.update(duration=5.0, faults=[], detectors=[])
    table["blocks"] = [dict(block_table(table, "guidance"), limits=[-10.0, 20.0])]
    commands = experiment.run(parsed(table))["guidance"]
    both = np.column_stack([commands["T_L"], commands["T_R"]])
    assert both.max() == pytest.approx(20.0) and both.min() >= -10.0
    table["blocks"][0]["limits"] = [20.0, -10.0]
    with pytest.raises(ScenarioError, match=r"^blocks\[0\]\.limits: expected \[lo, hi\] with lo < hi"):
        parsed(table)
