"""The Otter on a rectangle with thruster faults, and the UKF and EKF banks run on its data.

Plant: ``uvsym.plant("otter3dof")`` plus the paper's random force ``tau_d = alpha_d rand(t)``
(eq. 6) as a disturbance, ``nu' += M^-1 tau_d``, one uniform draw per sample and axis. Loop:
line-of-sight guidance with speed and heading PID (:class:`uvsym.sim.controllers.Autopilot`)
as one block, thrust commands saturated at the thrusters' limits, thruster faults
``T_i = eta_i T_bar_i`` on their windows, every state measured with Gaussian noise. The banks
read the measurements and the saturated commands ``T_bar`` (what the thruster was told).

Banks (uvsym's tuning; the paper gives none): no-fault model (6 states) and one model per
thruster with its efficiency ``alpha_i`` (7 states), UKF (alpha 1, beta 2, kappa 0) or EKF,
probability floor 1e-4, prior 0.98 on no-fault, federated reset of the kinematic states every sample.
"""

from __future__ import annotations

import time

import casadi as ca
import numpy as np

import uvsym
from derivations.usv_fukf_mmae.scenario import STATES, Scenario
from uvsym.faults import ActuatorFault, Profile, SensorFault
from uvsym.models.actuators import saturate
from uvsym.observers.ekf import extended_filter
from uvsym.observers.kalman import efficiency_augmented, run_filter
from uvsym.observers.mmae import mmae_bank
from uvsym.observers.ukf import unscented_filter
from uvsym.sim import simulate_system
from uvsym.sim.blocks import block
from uvsym.sim.controllers import Autopilot, Loop
from uvsym.sim.result import Signal, SimResult
from uvsym.symbolic import rk4
from uvsym.systems.signals import signals
from uvsym.systems.system import System, system

__all__ = ["MODELS", "TUNING", "disturbed_plant", "still_water", "process_noise", "guidance", "simulate_plant",
           "filters", "bank", "bank_signal", "run_banks", "run_scenario"]

MODELS = {"nofault": (), "left": ("T_L",), "right": ("T_R",)}
TUNING = {
    "ukf": {"alpha": 1.0, "beta": 2.0, "kappa": 0.0},
    "alpha_walk_std": 0.005,  # per sample, of the efficiency random walk
    "P0_std": (0.5, 0.5, 0.05, 0.1, 0.1, 0.05, 0.2),  # x, y, psi, u, v, r, alpha
    "p_min": 1e-4,
    "prior": (0.98, 0.01, 0.01),  # nofault, left, right: the boat leaves healthy
    "reset": True,
}
GAINS = {"speed": {"kp": 100.0, "ki": 10.0, "i_limit": 3.0},  # N per m/s, N per m; integral limit m
         "heading": {"kp": 80.0, "ki": 4.0, "kd": 120.0, "i_limit": 5.0}}  # N per rad, rad s, rad/s; rad s


def disturbed_plant() -> System:
    """``otter3dof`` with the force disturbance ``tau_d = (tau_u, tau_v, tau_r)`` (N, N, N m)."""
    base, M = uvsym.plant("otter3dof"), uvsym.vehicle("otter3dof").M
    d = signals(("tau_u", "N", "surge force disturbance"), ("tau_v", "N", "sway force disturbance"),
                ("tau_r", "N m", "yaw moment disturbance"), group="disturbance")
    return system("otter3dof_disturbed", f"{base.description}; random force disturbance tau_d", x=base.x, u=base.u,
                  d=d, p=base.p, p0=base.p0,
                  rhs=lambda x, u, dd, p: base.f(x, u, [], p) + ca.vertcat(ca.DM.zeros(3), ca.solve(ca.DM(M), dd)),
                  u_min=base.u_min, u_max=base.u_max, constants=base.constants,
                  source=f"{base.source}; tau_d as in the FUKF-MMAE paper's eq. 6")


