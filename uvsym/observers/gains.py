"""Observer gain design for a requested convergence time constant, and Remark 2's observability.

The error of Liu et al. 2014's observers obeys ``e' = A e`` with (diagonal M)
``A = -K (M^-1 T_d)^2`` (proportional: rate ``k_i tau_d,i^2 / m_i^2``) or ``A = -K M^-2``
(bias, constant: rate ``k_i / m_i^2``). Useful gains therefore scale with ``m_i^2``; the paper
does not say so. In the momentum form ``A = -K T_d^2`` or ``-K`` for any M, and the design is
exact. For the paper's form with a coupled M the same rule is applied to the diagonal of the
matrix that multiplies K; the rates actually achieved (eigenvalues of -A) are returned beside K.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from uvsym.codegen.cache import memoized
from uvsym.errors import ObserverError
from uvsym.faults import actuator_kind
from uvsym.observers.actuator import ActuatorObserver

__all__ = ["GainDesign", "design_gains", "unobservable_channels", "MIN_TIME_CONSTANT", "MAX_TIME_CONSTANT"]

MIN_TIME_CONSTANT, MAX_TIME_CONSTANT = 1e-9, 1e9  # s: gains of 1e9 to 1e-9 per second at most


@dataclass(frozen=True)
class GainDesign:
    """K: (n,) gains; rates: (n,) achieved convergence rates (1/s, eigenvalues of -A, sorted);
    unobservable: channel indices where the error does not converge (tau_d,i = 0)."""

    K: np.ndarray
    rates: np.ndarray
    unobservable: tuple[int, ...]


def unobservable_channels(observer: ActuatorObserver, tau_d, threshold: float = 1e-6) -> tuple[int, ...]:
    """Channels where a proportional fault cannot be seen (Remark 2): ``|tau_d,i| <= threshold`` (N, N m).

    Always empty for observers of kinds that do not scale tau_d (bias, constant). ObserverError for a
    tau_d that is not (n,) finite numbers.
    """
    if not actuator_kind(observer.kind).scales:
        return ()
    tau_d = _desired_action(tau_d, observer.function.size1_in("x"))
    return tuple(int(i) for i in np.flatnonzero(np.abs(tau_d) <= threshold))


def _desired_action(tau_d, n: int) -> np.ndarray:
    """tau_d as (n,) finite floats (N, N m); ObserverError naming tau_d otherwise."""
    try:
        tau_d = np.asarray(tau_d, dtype=float).ravel()
    except (TypeError, ValueError):
        raise ObserverError(f"tau_d must be {n} numbers (N, N m), got {tau_d!r:.60}") from None
    if tau_d.size != n or not np.all(np.isfinite(tau_d)):
        raise ObserverError(f"tau_d must have {n} finite entries, got {tau_d.tolist()}")
    return tau_d


def design_gains(observer: ActuatorObserver, time_constant: float, tau_d=None) -> GainDesign:
    """Gains K giving each observable channel the convergence time constant ``time_constant`` (s).

    tau_d: (n,) nominal desired action, needed by the proportional observer (its rate scales with
    tau_d,i^2); unobservable channels (Remark 2) get the gain 1 and are listed, not divided by zero.

    Raises
    ------
    ObserverError
        For something other than an :class:`ActuatorObserver` (e.g. its ``.function``), a time
        constant that is not positive and finite, a tau_d of the wrong size or not finite, or a
        tau_d that leaves every channel unobservable (all zero for the proportional observer).
    """
    if not isinstance(observer, ActuatorObserver):
        raise ObserverError(f"design_gains takes the ActuatorObserver that actuator_observer() returns, got "
                            f"{type(observer).__name__} (pass the observer, not its .function)")
    if isinstance(time_constant, bool) or not isinstance(time_constant, (int, float, np.floating)) or \
            not time_constant > 0.0 or not np.isfinite(time_constant):
        raise ObserverError(f"time_constant must be positive and finite (s), got {time_constant!r}")
    if not MIN_TIME_CONSTANT <= time_constant <= MAX_TIME_CONSTANT:
        raise ObserverError(f"time_constant {time_constant!r} s is outside [{MIN_TIME_CONSTANT:g}, "
                            f"{MAX_TIME_CONSTANT:g}] s: gains ~ 1 / time_constant would be meaningless in doubles")
    n = observer.function.size1_in("x")
    if tau_d is None:
        if actuator_kind(observer.kind).scales:
            raise ObserverError(f"the {observer.kind} observer's rate depends on tau_d: pass the nominal tau_d")
        tau_d = np.ones(n)
    return _designed(observer, float(time_constant), tuple(_desired_action(tau_d, n).tolist()))


@memoized(64)
def _designed(observer: ActuatorObserver, time_constant: float, tau_d: tuple) -> GainDesign:
    """:func:`design_gains` for checked arguments (memoized in-process: a campaign's scenarios share it),
    its arrays read-only."""
    n = len(tau_d)
    tau_d = np.array(tau_d)
    unobservable = unobservable_channels(observer, tau_d)
    if len(unobservable) == n:
        raise ObserverError(f"tau_d = {tau_d.tolist()} is zero in every channel: the {observer.kind} observer sees "
                            "no fault in any of them (Remark 2: a fault scaling tau_d,i is invisible where tau_d,i "
                            "= 0); give the nominal desired action of the run")
    per_unit_gain = -np.diag(np.asarray(observer.error_matrix(tau_d, np.ones(n))))
    K = np.ones(n)
    for i in range(n):
        if i not in unobservable:
            K[i] = 1.0 / (time_constant * per_unit_gain[i])
    rates = np.sort(-np.linalg.eigvals(np.asarray(observer.error_matrix(tau_d, K))).real)
    K.setflags(write=False)
    rates.setflags(write=False)
    return GainDesign(K=K, rates=rates, unobservable=unobservable)
