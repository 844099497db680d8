"""Equations of any named Function as LaTeX, one line per output entry, in the signals' own names.

``function_equations(f, inputs, outputs)`` re-evaluates ``f`` on one scalar symbol per named
signal (``i_sq``, ``omega_m_hat``, ...) so that the LaTeX reads in the signals' names rather than
``x_3``; ``observer_equations`` does it for an :class:`~uvsym.observers.base.Observer`: its step,
or the continuous form it keeps in ``equations``. Names are typeset by :func:`signal_latex`:
``omega_m_hat`` -> ``\\hat{\\omega}_{m}``, ``lambda_rq`` -> ``\\lambda_{rq}``, ``f_hat.X`` -> ``\\hat{f}_{X}``.

A Kalman filter's step (Cholesky factors, sigma points) written out entry by entry is far too
large to read or even to print; :func:`filter_equations` gives its structured form instead
(model, Jacobians F and H as matrices of their symbolic entries, prediction, gain, update).
Everywhere a size guard applies: an entry with more than ``max_operations`` operations written
out (:func:`operations`) is not converted; it is named (``F_{1,2}``) and listed, with its size,
in the ``skipped`` notes of the :class:`Equations` returned.
"""

from __future__ import annotations

import re

import casadi as ca
import numpy as np
import sympy as sp

from uvsym.errors import UvsymError
from uvsym.sympy_bridge import latex, to_sympy
from uvsym.systems.signals import Signals

__all__ = ["Equations", "operations", "entry_latex", "signal_latex", "function_equations", "observer_equations",
           "filter_equations", "equations_markdown", "MAX_OPERATIONS", "PART_TITLES"]

MAX_OPERATIONS = 400  # operations of one entry written out; a larger entry is named, not shown
MAX_WALK = 5_000  # DAG nodes above which an entry is not walked to count its written-out size

GREEK = {"alpha", "beta", "gamma", "delta", "epsilon", "zeta", "eta", "theta", "iota", "kappa", "lambda", "mu",
         "nu", "xi", "pi", "rho", "sigma", "tau", "phi", "chi", "psi", "omega", "Gamma", "Delta", "Theta",
         "Lambda", "Xi", "Pi", "Sigma", "Phi", "Psi", "Omega"}


def signal_latex(name: str) -> str:
    """LaTeX of a signal name: ``base_sub`` -> base with subscript (parts joined by commas), a
    ``hat`` part -> a hat on the base, Greek bases and parts as Greek letters, ``a.b`` -> ``a_{b}``;
    characters LaTeX treats specially are escaped."""
    parts = [p for p in re.split(r"[._]", name) if p]
    hat = "hat" in parts[1:]
    parts = [p for i, p in enumerate(parts) if p != "hat" or i == 0] or [name]
    base, rest = parts[0], parts[1:]
    tex = _word(base, upright=len(base) > 1)
    if hat:
        tex = f"\\hat{{{tex}}}"
    if rest:
        tex = f"{tex}_{{{','.join(_word(p, upright=False) for p in rest)}}}"
    return tex


def _word(word: str, upright: bool) -> str:
    """A Greek letter, or the word with LaTeX's special characters escaped (upright if asked)."""
    if word in GREEK:
        return f"\\{word}"
    escaped = re.sub(r"([#$%&{}~^\\])", lambda m: "\\" + m.group(1) if m.group(1) not in "~^\\"
                     else {"~": r"\textasciitilde{}", "^": r"\^{}", "\\": r"\backslash{}"}[m.group(1)], word)
    return r"\mathrm{" + escaped + "}" if upright else escaped


class Equations(list):
    """LaTeX lines (a list of str) and ``skipped``: one Markdown note per entry the size guard
    (``max_operations``) left out, naming it and its size."""

    def __init__(self, lines=(), skipped=()):
        super().__init__(lines)
        self.skipped = list(skipped)


