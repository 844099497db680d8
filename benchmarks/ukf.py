"""Cost of one UKF step and of the whole MMAE bank in generated C, against filterpy on the same
model and data.

Run ``python benchmarks/ukf.py`` (needs the ``bench`` extra's filterpy); writes
``benchmarks/results/ukf.json``. ``ukf_step_ns``: one step (update and prediction) of the 7-state
UKF of the left-thruster model; ``bank_step_ns``: the UKF bank's step (three UKFs of 6, 7 and 7
states, log-space probabilities, fusion, reset). Both from the derivation's C packages, timed in
a C loop (best of five batches). filterpy: ``UnscentedKalmanFilter`` with Merwe's scaled sigma
points (same alpha, beta, kappa, Q, R, P0) on a numpy RK4 of the same Otter model (checked
against uvsym's), run on the first ``SAMPLES`` samples of the derivation's scenario; its bank is
three such filters in the same MMAE loop written in numpy (filterpy's ``MMAEFilterBank`` needs
equal state sizes and multiplies probabilities without a floor, so it is not the same method).
The C figures are CPU time per call (``wall_*`` beside them), filterpy's are the CPU time of its
loop (``time.process_time``); compare as ratios within one run: the machine is shared.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import casadi as ca
import numpy as np
from filterpy.kalman import MerweScaledSigmaPoints, UnscentedKalmanFilter
from scipy.special import logsumexp

sys.path.insert(0, str(Path(__file__).resolve().parent))

import c_timing  # noqa: E402
from c_timing import c_loop_ns  # noqa: E402
from common import finish  # noqa: E402

import uvsym  # noqa: E402
from derivations.usv_fukf_mmae.experiment import disturbed_plant, run  # noqa: E402
from derivations.usv_fukf_mmae.observer_sets import shipped_bank  # noqa: E402
from derivations.usv_fukf_mmae.scenario import block_table, parsed, read  # noqa: E402
from uvsym.codegen import find_compiler  # noqa: E402
from uvsym.codegen.estimators import exported_observer  # noqa: E402
from uvsym.codegen.observer_sets import ObserverSet  # noqa: E402
from uvsym.observers.kalman import filter_observer, run_filter, transition  # noqa: E402
from uvsym.observers.mmae_design import bank_filters  # noqa: E402
from uvsym.sim.fields import Fields  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results" / "ukf.json"
SAMPLES = 1000  # samples filterpy runs (it is slow); uvsym's C is timed per call


def numpy_model():
    """``fx(x, dt, u, which)``: RK4 over dt of the 3-DOF Otter with efficiency state ``which``
    (None, 0 for T_L, 1 for T_R), in numpy; checked against uvsym's model."""
    model = uvsym.vehicle("otter3dof")
    m11, m22, m33 = np.diag(model.M)
    d11, d22, d33 = (float(model.h(np.zeros(3), np.eye(3)[i])[i]) for i in range(3))
    half, lo, hi = model.parameters.v("y_pont"), model.u_min[0], model.u_max[0]

    def f(x, thrust):
        _, _, psi, u, v, r = x[:6]
        T_L, T_R = np.clip(thrust, lo, hi)
        c, s = np.cos(psi), np.sin(psi)
        return np.array([c * u - s * v, s * u + c * v, r,
                         (m22 * v * r - d11 * u + T_L + T_R) / m11, (-m11 * u * r - d22 * v) / m22,
                         ((m11 - m22) * u * v - d33 * r + (T_L - T_R) * half) / m33])

    def fx(x, dt, u, which):
        thrust = np.array(u, dtype=float)
        if which is not None:
            thrust[which] *= x[6]
        k1 = f(x, thrust)
        k2 = f(x[:6] + dt / 2 * k1, thrust)
        k3 = f(x[:6] + dt / 2 * k2, thrust)
        k4 = f(x[:6] + dt * k3, thrust)
        return np.concatenate([x[:6] + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4), x[6:]])

    point, thrust = np.array([3.0, -2.0, 0.4, 1.3, 0.2, -0.1]), np.array([70.0, 40.0])
    plant = uvsym.plant("otter3dof")
    xs, us = ca.SX.sym("x", 6), ca.SX.sym("u", 2)
    F = ca.Function("F", [xs, us], [transition(plant, 0.05)(xs, us, ca.DM.zeros(2))])
    assert np.allclose(fx(point, 0.05, thrust, None), np.asarray(F(point, thrust)).ravel(), rtol=1e-12, atol=1e-12)
    return fx


def shipped_filters(tuning: dict, dt: float) -> dict:
    """model -> the shipped UKF bank's filter (``tuning``: the scenario's ukf block)."""
    return bank_filters(Fields(tuning, "ukf"), disturbed_plant(), dt)


def filterpy_filters(tuning: dict, dt: float, fx) -> dict:
    """model -> filterpy UKF with the shipped UKF bank's tuning."""
    built = {}
    for name, filt in shipped_filters(tuning, dt).items():
        n = filt.x0.size
        inputs = tuning["models"][name]
        which = None if not inputs else ("T_L", "T_R").index(inputs[0])
        points = MerweScaledSigmaPoints(n, alpha=tuning["alpha"], beta=tuning["beta"], kappa=tuning["kappa"])
        ukf = UnscentedKalmanFilter(n, 6, dt, hx=lambda x: x[:6], fx=fx, points=points)
        ukf.x, ukf.P, ukf.Q, ukf.R = filt.x0.copy(), filt.P0.copy(), filt.Q.copy(), filt.R.copy()
        built[name] = (ukf, which)
    return built


