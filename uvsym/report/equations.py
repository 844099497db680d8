"""Equations of any named Function as LaTeX, one line per output entry, in the signals' own names.

``function_equations(f, inputs, outputs)`` re-evaluates ``f`` on one scalar symbol per named
signal (``i_sq``, ``omega_m_hat``, ...) so that the LaTeX reads in the signals' names rather than
``x_3``; ``observer_equations`` does it for an :class:`~uvsym.observers.base.Observer`: its step,
or the continuous form it keeps in ``equations``. Names are typeset by :func:`signal_latex`:
``omega_m_hat`` -> ``\\hat{\\omega}_{m}``, ``lambda_rq`` -> ``\\lambda_{rq}``, ``f_hat.X`` -> ``\\hat{f}_{X}``.
"""

from __future__ import annotations

import re

import casadi as ca
import sympy as sp

from uvsym.errors import UvsymError
from uvsym.sympy_bridge import latex, to_sympy
from uvsym.systems.signals import Signals

__all__ = ["signal_latex", "function_equations", "observer_equations"]

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


def function_equations(function: ca.Function, inputs: list[Signals], outputs: list[tuple[Signals, str]],
                       values: dict | None = None, digits: int = 6) -> list[str]:
    """``lhs = rhs`` LaTeX lines for every output entry of ``function``.

    inputs: one Signals per input of ``function`` (same sizes), naming its entries; outputs: per
    output, (Signals naming its entries, decoration) with decoration "" (plain), "dot" or "next"
    (``x^{+}``); values: input index -> numbers substituted (e.g. gains), optional.
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
    lines = []
    for (group, decoration), expression in zip(outputs, results):
        expression = ca.vec(ca.SX(expression))
        rhs = to_sympy(expression)
        entries = [rhs] if not isinstance(rhs, sp.MatrixBase) else list(rhs)
        for name, entry in zip(group.names, entries):
            lhs = signal_latex(name)
            lhs = {"": lhs, "dot": f"\\dot{{{lhs}}}", "next": f"{lhs}^{{+}}"}[decoration]
            lines.append(f"{lhs} = {latex(sp.sympify(entry), digits, names=names)}")
    return lines


def observer_equations(observer, continuous: bool = True, digits: int = 6) -> list[str]:
    """LaTeX lines of an observer: its continuous form ``(xhat, y, u, p) -> xhat_dot`` when it keeps
    one with that shape (and ``continuous``), else its step ``s^+ = ..., out = ...``; the
    parameters are replaced by their default values p0."""
    form = observer.equations.get("continuous") if continuous else None
    groups = [observer.state, observer.reads_y, observer.reads_u, observer.params]
    if form is not None and form.n_in() == 4 and form.n_out() == 1 and \
            [form.numel_in(i) for i in range(4)] == [g.size for g in groups]:
        return function_equations(form, groups, [(observer.state, "dot")], {3: observer.p0}, digits)
    return function_equations(observer.step, groups, [(observer.state, "next"), (observer.publishes, "")],
                              {3: observer.p0}, digits)
