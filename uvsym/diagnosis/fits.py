"""Least-squares fits of actuator-fault hypotheses over one window (generalised likelihood ratios).

With the residual whitened by its noise level per channel, every statistic below is a sum of
squares in units of the noise variance: under a true hypothesis with white Gaussian noise, the
drop ``J_model - J_candidate`` of one added parameter is chi-square with one degree of freedom
(a generalised likelihood ratio, Basseville and Nikiforov 1993, ch. 4). The model's faults (already
decided) and the filter's free response (:class:`~uvsym.diagnosis.regressors.RegressorBank`) are
fitted jointly in every window.

Every vector involved is a combination of a few columns -- the free response, the residual and
each actuator's two filtered series -- so one Gram matrix of those columns gives every fit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from uvsym.diagnosis.regressors import RegressorBank
from uvsym.faults import ActuatorKind

__all__ = ["Hypothesis", "WindowFit", "fit_window"]


@dataclass(frozen=True)
class Hypothesis:
    """Actuator index a, fault kind, and the sample from which it acts (0: the whole record);
    ``at``: a size to linearise the vehicle's exact force model at (None: the first-order columns
    ``F[B_a]``, ``F[B_a v]``, linear in the size)."""

    actuator: int
    kind: ActuatorKind
    onset: int = 0
    at: float | None = None


@dataclass(frozen=True)
class WindowFit:
    """One window's verdicts. J_model: residual sum of squares with the model's faults fitted;
    theta_model: (len(model),) their sizes; cov_model: (len(model), len(model)) the sizes' covariance
    (the inverse information of the joint fit, in the sizes' units squared); removal: (len(model),) the
    rise of J when each is dropped; power: (len(model),) the J that each fault at ``values`` adds to a healthy record;
    glr, theta, info: (len(candidates),) ``J_model - J`` per added candidate, its size, and the
    information ``|P phi|^2`` (1 / variance of the size)."""

    J_model: float
    theta_model: np.ndarray
    cov_model: np.ndarray
    removal: np.ndarray
    power: np.ndarray
    glr: np.ndarray
    theta: np.ndarray
    info: np.ndarray


class _Columns:
    """The window's column matrix Z = [free response | residual | F[B_a], F[B_a v] per (a, onset)]."""

    def __init__(self, bank: RegressorBank, rows: np.ndarray, hypotheses: list[Hypothesis]):
        self.n_t = bank.n
        sigma = bank.sigma[rows]
        blocks = [bank.transient(rows), (bank.r[rows] / sigma).reshape(-1, 1)]
        self.index: dict[tuple, int] = {}
        for h in hypotheses:
            key = self._key(h, rows[0])
            if key not in self.index:
                self.index[key] = self.n_t + 1 + 2 * len(self.index)
                if h.at is None:
                    pair = (bank.gated(bank.G[:, h.actuator], rows, h.onset),
                            bank.gated(bank.H[:, h.actuator], rows, h.onset))
                else:
                    pair = bank.exact(rows, h.actuator, h.kind, h.at, h.onset)
                blocks += [(column / sigma).reshape(-1, 1) for column in pair]
        self.rows0 = rows[0]
        Z = np.hstack(blocks)
        self.S = Z.T @ Z
        self.size = Z.shape[1]

    @staticmethod
    def _key(h: Hypothesis, first: int) -> tuple:
        onset = h.onset if first < h.onset else 0
        return (h.actuator, onset) if h.at is None else (h.actuator, onset, h.kind.name, h.at)

    def combinations(self, hypotheses: list[Hypothesis]) -> tuple[np.ndarray, np.ndarray]:
        """Coefficients (C, Phi), each (size, len(hypotheses)), over Z: ``r = C[:, i] + f Phi[:, i]`` under
        hypothesis i (module docstring of regressors)."""
        C, Phi = np.zeros((self.size, len(hypotheses))), np.zeros((self.size, len(hypotheses)))
        for i, h in enumerate(hypotheses):
            j = self.index[self._key(h, self.rows0)]
            if h.at is not None:  # the exact columns are c and phi themselves
                C[j, i], Phi[j + 1, i] = 1.0, 1.0
                continue
            (g0, g1), (s0, s1) = h.kind.gain, h.kind.shift
            C[j, i], C[j + 1, i] = s0, g0 - 1.0
            Phi[j, i], Phi[j + 1, i] = s1, g1
        return C, Phi


def _schur(S: np.ndarray, basis: np.ndarray, W: np.ndarray, inverse: np.ndarray | None = None) -> np.ndarray:
    """Gram matrix of the combinations W (size, q) after projecting out the combinations ``basis``; inverse:
    the pseudo-inverse of ``basis' S basis`` where the caller has it (None: computed here)."""
    SB = S @ basis
    if inverse is None:
        inverse = _pinv(basis.T @ SB)
    return W.T @ S @ W - (W.T @ SB) @ inverse @ (SB.T @ W)


def _pinv(gram: np.ndarray) -> np.ndarray:
    """The pseudo-inverse of a symmetric Gram matrix (singular values below 1e-12 of the largest dropped).

    ``np.linalg.pinv(gram, rcond=1e-12, hermitian=True)`` bit for bit -- its eigendecomposition, order, cut-off
    and products, on arrays of the same layouts (BLAS may round a product of other layouts otherwise) --
    without its checks and wrapping (a third of its time on the diagnosis's small matrices)."""
    if gram.size == 0:
        return np.empty(gram.shape[::-1])
    s, u = np.linalg.eigh(gram)
    sign = np.copysign(1.0, s)
    s = np.abs(s)
    order = np.argsort(s)[::-1]  # the singular values, descending
    sign, s = sign[order], s[order]
    u = np.take_along_axis(u, order[None, :], axis=-1)  # C-ordered, as numpy's (u[:, order] is not)
    large = s > 1e-12 * s.max()
    s = np.divide(1, s, where=large, out=s)
    s[~large] = 0
    return np.matmul(u * sign, np.multiply(s[:, None], u.T))


def fit_window(bank: RegressorBank, rows: np.ndarray, model: list[Hypothesis], values: np.ndarray,
               candidates: list[Hypothesis]) -> WindowFit:
    """Fit the model's faults on ``rows`` and test each candidate added to them.

    values: (len(model),) the model faults' decided sizes (for ``power``).
    """
    Z = _Columns(bank, rows, model + candidates)
    C_model, Phi_model = Z.combinations(model)
    y, decided = np.zeros(Z.size), np.zeros(Z.size)
    y[Z.n_t] = 1.0
    for i in range(len(model)):
        decided = decided + C_model[:, i]
    y = y - decided  # the residual's column less the decided faults' own terms
    basis = np.hstack([np.eye(Z.size)[:, :Z.n_t], Phi_model])  # the free response and the model's faults
    SB = Z.S @ basis
    inverse = _pinv(basis.T @ SB)
    theta_model, cov_model = (inverse @ (SB.T @ y))[Z.n_t:], inverse[Z.n_t:, Z.n_t:]
    J_model = float(_schur(Z.S, basis, y[:, None], inverse)[0, 0])
    removal, power = np.zeros(len(model)), np.zeros(len(model))
    for i in range(len(model)):
        c, phi = C_model[:, i], Phi_model[:, i]
        others = np.delete(basis, Z.n_t + i, axis=1)
        gram = _schur(Z.S, others, np.column_stack([y + c, c + values[i] * phi]))
        removal[i], power[i] = gram[0, 0] - J_model, gram[1, 1]
    if not candidates:
        return WindowFit(J_model, theta_model, cov_model, removal, power, np.zeros(0), np.zeros(0), np.zeros(0))
    C, X = Z.combinations(candidates)
    gram = _schur(Z.S, basis, np.hstack([y[:, None] - C, X]), inverse)  # each candidate's target, its column
    H = len(candidates)
    uu, ux, xx = np.diagonal(gram[:H, :H]), np.diagonal(gram[:H, H:]), np.diagonal(gram[H:, H:])
    seen = xx > 1e-12 * max(float(np.max(xx)), 1e-300)
    theta = np.where(seen, ux / np.where(seen, xx, 1.0), np.nan)
    J = uu - np.where(seen, ux * np.nan_to_num(theta), 0.0)
    return WindowFit(J_model, theta_model, cov_model, removal, power, J_model - J, theta, np.where(seen, xx, 0.0))
