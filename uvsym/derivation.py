"""The derivation protocol: how a study plugs into ``uvsym report``, ``verify`` and ``codegen``.

A derivation reproduces one study (usually a paper) with uvsym. It lives outside the package
(``derivations/`` here, or any installed distribution) and registers a module-level
:class:`Derivation` as an entry point of the group ``uvsym.derivations``::

    [project.entry-points."uvsym.derivations"]
    my-study = "my_package.my_study:DERIVATION"

What a derivation implements:

- ``build(out_dir, progress)``: run the study and write ``report.md`` and whatever it links to
  into ``out_dir``, calling ``progress(message)`` at each step;
- ``claims()``, optional: its machine-checked claims, a list of
  :class:`~uvsym.verify.certificate.Certificate`, each with the status it is expected to have
  (a negative control expects ``"refuted"``);
- ``observer_sets``, optional: set name -> factory that takes keyword options with defaults
  (``vehicle``, ``form``, ...) and returns an :class:`~uvsym.codegen.observer_sets.ObserverSet`;
- ``scenarios``, optional: shipped example scenario name -> TOML path, each a scenario over a plant
  (:mod:`uvsym.sim.system_scenario`) that ``uvsym simulate``, ``uvsym campaign``, ``uvsym codegen``
  and ``uvsym verify`` take by its name: the ``*.toml`` files of the ``scenarios/`` folder of the
  derivation's package, by file name (uvsym finds them there without importing the derivation, and
  refuses a derivation that declares others).

What it gets for free:

- ``uvsym report NAME``: ``build`` into ``reports/NAME/`` and ``report.html`` beside ``report.md``;
- ``uvsym verify NAME``: the claims checked and tabulated, ``reports/NAME/proofs.json``, exit
  status 1 when a claim is not as expected;
- ``uvsym codegen SET -o DIR [--vehicle V] [--form F] [--float]``: the set as a C99 package,
  options passed to the factory only when given; ``uvsym codegen --list`` lists every set;
- its shipped scenarios in ``uvsym simulate --list``, run by name like uvsym's own.

Paper-specific numbers (vehicles, gains, faults, the paper's values) belong in the derivation;
nothing in ``uvsym`` imports one.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from importlib.metadata import EntryPoint, entry_points
from importlib.util import find_spec
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING

from uvsym.errors import DerivationError, UnknownNameError, did_you_mean

if TYPE_CHECKING:
    from uvsym.codegen.observer_sets import ObserverSet
    from uvsym.verify.certificate import Certificate

__all__ = ["GROUP", "SCENARIO_FOLDER", "Derivation", "DerivationError", "derivation", "derivations",
           "load_derivations", "observer_set", "observer_sets", "source_fingerprint", "study_scenarios"]

GROUP = "uvsym.derivations"
SCENARIO_FOLDER = "scenarios"  # in a derivation's package: its shipped scenarios, one TOML file each


@dataclass(frozen=True)
class Derivation:
    """A study as uvsym runs it (module docstring): name (the entry point's), title and parts."""

    name: str
    title: str
    build: Callable[[Path, Callable[[str], None]], None]
    claims: Callable[[], list[Certificate]] | None = None
    observer_sets: Mapping[str, Callable[..., ObserverSet]] = field(default_factory=dict)
    scenarios: Mapping[str, Path] = field(default_factory=dict)

    def __post_init__(self):
        if not isinstance(self.observer_sets, Mapping):
            raise DerivationError(f"derivation {self.name!r}: observer_sets must map set names to factories, "
                                  f"got {type(self.observer_sets).__name__}")
        if not isinstance(self.scenarios, Mapping):
            raise DerivationError(f"derivation {self.name!r}: scenarios must map names to TOML paths, "
                                  f"got {type(self.scenarios).__name__}")
        parts = {"build": self.build, **({} if self.claims is None else {"claims": self.claims}),
                 **{f"observer set {k!r}": f for k, f in self.observer_sets.items()}}
        bad = [part for part, f in parts.items() if not callable(f)]
        if bad:
            raise DerivationError(f"derivation {self.name!r}: not callable: {', '.join(bad)}")
        object.__setattr__(self, "observer_sets", MappingProxyType(dict(self.observer_sets)))
        object.__setattr__(self, "scenarios", MappingProxyType({k: Path(v) for k, v in self.scenarios.items()}))


def _entry_points() -> dict[str, EntryPoint]:
    return {ep.name: ep for ep in sorted(entry_points(group=GROUP), key=lambda ep: ep.name)}


def _load(ep: EntryPoint) -> Derivation:
    """The Derivation an entry point names; DerivationError naming the entry point otherwise."""
    where = f"entry point {ep.name!r} = {ep.value!r} (group {GROUP})"
    try:
        loaded = ep.load()
    except Exception as exc:  # a plug-in's own bug (SyntaxError, ValueError, ...) is reported, named
        raise DerivationError(f"{where} cannot be loaded: {type(exc).__name__}: {exc}") from exc
    if not isinstance(loaded, Derivation):
        raise DerivationError(f"{where} is a {type(loaded).__name__}, not a uvsym.derivation.Derivation")
    if loaded.name != ep.name:
        raise DerivationError(f"{where} names a Derivation called {loaded.name!r}")
    shipped = _shipped_files(ep)
    if {k: v.resolve() for k, v in loaded.scenarios.items()} != {k: v.resolve() for k, v in shipped.items()}:
        raise DerivationError(f"{where} declares the scenarios {sorted(loaded.scenarios) or 'none'}, not the files "
                              f"of its package's {SCENARIO_FOLDER}/ folder ({sorted(shipped) or 'none'}), where uvsym "
                              "finds them by name")
    return loaded


def _shipped_files(ep: EntryPoint) -> dict[str, Path]:
    """The scenario files of the package an entry point's module is (name -> path), found without importing it
    (only its parent packages); none for a plain module or one that cannot be found (its loading reports why)."""
    try:
        spec = find_spec(ep.module)
    except (ImportError, ValueError):  # a missing parent package; a module made at run time, without a spec
        return {}
    if spec is None or not spec.submodule_search_locations:
        return {}
    folder = Path(next(iter(spec.submodule_search_locations))) / SCENARIO_FOLDER
    return {path.stem: path for path in sorted(folder.glob("*.toml"))}


def load_derivations() -> dict[str, Derivation]:
    """Every installed derivation, by name (sorted); DerivationError for a malformed one."""
    return {name: _load(ep) for name, ep in _entry_points().items()}


def derivation(name: str) -> Derivation:
    """The installed derivation ``name`` (only it is loaded); UnknownNameError lists the known ones."""
    return derivations([name])[0]


def derivations(names: list[str]) -> list[Derivation]:
    """The installed derivations ``names``, only those loaded, after every name is checked (UnknownNameError
    with the closest name and the known ones)."""
    available = _entry_points()
    for name in names:
        if name not in available:
            raise UnknownNameError(f"unknown derivation {name!r}{did_you_mean(name, available)}; "
                                   f"known: {', '.join(available) or 'none installed'}")
    return [_load(available[name]) for name in names]


def observer_sets() -> dict[str, tuple[str, Callable[..., ObserverSet]]]:
    """Every observer set the installed derivations declare: set name -> (derivation name, factory)."""
    found: dict[str, tuple[str, Callable[..., ObserverSet]]] = {}
    for study in load_derivations().values():
        for name, factory in study.observer_sets.items():
            if name in found:
                raise DerivationError(f"observer set {name!r} is declared by both {found[name][0]!r} and "
                                      f"{study.name!r}")
            found[name] = (study.name, factory)
    return dict(sorted(found.items()))


def observer_set(name: str, **options) -> ObserverSet:
    """The observer set ``name`` built with ``options``; UnknownNameError for an unknown set or option."""
    from uvsym.codegen.observer_sets import make_observer_set

    available = observer_sets()
    if name not in available:
        raise UnknownNameError(f"unknown observer set {name!r}{did_you_mean(name, available)}; "
                               f"known: {', '.join(available) or 'none declared'}")
    return make_observer_set(name, available[name][1], **options)


def study_scenarios() -> dict[str, tuple[str, Path]]:
    """Every scenario the installed derivations ship (their packages' ``scenarios/`` folders, no derivation
    imported): name -> (derivation name, TOML path)."""
    found: dict[str, tuple[str, Path]] = {}
    for study, ep in _entry_points().items():
        for name, path in _shipped_files(ep).items():
            if name in found:
                raise DerivationError(f"scenario {name!r} is shipped by both {found[name][0]!r} and {study!r}")
            found[name] = (study, path)
    return dict(sorted(found.items()))


_SOURCE_SUFFIXES = (".py", ".toml", ".json", ".txt", ".csv")


def source_fingerprint(study: Derivation) -> str:
    """SHA-256 of everything a report depends on: the sources and data of uvsym and of the study's
    top-level package, and the versions of the libraries that compute it. Two builds with the same
    fingerprint come from the same code (``uvsym report`` records it in ``NAME/.build.json``)."""
    import hashlib
    import importlib
    import importlib.metadata
    import sys

    import uvsym

    digest = hashlib.sha256(sys.version.encode())
    for library in ("casadi", "numpy", "scipy", "sympy", "matplotlib", "cvxpy", "clarabel"):
        try:
            digest.update(f"{library} {importlib.metadata.version(library)}".encode())
        except importlib.metadata.PackageNotFoundError:
            digest.update(f"{library} none".encode())
    top = importlib.import_module(study.build.__module__.split(".")[0])
    for root in sorted({Path(uvsym.__file__).parent, Path(top.__file__).parent}):
        for path in sorted(root.rglob("*")):
            if path.suffix in _SOURCE_SUFFIXES and "__pycache__" not in path.parts and path.is_file():
                digest.update(str(path.relative_to(root.parent)).encode() + b"\0" + path.read_bytes())
    return digest.hexdigest()
