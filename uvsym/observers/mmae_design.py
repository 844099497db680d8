"""An MMAE bank (:mod:`uvsym.observers.mmae`) designed from a scenario's ``[[blocks]]`` table
(``type = "mmae"``): one Gaussian filter of the plant per hypothesis, a hypothesis naming the
inputs whose efficiency it estimates (:func:`~uvsym.observers.kalman.efficiency_augmented`).

Fields (besides type and name): ``filter`` (``"ukf"`` or ``"ekf"``), ``models`` (a table:
hypothesis = list of input names, ``[]`` for the no-fault model; at least two, in file order),
``q`` (n x n), ``r`` (n_y x n_y), ``p0`` (n x n) of the plant's states (covariances per sample:
a number, the diagonal or a full matrix), ``x0`` (n,) the initial estimate (default the plant's
operating point), ``efficiency_p0`` (variance of each efficiency at the start, efficiency 1),
``walk_std`` (standard deviation per sample of the efficiencies' random walk), ``floor`` (the
probability floor), ``prior`` (one probability per model, default uniform), ``reset``
(federated reset, default true), ``steps`` (RK4 steps per sample of the filters' model) and, for
the UKF, ``alpha``, ``beta``, ``kappa``. The filters' model is the plant itself with its
disturbances at zero (their effect is what ``q`` stands for) and its parameters at ``p0``.
"""

from __future__ import annotations

import numpy as np

from uvsym.errors import ScenarioError
from uvsym.observers.base import Observer
from uvsym.observers.ekf import extended_filter
from uvsym.observers.kalman import GaussianFilter, efficiency_augmented
from uvsym.observers.mmae import mmae_bank
from uvsym.observers.ukf import unscented_filter
from uvsym.sim.fields import Fields
from uvsym.systems.system import System

__all__ = ["FILTERS", "bank_models", "bank_filters", "designed_bank"]

FILTERS = ("ukf", "ekf")


def bank_models(fields: Fields, plant: System) -> dict[str, tuple[str, ...]]:
    """hypothesis -> the inputs with an efficiency state, from the ``models`` table."""
    value = fields.raw("models", None, "table", "hypothesis = [inputs with an efficiency state]")
    if not isinstance(value, dict) or len(value) < 2:
        raise ScenarioError(f"{fields._name('models')}: expected a table of at least two hypotheses "
                            f"(name = [inputs], [] for no fault), got {value!r}")
    models = {}
    for model, inputs in value.items():
        where = f"{fields._name('models')}.{model}"
        if not isinstance(inputs, list) or not all(isinstance(i, str) for i in inputs):
            raise ScenarioError(f"{where}: expected a list of input names, got {inputs!r}")
        unknown = [i for i in inputs if i not in plant.u.names]
        if unknown or len(set(inputs)) != len(inputs):
            raise ScenarioError(f"{where}: {inputs} must be distinct inputs of {plant.name} "
                                f"({', '.join(plant.u.names)})")
        models[model] = tuple(inputs)
    return models


def bank_filters(fields: Fields, plant: System, dt: float) -> dict[str, GaussianFilter]:
    """hypothesis -> its filter (module docstring), every field but the bank's own read."""
    from uvsym.sim.catalogue import _matrix

    method = fields.text("filter", choices=FILTERS)
    models = bank_models(fields, plant)
    n, n_y = plant.x.size, plant.y.size
    Q, R, P0 = (_matrix(fields, key, (size, size), dims) for key, size, dims in
                (("q", n, "n_x x n_x"), ("r", n_y, "n_y x n_y"), ("p0", n, "n_x x n_x")))
    x0 = fields.vector("x0", n, list(plant.x_op))
    start = fields.number("efficiency_p0", positive=True)
    walk = fields.number("walk_std", positive=True)
    steps = fields.integer("steps", 1, minimum=1, unit="RK4 steps per sample")
    unscented = {key: fields.number(key, default) for key, default in (("alpha", 1.0), ("beta", 2.0),
                                                                         ("kappa", 0.0))}
    if method == "ekf" and any(fields.has(key) for key in unscented):
        raise ScenarioError(f"{fields.path}: alpha, beta and kappa tune a UKF, not filter = \"ekf\"")
    built = {}
    for model, inputs in models.items():
        system = efficiency_augmented(plant, inputs) if inputs else plant
        extra = len(inputs)
        Q_m, P0_m = np.zeros((n + extra,) * 2), np.zeros((n + extra,) * 2)
        Q_m[:n, :n], Q_m[n:, n:] = Q, walk ** 2 * np.eye(extra)
        P0_m[:n, :n], P0_m[n:, n:] = P0, start * np.eye(extra)
        options = dict(dt=dt, Q=Q_m, R=R, P0=P0_m, x0=np.concatenate([x0, np.ones(extra)]), steps=steps, name=model)
        built[model] = (unscented_filter(system, **options, **unscented) if method == "ukf"
                        else extended_filter(system, **options))
    return built


def designed_bank(fields: Fields, plant: System, dt: float, name: str) -> Observer:
    """The MMAE bank (an Observer) a ``type = "mmae"`` table describes (module docstring)."""
    filters = bank_filters(fields, plant, dt)
    prior = fields.vector("prior", len(filters))
    reset = fields.raw("reset", True, "boolean", "federated reset of the shared states")
    if not isinstance(reset, bool):
        raise ScenarioError(f"{fields._name('reset')}: expected true or false, got {reset!r}")
    return mmae_bank(filters, name=name, p_min=fields.number("floor", 1e-3, positive=True), prior=prior, reset=reset)
