"""What the runner (:func:`uvsym.sim.run.run_closed_loop`) needs of a sampled closed loop.

Both loop builders, the marine scenario loop (:mod:`uvsym.sim.closed_loop`) and loops wired by
signal name (:mod:`uvsym.sim.wiring`), return a subclass of :class:`SampledLoop`, and share the
helpers below: the logged-signal layout, the per-sample input table W and the faults' meta.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from uvsym.errors import SimulationError

__all__ = ["SampledLoop", "disturbance_draws", "fault_summary", "logged_signals", "per_sample", "sample_inputs",
           "varying_rows"]


@dataclass(frozen=True, kw_only=True)
class SampledLoop:
    """A loop sampled every ``dt`` s. State ``z = [s; z_disc]`` (s the integrated plant part, n_s
    entries), per-sample input ``w`` (n_w columns, ``w[0]`` the time).

    discrete(z, w) -> (z_disc, u_cmd, out): the discrete part's next state, the plant inputs held
    over the sample, the logged signals (``signals``: name -> (slice of out, labels, units));
    plant_ode(s, u_cmd, env, t) -> s_dot (None for a discrete-time plant: fast path only);
    step(z, w) -> (z_next, out) the fixed-step path
    (``substeps`` RK4 steps of the plant per sample); layout: part of z -> slice. env_columns:
    where w holds the plant's environment; correction_columns: (vec(S), o) of a command
    correction, or None; substitution_columns: measurement channel -> its switch column.
    fault_ode(s, u_cmd, env, d, b) -> s_dot with the actuators delivering ``a + d a + b`` (d, b (m,)), for a
    loop whose w holds its actuator faults as such (D, B) stage columns, and ``actuator_faults`` the faults
    its plant_ode holds; None for a loop whose plant_ode reads its faults from w.
    """

    dt: float
    substeps: int
    n_z: int
    n_w: int
    n_s: int
    discrete: ca.Function
    plant_ode: ca.Function | None
    step: ca.Function
    layout: dict
    signals: dict
    env_columns: slice
    correction_columns: slice | None = None
    substitution_columns: dict = field(default_factory=dict)
    fault_ode: ca.Function | None = None
    actuator_faults: tuple | None = None

    def integrated(self, out: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """(s (k, n_s), u_cmd (k, m)): the integrated plant state and the held plant inputs at the samples
        of logged rows ``out`` (k, n_out), read back from what the loop logs (each loop says how); None
        for a loop that does not say (its fast path's step error is then not checked)."""
        return None

    def held_inputs(self, out: np.ndarray) -> np.ndarray:
        """u_cmd (k, m) of :meth:`integrated` alone (a loop may read it back without the state)."""
        return self.integrated(out)[1]

    def logged(self, out: np.ndarray, name: str) -> np.ndarray:
        """The columns of the logged signal ``name`` in logged rows ``out`` (k, n_out)."""
        return out[:, self.signals[name][0]]


def logged_signals(parts: dict[str, tuple]) -> tuple[ca.SX, dict]:
    """(out, name -> (slice of out, labels, units)) from name -> (expression, labels, units), in order."""
    signals, offset = {}, 0
    for name, (expr, labels, units) in parts.items():
        signals[name] = (slice(offset, offset + expr.numel()), tuple(labels), tuple(units))
        offset += expr.numel()
    return ca.vertcat(*[expr for expr, _, _ in parts.values()]), signals


def per_sample(values, size: int, N: int, what: str) -> np.ndarray:
    """(N + 1, size) rows from a constant (size,) or one row per sample; SimulationError otherwise."""
    table = np.asarray(values, dtype=float)
    if table.shape not in ((size,), (N + 1, size)) or not np.all(np.isfinite(table)):
        raise SimulationError(f"{what} must be {size} finite values, or one such row per sample ({N + 1}), "
                              f"got shape {table.shape}")
    return np.broadcast_to(table, (N + 1, size))


def sample_inputs(n_w: int, N: int, dt: float, n_noise: int, seed: int) -> np.ndarray:
    """W (N + 1, n_w): column 0 the sample times k dt (s), columns 1..n_noise standard normal draws
    (seeded) behind sensor noise faults, the rest 0 for the caller to fill."""
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise SimulationError(f"seed must be an integer >= 0 (it seeds the noise draws), got {seed!r}")
    W = np.zeros((N + 1, n_w))
    W[:, 0] = dt * np.arange(N + 1)
    W[:, 1:1 + n_noise] = np.random.default_rng(seed).standard_normal((N + 1, n_noise))
    return W


def varying_rows(N: int, dt: float, n_noise: int, seed: int, blocks=()) -> np.ndarray:
    """A run's varying input columns (N + 1, 1 + n_noise + the blocks' widths): :func:`sample_inputs`' times and
    seeded draws, then each block (N + 1, k) of ``blocks`` in order, written in place (no stacked copy)."""
    rows = sample_inputs(1 + n_noise + sum(block.shape[1] for block in blocks), N, dt, n_noise, seed)
    first = 1 + n_noise
    for block in blocks:
        rows[:, first:first + block.shape[1]] = block
        first += block.shape[1]
    return rows


def disturbance_draws(N: int, n_d: int, seed: int) -> np.ndarray:
    """(N + 1, n_d) standard normal draws behind white disturbances, one row per sample, from the
    stream ``(seed, 1)``: independent of the sensor noise draws of :func:`sample_inputs` (stream ``seed``)."""
    return np.random.default_rng((seed, 1)).standard_normal((N + 1, n_d))


def fault_summary(fault, target: str) -> dict:
    """JSON-friendly fault for a result's meta: target, kind, value, profile, onset and end (s; None: never)."""
    profile = fault.profile
    return {"target": target, "kind": fault.kind, "value": fault.value, "profile": profile.kind,
            "onset_s": profile.onset, "end_s": None if profile.end == float("inf") else profile.end}