def guidance(scenario: Scenario, plant: System):
    """LOS guidance, speed and heading loops, mixed onto (T_L, T_R) and saturated, as a block.
    The speed loop's feed-forward is the surge drag at the set speed, ``d11 U``."""
    model = uvsym.vehicle(scenario.vehicle)
    autopilot = Autopilot(
        speed=Loop(scenario.speed, feedforward=surge_damping(model) * scenario.speed, **GAINS["speed"]),
        heading=Loop(0.0, **GAINS["heading"]), path=scenario.path,
        outputs={"speed": {"T_L": 0.5, "T_R": 0.5}, "yaw": {"T_L": 1.0, "T_R": -1.0}})
    state = signals(*[(n, "") for n in autopilot.state_labels], group="state")

    def step(s, r):
        s_next, u_d, _ = autopilot.law(s, r, scenario.dt, model)
        return s_next, saturate(u_d, ca.DM(plant.u_min), ca.DM(plant.u_max))

    return block("guidance", step=step, state=state, reads=plant.x.names, publishes=plant.u.names, dt=scenario.dt)


def surge_damping(model) -> float:
    """d11 (N s/m): d h_surge / d u at rest, by casadi.jacobian."""
    nu = ca.SX.sym("nu", model.dof)
    slope = ca.Function("d11", [nu], [ca.jacobian(model.h(ca.DM.zeros(model.dof), nu)[0], nu)])
    return float(slope(ca.DM.zeros(model.dof))[0])


def simulate_plant(scenario: Scenario, method: str = "fast", progress=None) -> SimResult:
    """The closed loop: x0 on the first leg at the set speed; disturbance and noise seeded. Runs on
    CasADi's virtual machine (not compiled) so that the numbers do not depend on C compiler flags."""
    plant = disturbed_plant()
    N = int(round(scenario.duration / scenario.dt))
    rng = np.random.default_rng(scenario.seed)
    disturbance = np.asarray(scenario.alpha_d) * rng.uniform(-1.0, 1.0, size=(N + 1, 3))
    faults = tuple(ActuatorFault(plant.u.index(f.thruster), "loss_of_effectiveness", 1.0 - f.efficiency,
                                 Profile("step", onset=f.onset, end=f.end)) for f in scenario.faults)
    noise = tuple(SensorFault(plant.y.index(state), "noise", scenario.noise[state]) for state in STATES)
    first = scenario.path.segments()[0]
    x0 = [*first["start"], first["angle"], scenario.speed, 0.0, 0.0]
    result = simulate_system(plant, [guidance(scenario, plant)], duration=scenario.duration, dt=scenario.dt, x0=x0,
                             method=method, d=disturbance, actuator_faults=faults, sensor_faults=noise,
                             seed=scenario.seed + 1, compiled=False, progress=progress)
    result.meta.update(seed=scenario.seed, disturbance_seed=scenario.seed, noise_seed=scenario.seed + 1)
    return result  # meta's seed is the scenario's (its disturbance draws); the noise draws use seed + 1


def still_water(vehicle: str) -> System:
    """The filters' model: the vehicle as a System in still water (V_c = 0, no parameters left),
    as the paper's eqs. 1-3 have it; the current's rotation by psi then drops out of the step."""
    base = uvsym.plant(vehicle)
    return system(f"{vehicle}_still_water", f"{base.description}; no current", x=base.x, u=base.u,
                  rhs=lambda x, u, d, p: base.f(x, u, [], ca.DM.zeros(base.p.size)), u_min=base.u_min,
                  u_max=base.u_max, constants=base.constants, source=f"{base.source}; V_c = 0")


