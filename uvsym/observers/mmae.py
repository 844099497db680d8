"""Multiple-model adaptive estimation: a bank of Gaussian filters, Bayesian model probabilities in
log space, federated fusion and reset, as one :class:`~uvsym.observers.base.Observer`.

Each model i is a :class:`~uvsym.observers.kalman.GaussianFilter` (UKF or EKF, of any state
size) reading the same measurements and inputs. At sample k every filter makes its measurement
update and its log-likelihood ``l_i = log f(y_k | theta_i, Y_{k-1})`` (the fault paper's eqs.
25-28, with the UKF's own ``P_zz`` as the innovation covariance of eq. 28), and its normalised
innovation squared ``nis_i = r_i^T S_i^-1 r_i = 2 (l_i(yhat_i) - l_i(y_k))`` (the likelihood at the
predicted measurement less the one at y_k: chi-square with n_y degrees of freedom while model i
is right). Bayes' rule in log space, with a floor::

    log p_i <- l_i + log p_i - logsumexp_j(l_j + log p_j)
    log p_i <- max(log p_i, log p_min), renormalised (logsumexp)

so that no model is locked out (a model at the floor can win back when its data return). The
fused estimate of the states every model has (the kinematic states) is ``sum_i p_i xhat_i``
(eq. 29); with ``reset`` every filter's posterior of those states is then set to the fused
estimate before its prediction (federated feedback), so that after a fault ends the no-fault
model starts each sample from the best estimate and wins back. A NaN measurement skips every
update and leaves the probabilities unchanged (``skipped`` = 1).

State: each filter's ``[xhat; tril(P)]`` prefixed ``<model>.``, then ``logp.<model>``. Publishes
the fused ``<x>_hat``, ``p_<model>``, each model's own states (e.g. ``left.alpha_T_L_hat``) and
their posterior standard deviations (``left.alpha_T_L_std``), ``loglik_<model>``, ``nis_<model>``
(0 where the update was skipped), ``pd_margin`` (smallest over the bank) and ``skipped``.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from uvsym.errors import ObserverError
from uvsym.observers.base import Observer, check_name, observer
from uvsym.observers.kalman import (
    GaussianFilter,
    covariance_signals,
    initial_filter_state,
    measurement_gate,
    packed,
    unpacked,
)
from uvsym.systems.signals import Signals

__all__ = ["mmae_bank", "log_normalised"]


def log_normalised(v):
    """``v - logsumexp(v)`` (SX column), computed from its largest entry."""
    top = v[0]
    for i in range(1, v.numel()):
        top = ca.fmax(top, v[i])
    return v - (top + ca.log(ca.sum1(ca.exp(v - top))))


def _check_bank(filters: dict[str, GaussianFilter]) -> tuple[str, ...]:
    """The state names every model has (in the first model's order); ObserverError otherwise."""
    if len(filters) < 2:
        raise ObserverError(f"an MMAE bank needs at least two models, got {len(filters)}")
    first = next(iter(filters.values()))
    for model, f in filters.items():
        check_name(model, "model")
        if not isinstance(f, GaussianFilter):
            raise ObserverError(f"model {model}: expected a GaussianFilter (unscented_filter, extended_filter), "
                                f"got {type(f).__name__}")
        for what in ("y", "u", "p"):
            if getattr(f.system, what).names != getattr(first.system, what).names:
                raise ObserverError(f"model {model} reads {what} = {getattr(f.system, what).names}, the first model "
                                    f"{getattr(first.system, what).names}; a bank's models read the same signals")
        if abs(f.dt - first.dt) > 1e-12 * first.dt:
            raise ObserverError(f"model {model} is sampled every {f.dt:g} s, the first model every {first.dt:g} s")
    shared = tuple(n for n in first.system.x.names if all(n in f.system.x.names for f in filters.values()))
    if not shared:
        raise ObserverError("the bank's models share no state to fuse")
    return shared


def mmae_bank(filters: dict[str, GaussianFilter], *, name: str = "mmae", p_min: float = 1e-3, prior=None,
              reset: bool = True) -> Observer:
    """The bank (module docstring) of ``filters`` (model name -> filter, at least two).

    p_min: probability floor in (0, 1 / number of models); prior: initial probabilities (default
    uniform), positive, normalised here; reset: federated reset of the shared states.
    """
    check_name(name, "observer")
    shared = _check_bank(filters)
    models = list(filters)
    count = len(models)
    if not (isinstance(p_min, (int, float)) and 0.0 < p_min < 1.0 / count):
        raise ObserverError(f"{name}: p_min must be in (0, 1/{count}), got {p_min!r}")
    wrong_prior = ObserverError(f"{name}: prior must be {count} positive probabilities ({', '.join(models)})")
    try:
        prior = np.full(count, 1.0 / count) if prior is None else np.asarray(prior, dtype=float).ravel()
    except (TypeError, ValueError):  # not numbers
        raise wrong_prior from None
    if prior.size != count or not np.all(np.isfinite(prior)) or np.any(prior <= 0):
        raise wrong_prior
    prior = prior / prior.sum()
    first = filters[models[0]].system
    sizes = [f.system.x.size for f in filters.values()]
    slots = np.cumsum([0] + [n + n * (n + 1) // 2 for n in sizes])
    picks = {m: filters[m].system.x.indices(shared) for m in models}
    floor = float(np.log(p_min))

    def step(s, y, u, p):
        posts, logliks, nis, margins, skipped = [], [], [], [], 0.0
        for m, n, start in zip(models, sizes, slots):
            x, P = s[start:start + n], unpacked(s[start + n:start + n + n * (n + 1) // 2], n)
            x_post, P_post, r, loglik, margin, skipped = measurement_gate(filters[m], x, P, y, u, p)
            at_prediction = measurement_gate(filters[m], x, P, y - r, u, p)[3]  # y - r: the predicted y
            posts.append((x_post, P_post))
            logliks.append(loglik)
            nis.append(2.0 * (at_prediction - loglik))
            margins.append(margin)
        logp = log_normalised(ca.fmax(log_normalised(s[slots[-1]:] + ca.vertcat(*logliks)), floor))
        probability = ca.exp(logp)
        fused = sum((probability[i] * posts[i][0][picks[m]] for i, m in enumerate(models)),
                    ca.SX.zeros(len(shared)))
        s_next, own = [], []
        for i, m in enumerate(models):
            x_post, P_post = posts[i]
            if reset:
                x_post = ca.vertcat(*[fused[picks[m].index(j)] if j in picks[m] else x_post[j]
                                      for j in range(x_post.numel())])
            x_next, P_next, margin = filters[m].predict(x_post, P_post, u, p)
            margins.append(margin)
            s_next += [x_next, packed(P_next)]
            mine = [j for j, n in enumerate(filters[m].system.x.names) if n not in shared]
            own += [posts[i][0][j] for j in mine] + [ca.sqrt(ca.fmax(P_post[j, j], 0.0)) for j in mine]
        margin = margins[0]
        for v in margins[1:]:
            margin = ca.fmin(margin, v)
        out = ca.vertcat(fused, probability, *own, *logliks, *nis, margin, skipped)
        return tuple(ca.cse([ca.vertcat(*s_next, logp), out]))  # shared subexpressions once

    state, own = Signals(group="state"), Signals(group="estimate")
    for m in models:
        x = filters[m].system.x
        state = state + (x.renamed(suffix="_hat") + covariance_signals(x)).renamed(prefix=f"{m}.")
        mine = x.select([n for n in x.names if n not in shared])
        own = own + mine.renamed(prefix=f"{m}.", suffix="_hat") + mine.renamed(prefix=f"{m}.", suffix="_std")
    state = state + Signals(tuple(f"logp.{m}" for m in models), ("-",) * count,
                            tuple(f"log probability of model {m}" for m in models), "state")
    publishes = (first.x.select(shared).renamed(suffix="_hat", group="estimate")
                 + Signals(tuple(f"p_{m}" for m in models), ("-",) * count,
                           tuple(f"probability of model {m}" for m in models), "probability")
                 + own + Signals(tuple(f"loglik_{m}" for m in models), ("-",) * count, (), "diagnostic")
                 + Signals(tuple(f"nis_{m}" for m in models), ("-",) * count,
                           tuple(f"normalised innovation squared of model {m}" for m in models), "diagnostic")
                 + Signals(("pd_margin", "skipped"), ("-", "-"),
                           ("smallest relative Cholesky pivot of the bank's step (> 0: P.D.)",
                            "1 where y_k had a NaN and the updates were skipped"), "diagnostic"))
    s0 = np.concatenate([initial_filter_state(filters[m]) for m in models] + [np.log(prior)])
    methods = sorted({f.method.upper() for f in filters.values()})
    return observer(name, step=step, dt=filters[models[0]].dt, p0=first.p0, params=first.p.renamed(group="parameter"),
                    state=state, reads_y=first.y.renamed(group="measurement"),
                    reads_u=first.u.renamed(group="input"), publishes=publishes, init=lambda y0, u0, p: s0,
                    description=f"MMAE bank of {'/'.join(methods)} models {', '.join(models)} (floor {p_min:g}, "
                                f"{'federated reset' if reset else 'no reset'}), sampled every "
                                f"{filters[models[0]].dt:g} s")
