"""What the runner (:func:`uvsym.sim.run.run_closed_loop`) needs of a sampled closed loop.

Both loop builders, the marine scenario loop (:mod:`uvsym.sim.closed_loop`) and loops wired by
signal name (:mod:`uvsym.sim.wiring`), return a subclass of :class:`SampledLoop`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import casadi as ca

__all__ = ["SampledLoop"]


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