def process_noise(scenario: Scenario) -> np.ndarray:
    """Q (6, 6) of the kinematic states: the disturbance's covariance ``alpha_d^2 / 3`` (uniform
    draws) through the sampled plant, ``G diag(alpha_d^2 / 3) G^T`` with ``G = dx_{k+1} / dtau_d``
    (casadi.jacobian of the RK4 step) at the set speed. The position block rotates with the
    heading: both positions get the largest variance over headings, their correlations with the
    other states are dropped; ``1e-12 I`` keeps Q positive definite."""
    plant, first = disturbed_plant(), scenario.path.segments()[0]
    x, d = ca.SX.sym("x", 6), ca.SX.sym("d", 3)
    u = ca.DM.zeros(plant.u.size)
    step = rk4(lambda s, _t: plant.f(s, u, d, plant.p0), x, scenario.dt, 1)
    jac = ca.Function("G", [x, d], [ca.jacobian(step, d)])
    spread = np.diag(np.asarray(scenario.alpha_d) ** 2 / 3.0)

    def at(psi):
        G = np.asarray(jac([0.0, 0.0, psi, scenario.speed, 0.0, 0.0], np.zeros(3)))
        return G @ spread @ G.T

    Q = at(first["angle"])
    Q[:2, :] = Q[:, :2] = 0.0
    Q[0, 0] = Q[1, 1] = max(float(np.max(np.diag(at(psi))[:2])) for psi in np.linspace(0.0, np.pi, 9))
    return Q + 1e-12 * np.eye(6)


def filters(scenario: Scenario, method: str) -> dict:
    """model name -> GaussianFilter ('ukf' or 'ekf') with the tuning of TUNING.

    Q: :func:`process_noise` for the kinematic states, TUNING's random walk for the efficiency;
    R the sensor noise variances; P0 from TUNING; x0 the start of the path.
    """
    base = still_water(scenario.vehicle)
    Q_kinematic = process_noise(scenario)
    R = np.array([scenario.noise[s] for s in STATES]) ** 2
    first = scenario.path.segments()[0]
    x0 = np.array([*first["start"], first["angle"], scenario.speed, 0.0, 0.0])
    built = {}
    for model, thrusters in MODELS.items():
        plant = efficiency_augmented(base, thrusters) if thrusters else base
        extra = len(thrusters)
        Q = np.zeros((6 + extra, 6 + extra))
        Q[:6, :6], Q[6:, 6:] = Q_kinematic, TUNING["alpha_walk_std"] ** 2 * np.eye(extra)
        options = dict(dt=scenario.dt, Q=Q, R=R,
                       P0=np.asarray(TUNING["P0_std"][:6 + extra]) ** 2, x0=np.concatenate([x0, np.ones(extra)]),
                       name=model)
        built[model] = (unscented_filter(plant, **options, **TUNING["ukf"]) if method == "ukf"
                        else extended_filter(plant, **options))
    return built


def bank(scenario: Scenario, method: str, p_min: float | None = None):
    """The MMAE bank (an Observer) of the three models, 'ukf' or 'ekf' (floor p_min, default TUNING's)."""
    return mmae_bank(filters(scenario, method), name=f"{method}_bank", p_min=p_min or TUNING["p_min"],
                     prior=TUNING["prior"], reset=TUNING["reset"])


def bank_signal(scenario: Scenario, result: SimResult, method: str, p_min: float | None = None) -> Signal:
    """Everything the bank publishes, one row per sample of ``result`` (measurements y, commands T_bar)."""
    obs = bank(scenario, method, p_min)
    _, OUT = run_filter(obs, result["y"].values, result["guidance"].values)
    return Signal(OUT, obs.publishes.names, obs.publishes.units)


def run_banks(scenario: Scenario, result: SimResult) -> dict:
    """method -> :func:`bank_signal` of the UKF and the EKF bank."""
    return {method: bank_signal(scenario, result, method) for method in ("ukf", "ekf")}


def run_scenario(scenario: Scenario, method: str | None = None, progress=None) -> SimResult:
    """The plant loop and both banks: a SimResult with signals ``ukf_bank`` and ``ekf_bank`` added."""
    started = time.perf_counter()
    result = simulate_plant(scenario, method or "fast", progress)
    banks = run_banks(scenario, result)
    signals_ = dict(result.signals, **{f"{m}_bank": sig for m, sig in banks.items()})
    meta = {**result.meta, "plant_wall_s": result.meta.get("wall_s"), "wall_s": time.perf_counter() - started}
    return SimResult(result.t, signals_, {**meta, "scenario": scenario.name, "banks": ["ukf", "ekf"]})
