"""Actuator configurations built from geometry, and their identifiability (Liu et al. 2014, sec. 2.3).

``tau = B u`` with B (6 x m). Two of the paper's three classes are built here from geometry;
the first (thruster plus fins) comes from a vehicle model as ``B = d tau / d u``.

- fixed-direction thrusters: k horizontal at angles alpha_i (thrust along (cos a, sin a, 0)),
  m - k vertical (thrust along +z), each column ``(e_i, r_i x e_i)``;
- vectored thrusters: thrust direction ``e = (sin th_ez cos th_ex, sin th_ez sin th_ex, cos th_ez)``;
  each controllable angle adds an input (the force component along d e / d angle), so a thruster
  with both angles free contributes three columns.

Actuator i is identifiable from tau exactly when no combination of the other columns can
stand in for it: when every vector of the null space of B has a zero i-th entry. This rank test
holds for any geometry; the paper's counting rules (at most 3 horizontal and 3 vertical fixed
thrusters) are its special case for horizontal thrusters in the plane z = 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from uvsym.errors import ConfigurationError
from uvsym.kinematics import Smtrx

__all__ = ["ActuatorConfiguration", "Identifiability", "fixed_thrusters", "vectored_thrusters", "identifiability"]

# Singular values below RANK_TOL * largest are treated as zero.
RANK_TOL = 1e-10


@dataclass(frozen=True)
class ActuatorConfiguration:
    """B (6 x m, columns in N or N m per unit input), input labels and input groups by plane."""

    name: str
    B: np.ndarray
    labels: tuple[str, ...]
    groups: tuple[tuple[str, tuple[int, ...]], ...]


@dataclass(frozen=True)
class Identifiability:
    """Rank of B, whether each input can be recovered from tau = B u, and why not where not."""

    rank: int
    n_inputs: int
    identifiable: tuple[bool, ...]
    reasons: tuple[str, ...]

    @property
    def all_identifiable(self) -> bool:
        """True when B has full column rank: u = B^+ tau recovers every input."""
        return all(self.identifiable)


def _column(direction, position) -> np.ndarray:
    """(e, r x e) for a unit thrust along ``direction`` applied at ``position`` (m)."""
    e = np.asarray(direction, dtype=float)
    return np.r_[e, Smtrx(np.asarray(position, dtype=float)) @ e]


def _positions(name: str, positions, count: int) -> np.ndarray:
    array = np.asarray(positions, dtype=float).reshape(-1, 3) if np.size(positions) else np.zeros((0, 3))
    if array.shape[0] != count or not np.all(np.isfinite(array)):
        raise ConfigurationError(f"{name}: need {count} finite positions (x, y, z) in m, got {np.shape(positions)}")
    return array


def fixed_thrusters(alpha, horizontal_positions, vertical_positions) -> ActuatorConfiguration:
    """Fixed-direction thrusters (paper's class 2).

    Parameters
    ----------
    alpha : (k,) array
        Horizontal thrust angles from the x axis (rad).
    horizontal_positions : (k, 3) array
        Positions of the horizontal thrusters from the CO (m).
    vertical_positions : (m - k, 3) array
        Positions of the vertical thrusters (m).
    """
    alpha = np.atleast_1d(np.asarray(alpha, dtype=float))
    if not np.all(np.isfinite(alpha)):
        raise ConfigurationError("fixed_thrusters: angles alpha must be finite (rad)")
    k = alpha.size
    r_h = _positions("fixed_thrusters horizontal", horizontal_positions, k)
    n_v = np.asarray(vertical_positions, dtype=float).reshape(-1, 3).shape[0] if np.size(vertical_positions) else 0
    r_v = _positions("fixed_thrusters vertical", vertical_positions, n_v)
    columns = [_column((np.cos(a), np.sin(a), 0.0), r) for a, r in zip(alpha, r_h)]
    columns += [_column((0.0, 0.0, 1.0), r) for r in r_v]
    if not columns:
        raise ConfigurationError("fixed_thrusters: no thrusters given")
    labels = tuple(f"T_h{i + 1}" for i in range(k)) + tuple(f"T_v{j + 1}" for j in range(n_v))
    groups = (("horizontal", tuple(range(k))), ("vertical", tuple(range(k, k + n_v))))
    return ActuatorConfiguration("fixed thrusters", np.column_stack(columns), labels, groups)


def vectored_thrusters(theta_ex, theta_ez, positions, free_angles) -> ActuatorConfiguration:
    """Vectored (azimuth) thrusters (paper's class 3), linearised at the given angles.

    Parameters
    ----------
    theta_ex : (n,) array
        Current azimuth of each thrust vector, from x in the horizontal plane (rad).
    theta_ez : (n,) array
        Current tilt of each thrust vector, from z (rad).
    positions : (n, 3) array
        Thruster positions from the CO (m).
    free_angles : (n,) sequence of str
        Each one of "none", "ex", "ez", "both": which angles are controllable.
    """
    ex = np.atleast_1d(np.asarray(theta_ex, dtype=float))
    ez = np.atleast_1d(np.asarray(theta_ez, dtype=float))
    n = ex.size
    if ez.size != n or len(free_angles) != n:
        raise ConfigurationError(f"vectored_thrusters: theta_ex, theta_ez and free_angles need {n} entries each")
    r = _positions("vectored_thrusters", positions, n)
    columns, labels = [], []
    for i in range(n):
        choice = free_angles[i]
        if choice not in ("none", "ex", "ez", "both"):
            raise ConfigurationError(f"vectored_thrusters: free_angles[{i}] = {choice!r}; "
                                     "use 'none', 'ex', 'ez' or 'both'")
        e = (np.sin(ez[i]) * np.cos(ex[i]), np.sin(ez[i]) * np.sin(ex[i]), np.cos(ez[i]))
        de_dex = (-np.sin(ez[i]) * np.sin(ex[i]), np.sin(ez[i]) * np.cos(ex[i]), 0.0)
        de_dez = (np.cos(ez[i]) * np.cos(ex[i]), np.cos(ez[i]) * np.sin(ex[i]), -np.sin(ez[i]))
        columns.append(_column(e, r[i]))
        labels.append(f"T{i + 1}")
        if choice in ("ex", "both"):
            columns.append(_column(de_dex, r[i]))
            labels.append(f"T{i + 1}_ex")
        if choice in ("ez", "both"):
            columns.append(_column(de_dez, r[i]))
            labels.append(f"T{i + 1}_ez")
    return ActuatorConfiguration("vectored thrusters", np.column_stack(columns), tuple(labels),
                                 (("all", tuple(range(len(labels)))),))


def identifiability(config: ActuatorConfiguration) -> Identifiability:
    """Which inputs ``u = B^+ tau`` recovers uniquely, with a reason for each one it cannot.

    Input i is identifiable iff every null-space vector of B has a zero i-th entry. Reasons
    name the inputs it can be traded against and, per group, the paper's count rule (at most
    3 horizontal and 3 vertical fixed thrusters; at most 6 controllable inputs in all).
    """
    B = np.asarray(config.B, dtype=float)
    if B.ndim != 2 or not 1 <= B.shape[0] <= 6 or not np.all(np.isfinite(B)):
        raise ConfigurationError(f"{config.name}: B must be a finite k x m matrix with 1 <= k <= 6 "
                                 f"force rows, got shape {B.shape}")
    m = B.shape[1]
    s = np.linalg.svd(B, compute_uv=False)
    rank = int(np.sum(s > RANK_TOL * max(s[0], 1e-300)))
    import scipy.linalg  # here: importing it costs every uvsym command about 0.14 s

    null = scipy.linalg.null_space(B, rcond=RANK_TOL)
    identifiable, reasons = [], []
    for i in range(m):
        weight = np.abs(null[i, :]) if null.size else np.zeros(0)
        if weight.size == 0 or np.max(weight) <= 1e-9:
            identifiable.append(True)
            reasons.append("")
            continue
        partners = sorted({config.labels[j] for j in range(m) if j != i
                           and np.max(np.abs(null[j, :]) * (np.abs(null[i, :]) > 1e-9)) > 1e-9})
        count_rule = _count_rule(config, i)
        identifiable.append(False)
        reasons.append(f"{config.labels[i]} can be traded against {', '.join(partners)} without changing tau "
                       f"(rank {rank} < {m} inputs){count_rule}")
    return Identifiability(rank, m, tuple(identifiable), tuple(reasons))


def _count_rule(config: ActuatorConfiguration, i: int) -> str:
    """The paper's counting rule that input i's group violates, as a sentence fragment."""
    for group, members in config.groups:
        if i in members:
            limit = 6 if group == "all" else 3
            if len(members) > limit:
                return f"; {len(members)} {group} inputs for {limit} equations"
    return ""