def operations(expression) -> int:
    """Operations of a scalar SX written out as one formula, symbols and constants counted as one
    each and a shared sub-expression at each use (as it is printed). Above ``MAX_WALK`` nodes of
    the expression graph it is not walked: the graph's node count, a lower bound, is returned."""
    expression = ca.SX(expression)
    symbols = ca.symvar(expression)
    if symbols and ca.Function("size", symbols, [expression]).n_nodes() > MAX_WALK:
        return ca.Function("size", symbols, [expression]).n_nodes()
    memo: dict[int, int] = {}
    stack = [expression]
    while stack:  # post-order without recursion (a graph may be deeper than Python's stack)
        node = stack[-1]
        key = node.element_hash()
        if key in memo:
            stack.pop()
            continue
        deps = [node.dep(i) for i in range(node.n_dep())] if not (node.is_symbolic() or node.is_constant()) else []
        pending = [d for d in deps if d.element_hash() not in memo]
        if pending:
            stack.extend(pending)
            continue
        memo[key] = 1 + sum(memo[d.element_hash()] for d in deps)
        stack.pop()
    return memo[expression.element_hash()]


def entry_latex(expression, names: dict[str, str], digits: int, max_operations: int,
                label: str, zero_below: float = 0.0) -> tuple[str | None, str | None]:
    """(LaTeX, None) of a scalar SX, or (None, note) when written out it has more than
    ``max_operations`` operations; the note names ``label`` (LaTeX) and the count. zero_below: as
    :func:`uvsym.sympy_bridge.latex`."""
    size = operations(expression)
    if size > max_operations:
        more = "at least " if size > MAX_WALK else ""
        return None, (f"${label}$: {more}{size} operations written out, more than the guard of "
                      f"{max_operations}; not shown")
    return latex(sp.sympify(to_sympy(expression)), digits, zero_below, names=names), None


def function_equations(function: ca.Function, inputs: list[Signals], outputs: list[tuple[Signals, str]],
                       values: dict | None = None, digits: int = 6,
                       max_operations: int = MAX_OPERATIONS, zero_below: float = 0.0) -> Equations:
    """``lhs = rhs`` LaTeX lines for every output entry of ``function``.

    inputs: one Signals per input of ``function`` (same sizes), naming its entries; outputs: per
    output, (Signals naming its entries, decoration) with decoration "" (plain), "dot" or "next"
    (``x^{+}``); values: input index -> numbers substituted (e.g. gains), optional. An entry with
    more than ``max_operations`` operations written out has no line, a note in ``skipped`` instead.
    zero_below: coefficients of smaller magnitude shown as 0, those within it of 1 as 1 (rounding
    residues; say so where it is used).
    """
    if len(inputs) != function.n_in() or len(outputs) != function.n_out():
        raise UvsymError(f"{function.name()}: give one Signals per input ({function.n_in()}) and output "
                         f"({function.n_out()})")
    args = []
    for i, group in enumerate(inputs):
        if group.size != function.numel_in(i):
            raise UvsymError(f"{function.name()}: input {function.name_in(i)} has {function.numel_in(i)} entries, "
                             f"{group.size} names given")
        if values and i in values:
            args.append(ca.DM(values[i]))
        else:
            args.append(ca.vertcat(*[ca.SX.sym(name) for name in group.names]) if group.size else ca.SX(0, 1))
    results = function.call(args)
    names = {name: signal_latex(name) for group in inputs for name in group.names}
    equations = Equations()
    for (group, decoration), expression in zip(outputs, results):
        expression = ca.vec(ca.SX(expression))
        for k, name in enumerate(group.names):
            lhs = signal_latex(name)
            lhs = {"": lhs, "dot": f"\\dot{{{lhs}}}", "next": f"{lhs}^{{+}}"}[decoration]
            tex, note = entry_latex(expression[k], names, digits, max_operations, lhs, zero_below)
            if note:
                equations.skipped.append(note)
            else:
                equations.append(f"{lhs} = {tex}")
    return equations