def filterpy_ukf_us(tuning: dict, dt: float, fx, Y, U) -> float:
    """filterpy's left-model UKF, update then predict per sample: microseconds per sample."""
    ukf, which = filterpy_filters(tuning, dt, fx)["left"]
    started = time.process_time()
    for y, u in zip(Y, U):
        ukf.update(y)
        ukf.predict(u=u, which=which)
    return (time.process_time() - started) / len(Y) * 1e6


def filterpy_bank_us(tuning: dict, dt: float, fx, Y, U) -> tuple[float, np.ndarray]:
    """Three filterpy UKFs in the MMAE loop (log-space Bayes with the floor, fusion, reset): us per sample."""
    bank = filterpy_filters(tuning, dt, fx)
    logp = np.log(np.asarray(tuning["prior"]))
    floor = np.log(tuning["floor"])
    probabilities = []
    started = time.process_time()
    for y, u in zip(Y, U):
        for ukf, _ in bank.values():
            ukf.update(y)
        logp = logp + np.array([ukf.log_likelihood for ukf, _ in bank.values()])
        logp = np.maximum(logp - logsumexp(logp), floor)
        logp -= logsumexp(logp)
        p = np.exp(logp)
        fused = sum(pi * ukf.x[:6] for pi, (ukf, _) in zip(p, bank.values()))
        for ukf, which in bank.values():
            ukf.x[:6] = fused
            ukf.predict(u=u, which=which)
        probabilities.append(p)
    return (time.process_time() - started) / len(Y) * 1e6, np.array(probabilities)


def c_step_ns(observer, y, u) -> dict:
    """ns per call of the observer's step from its generated C package: ``cpu`` (the process's
    CPU time, CLOCK_PROCESS_CPUTIME_ID: what the step costs on a shared machine) and ``wall``
    (CLOCK_MONOTONIC, also counting the time other processes hold the core)."""
    name = f"bench_{observer.name}"
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        ObserverSet(name, observer.description, (exported_observer(observer),)).write(folder)
        s0 = observer.initial_state(y, u)
        n_s, n_out, n_p = observer.state.size, observer.publishes.size, max(1, observer.params.size)
        values = ", ".join(f"{v:.17g}" for v in s0)
        setup = f"""
  static {name}_real s[{n_s}] = {{{values}}}, s_next[{n_s}], out[{n_out}], p[{n_p}] = {{0}};  /* still water */
  static {name}_real y[6] = {{{", ".join(f"{v:.17g}" for v in y)}}}, u[2] = {{{u[0]:.17g}, {u[1]:.17g}}};"""
        wall_template = c_timing.TEMPLATE
        timings = {}
        try:
            for clock, template in (("wall", wall_template),
                                    ("cpu", wall_template.replace("CLOCK_MONOTONIC", "CLOCK_PROCESS_CPUTIME_ID"))):
                c_timing.TEMPLATE = template
                timings[clock] = c_loop_ns([folder / "src" / f"{name}_casadi.c", folder / "src" / f"{name}.c"],
                                           folder / "include", f"{name}.h", setup,
                                           f"{name}_{observer.name}_step(s, y, u, p, s_next, out)", "y[0]",
                                           float(y[0]), "out[0]", calls=200_000)
        finally:
            c_timing.TEMPLATE = wall_template
        return timings


def main() -> dict:
    table = read()
    tuning, dt = block_table(table, "ukf"), table["step"]
    result = run(parsed(table))
    Y, U = result["y"].values, result["guidance"].values[:, :2]  # T_L, T_R
    fx = numpy_model()
    left = filter_observer(shipped_filters(tuning, dt)["left"], "left-thruster UKF")
    ukf_bank = shipped_bank("ukf")
    ukf_ns = c_step_ns(left, Y[0], U[0])
    bank_ns = c_step_ns(ukf_bank, Y[0], U[0])
    started = time.process_time()
    _, OUT = run_filter(ukf_bank, Y[:SAMPLES], U[:SAMPLES])
    vm_us = (time.process_time() - started) / SAMPLES * 1e6
    fp_ukf_us = filterpy_ukf_us(tuning, dt, fx, Y[:SAMPLES], U[:SAMPLES])
    fp_bank_us, fp_p = filterpy_bank_us(tuning, dt, fx, Y[:SAMPLES], U[:SAMPLES])
    uvsym_p = OUT[:, [ukf_bank.publishes.index(f"p_{m}") for m in tuning["models"]]]
    return {"ukf_step_ns": ukf_ns["cpu"], "bank_step_ns": bank_ns["cpu"],
            "speedup_vs_filterpy_ukf": fp_ukf_us * 1e3 / ukf_ns["cpu"],
            "speedup_vs_filterpy_mmae": fp_bank_us * 1e3 / bank_ns["cpu"],
            "wall_ukf_step_ns": ukf_ns["wall"], "wall_bank_step_ns": bank_ns["wall"],
            "filterpy_ukf_step_us": fp_ukf_us, "filterpy_bank_step_us": fp_bank_us,
            "casadi_vm_bank_step_us": vm_us, "samples_filterpy": SAMPLES,
            "max_probability_difference_vs_filterpy": float(np.max(np.abs(uvsym_p - fp_p))),
            "sx_instructions": {"ukf_step": left.step.n_instructions(), "bank_step": ukf_bank.step.n_instructions()}}


if __name__ == "__main__":
    if find_compiler() is None:
        sys.exit("no C compiler: nothing to measure")
    finish(main(), {"ukf_step_ns_max": 3000, "bank_step_ns_max": 10000, "speedup_vs_filterpy_ukf_min": 100,
                    "speedup_vs_filterpy_mmae_min": 100}, RESULTS)
