"""Block LMIs of observers with one gain per block (Yu, Jiang & Zhang 2018, Theorems 1-2, eqs. 11, 22),
solved by cvxpy + Clarabel and decided without trusting the solver.

The error ``e = (e_1, ..., e_k)`` (block i of size n_i) obeys ``e' = (Omega - blkdiag(K_i C_i)) e``:
Omega (n, n) the coupled error matrix, C_i (p_i, n_i) what block i measures, K_i (n_i, p_i) its gain.
With ``V = sum_i e_i^T P_i e_i`` and ``Y_i = P_i K_i`` the decay ``V' <= -2 alpha V`` is the LMI

    P_i > 0,   He(P Omega - blkdiag(Y_i C_i)) + 2 alpha P < 0,   P = blkdiag(P_i),  He(X) = X + X^T

(the paper's Phi blocks; one block of size n is the usual observer LMI). Outcomes:

- **proved**: the solver's P, K -- rounded to ``GAIN_DIGITS`` significant digits where they still
  pass, so that gains and margins repeat across machines (:func:`~uvsym.verify.synthesis.rounded_gain`)
  -- are taken as rationals and ``P_i > 0``, ``-(He(P A_cl) + 2 alpha P) > 0`` for
  ``A_cl = Omega - blkdiag(K_i C_i)`` are shown by exact LDL^T; the gains are returned.
- **refuted**: a dual certificate ``Z = Z^T >= 0``, ``Z != 0`` with ``C_i Z_ii = 0`` and every
  diagonal block ``S_i = [Omega Z + Z Omega^T + 2 alpha Z]_ii >= 0``, all checked in exact
  rationals. It excludes every P, Y: else ``Q = He(P Omega - Y C) + 2 alpha P < 0`` would give
  ``0 > tr(Q Z) = sum_i tr(P_i S_i) - 2 sum_i tr(Y_i C_i Z_ii) >= 0``. Candidates come from the
  blocks' modes that no K_i moves (``C_i v = 0``, ``Omega_ii v = lambda v``, ``Re lambda >= -alpha``:
  ``Z_ii = Re(v v^H)``, reported as the eigenvalue evidence) and from the dual SDP.
- **inconclusive** otherwise.

The problem data are taken exactly as given (doubles are exact rationals); pass Fraction matrices
for data derived exactly (e.g. a decoupling computed in rationals).
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass
from fractions import Fraction

import cvxpy as cp
import numpy as np
import scipy.linalg
import sympy

from uvsym.errors import VerificationError as LMIError
from uvsym.verify.certificate import Certificate
from uvsym.verify.lyapunov import exact_positive_definite
from uvsym.verify.synthesis import DESIGN_MARGIN, rounded_gain

__all__ = ["BlockGains", "BlockLMI", "block_lmi", "block_lmi_claim", "dual_certificate",
           "exact_positive_semidefinite", "solve_block_lmi"]

Matrix = list[list[Fraction]]
DENOMINATORS = (10**3, 10**6, 10**9)  # rational roundings tried for a dual certificate
CHECK = "Z >= 0, C_i Z_ii = 0, [Omega Z + Z Omega^T + 2 alpha Z]_ii >= 0 in exact rationals"


@dataclass(frozen=True)
class BlockLMI:
    """The LMI of the module docstring: omega (n, n) and outputs C_i (p_i, n_i) exact; decay alpha (1/s)."""

    names: tuple[str, ...]
    omega: tuple[tuple[Fraction, ...], ...]
    outputs: tuple[tuple[tuple[Fraction, ...], ...], ...]
    sizes: tuple[int, ...]
    decay: Fraction

    @property
    def starts(self) -> list[int]:
        """First row of each block."""
        return [sum(self.sizes[:i]) for i in range(len(self.sizes))]

    def float_omega(self) -> np.ndarray:
        """Omega (n, n) as doubles (for the solver; the checks use the exact entries)."""
        return np.array([[float(v) for v in row] for row in self.omega])

    def float_output(self, i: int) -> np.ndarray:
        """C_i (p_i, n_i) as doubles."""
        return np.array([[float(v) for v in row] for row in self.outputs[i]]).reshape(-1, self.sizes[i])


@dataclass(frozen=True)
class BlockGains:
    """K_i (n_i, p_i) and P_i (n_i, n_i) per block, the certificate of their exact re-check."""

    K: tuple[np.ndarray, ...]
    P: tuple[np.ndarray, ...]
    certificate: Certificate


def _exact(value, what: str) -> Matrix:
    """A 2-D matrix of Fractions (doubles converted exactly); LMIError naming ``what`` otherwise."""
    if isinstance(value, (list, tuple)) and value and all(isinstance(r, (list, tuple)) for r in value) and \
            all(isinstance(v, (Fraction, int)) for r in value for v in r):
        rows = [[Fraction(v) for v in r] for r in value]
        if len({len(r) for r in rows}) > 1:
            raise LMIError(f"{what}: rows of different lengths")
        return rows
    if isinstance(value, sympy.MatrixBase):
        if not all(v.is_Rational for v in value):
            raise LMIError(f"{what}: a sympy matrix must hold rationals only")
        return [[Fraction(int(v.p), int(v.q)) for v in row] for row in value.tolist()]
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise LMIError(f"{what} must be a numeric matrix, got {type(value).__name__}") from None
    if array.ndim != 2:
        raise LMIError(f"{what} must be a 2-D matrix, got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        raise LMIError(f"{what} must be finite (no NaN or infinity)")
    return [[Fraction(float(v)) for v in row] for row in array]


def block_lmi(omega, blocks, decay: float = 0.0) -> BlockLMI:
    """The block LMI for ``omega`` (n, n) with ``blocks`` = [(name, C_i (p_i, n_i)), ...] in the order of
    e's blocks (``sum n_i = n``; a C_i with no rows: no injection) and rate ``decay`` (1/s, >= 0).

    Raises LMIError naming the block or argument for mismatched sizes, non-finite entries, repeated
    names or a negative decay."""
    names = [name for name, _ in blocks]
    if not names or len(set(names)) != len(names) or not all(isinstance(n, str) and n for n in names):
        raise LMIError(f"blocks need distinct non-empty names, got {names}")
    outputs = []
    for name, C in blocks:
        if isinstance(C, np.ndarray) and C.ndim == 2 and C.shape[0] == 0:
            raise LMIError(f"block {name!r}: a C with no rows cannot tell its size; give a zero row (no injection)")
        outputs.append(_exact(C, f"block {name!r}: output matrix C"))
    sizes = [len(C[0]) if C and C[0] else 0 for C in outputs]
    if any(s == 0 for s in sizes):
        raise LMIError(f"blocks {[n for n, s in zip(names, sizes) if s == 0]} have no columns (their size)")
    Om = _exact(omega, "Omega")
    n = sum(sizes)
    if len(Om) != n or any(len(r) != n for r in Om):
        raise LMIError(f"Omega must be ({n}, {n}) for blocks {dict(zip(names, sizes))}, got "
                       f"({len(Om)}, {len(Om[0]) if Om else 0})")
    try:
        alpha = Fraction(float(decay))
    except (TypeError, ValueError, OverflowError):
        raise LMIError(f"decay must be a finite number (1/s), got {decay!r}") from None
    if alpha < 0:
        raise LMIError(f"decay must be >= 0 (1/s), got {decay}")
    return BlockLMI(tuple(names), tuple(tuple(r) for r in Om), tuple(tuple(tuple(r) for r in C) for C in outputs),
                    tuple(sizes), alpha)


def exact_positive_semidefinite(matrix: Matrix) -> bool:
    """Whether a symmetric rational matrix is positive semidefinite, exactly: symmetric elimination
    on a positive pivot (its Schur complement is PSD iff the matrix is); with no positive diagonal
    entry left the rest must be zero."""
    a = [list(r) for r in matrix]
    if any(a[i][j] != a[j][i] for i in range(len(a)) for j in range(i)):
        return False
    while a:
        k = next((i for i in range(len(a)) if a[i][i] > 0), None)
        if k is None:
            return all(v == 0 for r in a for v in r)
        pivot, row = a[k][k], a[k]
        a = [[a[i][j] - a[i][k] * row[j] / pivot for j in range(len(a)) if j != k] for i in range(len(a)) if i != k]
    return True


def _blkdiag_products(problem: BlockLMI, Z: Matrix) -> tuple[list[Matrix], list[Matrix]]:
    """(C_i Z_ii, S_i = [Omega Z + Z Omega^T + 2 alpha Z]_ii) per block, exactly."""
    Om, n = problem.omega, len(problem.omega)
    CZ, S = [], []
    for i, (start, size) in enumerate(zip(problem.starts, problem.sizes)):
        idx = range(start, start + size)
        OZ = [[sum(Om[r][k] * Z[k][c] for k in range(n) if Z[k][c]) for c in idx] for r in idx]
        S.append([[OZ[a][b] + OZ[b][a] + 2 * problem.decay * Z[r][c] for b, c in enumerate(idx)]
                  for a, r in enumerate(idx)])
        CZ.append([[sum(C_row[k] * Z[start + k][c] for k in range(size)) for c in idx] for C_row in problem.outputs[i]])
    return CZ, S


def _dual_holds(problem: BlockLMI, Z: Matrix) -> bool:
    if not any(v for r in Z for v in r) or not exact_positive_semidefinite(Z):
        return False
    CZ, S = _blkdiag_products(problem, Z)
    return all(v == 0 for M in CZ for r in M for v in r) and all(exact_positive_semidefinite(M) for M in S)


def _rounded(Z: np.ndarray, denominator: int) -> Matrix:
    Z = 0.5 * (Z + Z.T) / np.max(np.abs(Z))
    return [[Fraction(float(v)).limit_denominator(denominator) for v in row] for row in Z]


def _mode_candidates(problem: BlockLMI) -> list[tuple[np.ndarray, dict]]:
    """Z = Re(v v^H) in block i for each v with ``[Omega_ii - lambda I; C_i] v = 0`` (PBH: a mode no K_i
    moves) and ``Re lambda >= -alpha``."""
    Om, found = problem.float_omega(), []
    for i, (start, size) in enumerate(zip(problem.starts, problem.sizes)):
        block = Om[start:start + size, start:start + size]
        C = problem.float_output(i)
        scale = max(1.0, float(np.max(np.abs(block))), float(np.max(np.abs(C))) if C.size else 1.0)
        for lam in np.linalg.eigvals(block):
            if lam.real < -float(problem.decay) - 1e-9 * scale:
                continue
            _, sigma, Vh = np.linalg.svd(np.vstack([block - lam * np.eye(size), C.astype(complex)]))
            sigma = np.concatenate([sigma, np.zeros(size - sigma.size)])
            for v in Vh.conj()[sigma < 1e-9 * scale]:
                v = v / v[np.argmax(np.abs(v))]
                Z = np.zeros((len(Om), len(Om)))
                Z[start:start + size, start:start + size] = np.real(np.outer(v, v.conj()))
                found.append((Z, {"block": problem.names[i], "eigenvalue": [float(lam.real), float(lam.imag)]}))
    return found


def _sdp_candidate(problem: BlockLMI) -> np.ndarray | None:
    n, Om = len(problem.omega), problem.float_omega()
    Z = cp.Variable((n, n), symmetric=True)
    M = Om @ Z + Z @ Om.T + 2 * float(problem.decay) * Z
    constraints = [Z >> 0, cp.trace(Z) == 1]
    for i, (start, size) in enumerate(zip(problem.starts, problem.sizes)):
        block = slice(start, start + size)
        S = M[block, block]
        constraints.append(0.5 * (S + S.T) >> 0)
        if problem.outputs[i]:
            constraints.append(problem.float_output(i) @ Z[block, block] == 0)
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="Solution may be inaccurate")
        try:
            cp.Problem(cp.Minimize(0), constraints).solve(solver=cp.CLARABEL)
        except cp.SolverError:
            return None
    return None if Z.value is None else np.asarray(Z.value)


def dual_certificate(problem: BlockLMI) -> dict | None:
    """A dual certificate (module docstring) checked exactly, or None: {"Z": the first, rational entries
    as strings, "source": how it was found, "modes": every block mode (eigenvalue) that certifies alone}."""
    evidence = None
    for Z, info in _mode_candidates(problem):
        exact = next((M for M in (_rounded(Z, d) for d in DENOMINATORS) if _dual_holds(problem, M)), None)
        if exact is None:
            continue
        if evidence is None:
            evidence = {"Z": [[str(v) for v in row] for row in exact], "modes": [],
                        "source": "modes that no gain moves (PBH)", "check": CHECK}
        mode = {"block": info["block"], "eigenvalue": info["eigenvalue"]}
        if mode not in evidence["modes"]:
            evidence["modes"].append(mode)  # every mode that certifies on its own
    if evidence is None:  # the dual SDP, only when no mode gives a certificate
        Z = _sdp_candidate(problem)
        exact = None if Z is None else next((M for M in (_rounded(Z, d) for d in DENOMINATORS)
                                             if _dual_holds(problem, M)), None)
        if exact is not None:
            evidence = {"Z": [[str(v) for v in row] for row in exact], "modes": [],
                        "source": "dual SDP (cvxpy, Clarabel), rounded", "check": CHECK}
    return evidence


def _balance(problem: BlockLMI) -> np.ndarray:
    """Powers of two D (n,) that balance Omega (D^-1 Omega D), exact in any arithmetic; the outputs
    count as rows of Omega so that a state seen only by a sensor is not scaled away."""
    n = len(problem.omega)
    stacked = np.zeros((n, n))
    stacked[:] = problem.float_omega()
    for i, (start, size) in enumerate(zip(problem.starts, problem.sizes)):
        C = problem.float_output(i)
        if C.size:
            stacked[start:start + size, start:start + size] += np.diag(np.max(np.abs(C), axis=0))
    _, (scale, _) = scipy.linalg.matrix_balance(stacked, permute=False, separate=True)
    return np.clip(np.asarray(scale, dtype=float), 2.0**-20, 2.0**20)


def _solve(problem: BlockLMI, rate: float, D: np.ndarray) -> tuple[list[np.ndarray], list[np.ndarray]] | None:
    """(P_i, K_i) from cvxpy + Clarabel for ``rate`` in the coordinates ``D^-1 e`` (D (n,) a diagonal
    scaling), mapped back; None if the solver finds none."""
    Om = problem.float_omega()
    Om_b = Om * D[None, :] / D[:, None]
    Ps, Ys = [], []
    for i, (start, size) in enumerate(zip(problem.starts, problem.sizes)):
        C = problem.float_output(i) * D[None, start:start + size]
        P, Y = cp.Variable((size, size), symmetric=True), cp.Variable((size, C.shape[0])) if C.size else None
        Ps.append(P)
        Ys.append((Y, C))
    P = cp.bmat([[Ps[i] if i == j else np.zeros((problem.sizes[i], problem.sizes[j]))
                  for j in range(len(Ps))] for i in range(len(Ps))])
    injection = cp.bmat([[Y @ C if (i == j and Y is not None) else np.zeros((problem.sizes[i], problem.sizes[j]))
                          for j, _ in enumerate(Ys)] for i, (Y, C) in enumerate(Ys)])
    M = P @ Om_b - injection
    M = M + M.T + 2 * rate * P
    n = len(Om)
    constraints = [Pi >> np.eye(Pi.shape[0]) for Pi in Ps] + [M << -1e-6 * np.eye(n)]
    objective = cp.Minimize(sum(cp.trace(Pi) for Pi in Ps) + sum(cp.norm(Y, "fro") for Y, _ in Ys if Y is not None))
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="Solution may be inaccurate")
        try:
            cp.Problem(objective, constraints).solve(solver=cp.CLARABEL)
        except cp.SolverError:
            return None
    if any(Pi.value is None for Pi in Ps):
        return None
    P_out, K_out = [], []
    for (start, size), Pi, (Y, _) in zip(zip(problem.starts, problem.sizes), Ps, Ys):
        d = D[start:start + size]
        Pv = 0.5 * (Pi.value + Pi.value.T)
        K_b = np.linalg.solve(Pv, Y.value) if Y is not None else np.zeros((size, 0))
        P_out.append(Pv / d[:, None] / d[None, :])  # e_b = D^-1 e: P = D^-1 P_b D^-1, K = D K_b
        K_out.append(d[:, None] * K_b)
    return P_out, K_out


def _exact_check(problem: BlockLMI, P: list[np.ndarray], K: list[np.ndarray]) -> tuple[bool, Fraction]:
    """P_i > 0 and -(He(P A_cl) + 2 alpha P) > 0 for A_cl = Omega - blkdiag(K_i C_i), in exact rationals."""
    n = len(problem.omega)
    A = [list(r) for r in problem.omega]
    Pfull = [[Fraction(0)] * n for _ in range(n)]
    margins = []
    for i, (start, size) in enumerate(zip(problem.starts, problem.sizes)):
        Ki, Pi = _exact(K[i], "K"), _exact(0.5 * (P[i] + P[i].T), "P")
        ok, pivot = exact_positive_definite(Pi)
        if not ok:
            return False, pivot
        margins.append(pivot)
        C = problem.outputs[i]
        for r in range(size):
            for c in range(size):
                Pfull[start + r][start + c] = Pi[r][c]
                A[start + r][start + c] -= sum(Ki[r][k] * C[k][c] for k in range(len(C)))
    PA = [[sum(Pfull[r][k] * A[k][c] for k in range(n) if Pfull[r][k]) for c in range(n)] for r in range(n)]
    Q = [[-(PA[r][c] + PA[c][r] + 2 * problem.decay * Pfull[r][c]) for c in range(n)] for r in range(n)]
    ok, pivot = exact_positive_definite(Q)
    return ok, min(margins + [pivot])


def solve_block_lmi(problem: BlockLMI, claim: str = "block LMI", set_description: str = "",
                    expected: str = "proved") -> tuple[BlockGains | None, Certificate]:
    """(gains or None, certificate): proved with gains, refuted with an exact dual certificate, or
    inconclusive (module docstring). The LMI is solved for ``DESIGN_MARGIN`` times the rate, then at
    the rate itself; the answer is re-checked at the rate."""
    started = time.perf_counter()
    alpha = float(problem.decay)
    where = set_description or f"blocks {', '.join(problem.names)}; decay {alpha:g} 1/s"
    blocks = f"{len(problem.sizes)} block{'s' if len(problem.sizes) != 1 else ''}"
    solved = f"block LMI ({blocks}) solved by cvxpy + Clarabel"
    scalings = (_balance(problem), np.ones(len(problem.omega)))
    for rate, D in ((r, D) for r in (DESIGN_MARGIN * alpha + 1e-6, alpha) for D in scalings):
        solution = _solve(problem, rate, D)
        if solution is None:
            continue
        for P, K in (([rounded_gain(p) for p in solution[0]], [rounded_gain(k) for k in solution[1]]), solution):
            ok, margin = _exact_check(problem, P, K)  # rounded (repeats across machines) where it passes
            if ok:
                break
        if ok:
            method = f"{solved}; its P and K re-checked by exact rational LDL^T (margin: the smallest pivot)"
            certificate = Certificate(claim, where, method, "proved", expected, margin=float(margin),
                                      seconds=time.perf_counter() - started,
                                      details={"K": [k.tolist() for k in K], "P": [p.tolist() for p in P]})
            return BlockGains(tuple(K), tuple(P), certificate), certificate
    evidence = dual_certificate(problem)
    if evidence is not None:
        method = f"block LMI ({blocks}) infeasible: a dual certificate Z ({evidence['source']}) with {CHECK}"
        return None, Certificate(claim, where, method, "refuted", expected, seconds=time.perf_counter() - started,
                                 counterexample=evidence)
    method = f"{solved}: no gain passed the exact re-check, and no dual certificate was found"
    return None, Certificate(claim, where, method, "inconclusive", expected, seconds=time.perf_counter() - started,
                             reason="neither a gain that passes the exact re-check nor a dual certificate was found")


def block_lmi_claim(problem: BlockLMI, claim: str, set_description: str = "", expected: str = "proved") -> Certificate:
    """The certificate of :func:`solve_block_lmi` alone."""
    return solve_block_lmi(problem, claim, set_description, expected)[1]