def observer_equations(observer, continuous: bool = True, digits: int = 6,
                       max_operations: int = MAX_OPERATIONS, zero_below: float = 0.0) -> Equations:
    """LaTeX lines of an observer: a Gaussian filter's structured form (the parts of
    :func:`filter_equations`, one after the other) when it keeps its filter in
    ``equations["filter"]``; else its continuous form ``(xhat, y, u, p) -> xhat_dot`` when it keeps
    one with that shape (and ``continuous``), else its step ``s^+ = ..., out = ...``. The
    parameters are replaced by their default values p0; entries larger than ``max_operations``
    are listed in ``skipped``; zero_below as :func:`function_equations` (not for a filter)."""
    if "filter" in observer.equations:
        parts = filter_equations(observer.equations["filter"], digits, max_operations).values()
        return Equations([line for part in parts for line in part], [note for part in parts for note in part.skipped])
    form = observer.equations.get("continuous") if continuous else None
    groups = [observer.state, observer.reads_y, observer.reads_u, observer.params]
    if form is not None and form.n_in() == 4 and form.n_out() == 1 and \
            [form.numel_in(i) for i in range(4)] == [g.size for g in groups]:
        return function_equations(form, groups, [(observer.state, "dot")], {3: observer.p0}, digits, max_operations,
                                  zero_below)
    return function_equations(observer.step, groups, [(observer.state, "next"), (observer.publishes, "")],
                              {3: observer.p0}, digits, max_operations, zero_below)


def _jacobian(expression, x: ca.SX, symbol: str, names: dict[str, str], digits: int,
              max_operations: int) -> Equations:
    """``symbol = [d expression_i / d x_j]`` as one bmatrix line; an entry above the guard is shown
    as ``symbol_{i,j}`` (from 1) with a note."""
    J = ca.SX(ca.jacobian(expression, x))
    rows, skipped = [], []
    for i in range(J.shape[0]):
        row = []
        for j in range(J.shape[1]):
            label = f"{symbol}_{{{i + 1},{j + 1}}}"
            tex, note = entry_latex(J[i, j], names, digits, max_operations, label) if J.has_nz(i, j) else ("0", None)
            row.append(label if note else tex)
            skipped += [note] if note else []
        rows.append(" & ".join(row))
    return Equations([r"\begin{bmatrix} " + r" \\ ".join(rows) + r" \end{bmatrix}"], skipped)


def filter_equations(filt, digits: int = 4, max_operations: int = MAX_OPERATIONS) -> dict[str, Equations]:
    """The structured form of a :class:`~uvsym.observers.kalman.GaussianFilter` (EKF or UKF):
    parts ``model`` (the state vector, f or the discrete map, h), ``jacobians`` (EKF: ``F_k = dF/dx``
    of the discrete map, ``H_k = dh/dx``, matrices of their symbolic entries; UKF: H when h is affine
    in x, the closed form it uses), ``prediction``, ``gain`` and ``update``, each LaTeX lines with
    ``skipped`` notes. Parameters at p0, disturbances 0 (as the filter runs); Q, R to ``digits``.

    The model and Jacobians are derived from the filter's System and its discrete map
    (:func:`~uvsym.observers.kalman.transition`); the rest is the method's algebra, with the
    filter's own Q, R and (UKF) weights. Raises UvsymError for a method other than 'ekf' or 'ukf'.
    """
    from uvsym.observers.kalman import transition
    from uvsym.observers.ukf import unscented_weights
    from uvsym.report.markdown import latex_matrix

    if filt.method not in ("ekf", "ukf"):
        raise UvsymError(f"{filt.name}: no structured form for filter method {filt.method!r} (known: ekf, ukf)")
    system, n = filt.system, filt.system.x.size
    p0 = ca.DM(np.asarray(system.p0, dtype=float).reshape(-1, 1))
    x = ca.vertcat(*[ca.SX.sym(name) for name in system.x.names])
    u = ca.vertcat(*[ca.SX.sym(name) for name in system.u.names]) if system.u.size else ca.SX(0, 1)
    names = {name: signal_latex(name) for group in (system.x, system.u) for name in group.names}
    state = r"\mathbf{x} = \begin{bmatrix} " + r" \\ ".join(signal_latex(v) for v in system.x.names) + r" \end{bmatrix}"
    if system.discrete:
        dynamics = function_equations(system.f, [system.x, system.u, system.d, system.p], [(system.x, "next")],
                                      {2: np.zeros(system.d.size), 3: system.p0}, digits, max_operations)
        discrete_map = r"F(\mathbf{x}, \mathbf{u}) = \mathbf{x}^{+}\quad \text{(the model's own map)}"
    else:
        dynamics = function_equations(system.f, [system.x, system.u, system.d, system.p], [(system.x, "dot")],
                                      {2: np.zeros(system.d.size), 3: system.p0}, digits, max_operations)
        steps = filt.settings["steps"]
        discrete_map = (rf"F(\mathbf{{x}}, \mathbf{{u}}) = \text{{{steps} RK4 step{'s' if steps > 1 else ''} of }} "
                        r"\dot{\mathbf{x}} = f(\mathbf{x}, \mathbf{u})"
                        rf"\text{{ over }} \Delta t = {filt.dt:g}\,\mathrm{{s}}")
    measured = Signals(tuple(f"y.{name}" if name in system.x.names + system.u.names else name
                             for name in system.y.names), system.y.units)  # y = x reads y_x = x
    output = function_equations(system.h, [system.x, system.u, system.p], [(measured, "")], {2: system.p0}, digits,
                                max_operations)
    model = Equations([state, *dynamics, discrete_map, *output], dynamics.skipped + output.skipped)
    h = system.h(x, u, p0)
    Q, R = latex_matrix(filt.Q, digits), latex_matrix(filt.R, digits)
    loglik = (r"\log f(y_k \mid Y_{k-1}) = -\frac{1}{2} r_k^{\top} S_k^{-1} r_k - \sum_j \log L_{jj} - \frac{n_y}{2}"
              r" \log 2\pi,\quad L L^{\top} = S_k")
    if filt.method == "ekf":
        F_k = _jacobian(transition(system, filt.dt, filt.settings["steps"])(x, u, p0), x, "F", names, digits,
                        max_operations)
        H_k = _jacobian(h, x, "H", names, digits, max_operations)
        jacobians = Equations([r"F_k = \frac{\partial F}{\partial \mathbf{x}}(\hat{x}_{k|k}, u_k) = " + F_k[0],
                               r"H_k = \frac{\partial h}{\partial \mathbf{x}}(\hat{x}_{k|k-1}, u_k) = " + H_k[0]],
                              F_k.skipped + H_k.skipped)
        if not system.discrete:  # the continuous model's Jacobian, which F_k integrates
            A = _jacobian(system.f(x, u, ca.DM.zeros(system.d.size), p0), x, "A", names, digits, max_operations)
            jacobians = Equations([r"A = \frac{\partial f}{\partial \mathbf{x}} = " + A[0]
                                   + r"\quad \text{(}F_k\text{ is the Jacobian of its RK4 map)}",
                                   *jacobians], A.skipped + jacobians.skipped)
        prediction = [r"\hat{x}_{k+1|k} = F(\hat{x}_{k|k}, u_k)", r"P_{k+1|k} = F_k P_{k|k} F_k^{\top} + Q",
                      f"Q = {Q}"]
        gain = [r"S_k = H_k P_{k|k-1} H_k^{\top} + R", f"R = {R}", r"K_k = P_{k|k-1} H_k^{\top} S_k^{-1}"]
        update = [r"r_k = y_k - h(\hat{x}_{k|k-1}, u_k)", r"\hat{x}_{k|k} = \hat{x}_{k|k-1} + K_k r_k",
                  r"P_{k|k} = (I - K_k H_k) P_{k|k-1} (I - K_k H_k)^{\top} + K_k R K_k^{\top}", loglik]
    else:
        s = filt.settings
        _, w_m, w_c = unscented_weights(n, s["alpha"], s["beta"], s["kappa"])
        lam = s["alpha"] ** 2 * (n + s["kappa"]) - n
        sigma = (r"\mathcal{X}_0 = \hat{x},\quad \mathcal{X}_i, \mathcal{X}_{n+i} = \hat{x} \pm \sqrt{n + \lambda}\,"
                 r" L_{:,i}\ (i = 1, \ldots, n),\quad L L^{\top} = P")
        weights = (rf"n = {n},\ \alpha = {s['alpha']:g},\ \beta = {s['beta']:g},\ \kappa = {s['kappa']:g},\ "
                   rf"\lambda = \alpha^2 (n + \kappa) - n = {lam:.{digits}g},\quad w^{{m}}_0 = "
                   rf"{w_m[0]:.{digits}g},\ w^{{c}}_0 = {w_c[0]:.{digits}g},\ w_i = {w_m[1]:.{digits}g}")
        prediction = [sigma + r"\quad \text{with } (\hat{x}, P) = (\hat{x}_{k|k}, P_{k|k})", weights,
                      r"\hat{x}_{k+1|k} = \sum_{i=0}^{2n} w^{m}_i F(\mathcal{X}_i, u_k)",
                      r"P_{k+1|k} = \sum_{i=0}^{2n} w^{c}_i \left(F(\mathcal{X}_i, u_k) - \hat{x}_{k+1|k}\right)"
                      r"\left(F(\mathcal{X}_i, u_k) - \hat{x}_{k+1|k}\right)^{\top} + Q", f"Q = {Q}"]
        if s["affine_closed_form"]:
            H = _jacobian(h, x, "H", names, digits, max_operations)
            jacobians = Equations([r"H = \frac{\partial h}{\partial \mathbf{x}} = " + H[0]
                                   + r"\quad \text{(h affine in x: the transform is exact)}"], H.skipped)
            gain = [r"\hat{z}_k = h(\hat{x}_{k|k-1}, u_k),\quad P_{zz} = H P_{k|k-1} H^{\top} + R,\quad "
                    r"P_{xz} = P_{k|k-1} H^{\top}", f"R = {R}"]
        else:
            jacobians = Equations()
            gain = [sigma + r"\quad \text{with } (\hat{x}, P) = (\hat{x}_{k|k-1}, P_{k|k-1}),\quad "
                    r"\mathcal{Z}_i = h(\mathcal{X}_i, u_k)",
                    r"\hat{z}_k = \sum_{i=0}^{2n} w^{m}_i \mathcal{Z}_i,\quad P_{zz} = \sum_{i=0}^{2n} w^{c}_i "
                    r"(\mathcal{Z}_i - \hat{z}_k)(\mathcal{Z}_i - \hat{z}_k)^{\top} + R",
                    r"P_{xz} = \sum_{i=0}^{2n} w^{c}_i (\mathcal{X}_i - \hat{x}_{k|k-1})"
                    r"(\mathcal{Z}_i - \hat{z}_k)^{\top}", f"R = {R}"]
        gain.append(r"K_k = P_{xz} P_{zz}^{-1}")
        update = [r"r_k = y_k - \hat{z}_k", r"\hat{x}_{k|k} = \hat{x}_{k|k-1} + K_k r_k",
                  r"P_{k|k} = P_{k|k-1} - K_k P_{xz}^{\top}", loglik.replace("S_k", "P_{zz}")]
    return {"model": model, "jacobians": jacobians, "prediction": Equations(prediction), "gain": Equations(gain),
            "update": Equations(update)}


PART_TITLES = {"model": "Model", "jacobians": "Jacobians", "prediction": "Prediction", "gain": "Gain",
               "update": "Update"}


def equations_markdown(equations: Equations | dict[str, Equations]) -> str:
    """Markdown of :class:`Equations` (one ``$$ ... $$`` per line, then the size guard's notes) or
    of the parts of :func:`filter_equations` (each under its title in bold)."""
    if isinstance(equations, dict):
        return "\n\n".join(f"**{PART_TITLES.get(part, part)}**\n\n{equations_markdown(lines)}"
                           for part, lines in equations.items() if lines or lines.skipped)
    text = "\n\n".join(f"$$ {line} $$" for line in equations)
    if equations.skipped:
        text += "\n\nNot written out (size guard):\n\n" + "\n".join(f"- {note}" for note in equations.skipped)
    return text
