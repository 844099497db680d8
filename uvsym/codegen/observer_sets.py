"""Observer sets: what ``uvsym codegen NAME`` exports, as a derivation declares it.

A derivation maps set names to factories (:class:`uvsym.derivation.Derivation`); a factory takes
keyword options only (e.g. ``vehicle``, ``form``), each with a default, and returns an
:class:`ObserverSet`. :func:`make_observer_set` calls one with the options given and refuses an
option the factory does not take.
"""

from __future__ import annotations

import inspect
import tempfile
import warnings
from collections.abc import Callable
from dataclasses import dataclass

from uvsym.codegen import targets
from uvsym.codegen.example import Example
from uvsym.codegen.package import Exported, write_package
from uvsym.codegen.precision import FLOAT_TOLERANCE, checked_float
from uvsym.errors import CodegenError, UnknownNameError

__all__ = ["ObserverSet", "make_observer_set", "option_flags", "options_of"]


@dataclass(frozen=True)
class ObserverSet:
    """A C package's worth of Functions: its C name, a one-line description, what it exports.

    citation: the reference of the method the set implements (written into the header, README
    and manifest; empty when it implements no published method). example: experiment data for
    one of its functions (:class:`~uvsym.codegen.example.Example`): ``main.c`` calls it, and a
    float build is measured on it.
    """

    package_name: str
    description: str
    exported: tuple[Exported, ...]
    citation: str = ""
    example: Example | None = None

    def __post_init__(self):
        if not self.exported or not all(isinstance(e, Exported) for e in self.exported):
            raise CodegenError(f"observer set {self.package_name}: exported must be a non-empty tuple of Exported")
        if self.example is not None and not isinstance(self.example, Example):
            raise CodegenError(f"observer set {self.package_name}: example must be an Example, "
                               f"not {type(self.example).__name__}")

    def write(self, out_dir, precision: str = "double", finite_check: bool = True,
              float_tolerance: float = FLOAT_TOLERANCE, target: str | None = None,
              budget: dict[str, int] | None = None, analysis_seconds: float | None = None) -> dict:
        """Write the C package into ``out_dir`` (:func:`uvsym.codegen.package.write_package`); the manifest.

        A float package is first run against double precision on the set's example
        (:func:`uvsym.codegen.precision.checked_float`) and refused with PrecisionError beyond
        ``float_tolerance``; its figure goes into the manifest (``float_check``). A set without an
        example is written in float with a warning that it was not measured.

        target: a name of :data:`uvsym.codegen.targets.TARGETS`; the package is first built and run
        for it in a scratch folder (:func:`uvsym.codegen.target_run.run_target`), its figures and
        its distance from Python go into the manifest (``target``) and README, what its harness printed
        into ``target/harness.out``, and a figure beyond
        ``budget`` (flash, ram, stack, instructions) refuses the package with BudgetError;
        ``analysis_seconds``: cppcheck's time limit on the target build (None: ``CPPCHECK_SECONDS``).
        """
        extra = {}
        if precision == "float":
            if self.example is None:
                warnings.warn(f"observer set {self.package_name}: the float build is not measured against double "
                              f"precision (the set gives no example data)", RuntimeWarning, stacklevel=2)
            else:
                exported = next((e for e in self.exported if e.function.name() == self.example.function), None)
                if exported is None:
                    raise CodegenError(f"observer set {self.package_name}: its example calls {self.example.function}, "
                                       f"which it does not export")
                extra["float_check"] = checked_float(exported, self.example, float_tolerance).to_dict(float_tolerance)
        chosen = printed = None
        if target is not None:
            chosen = targets.target(target)
            extra["target"], printed = self._measure_target(chosen, precision, finite_check, budget or {},
                                                            analysis_seconds)
        return write_package(out_dir, list(self.exported), self.package_name, precision, self.description,
                             citation=self.citation, example=self.example, finite_check=finite_check, extra=extra,
                             target=chosen, target_output=printed)

    def _measure_target(self, chosen, precision: str, finite_check: bool, budget: dict[str, int],
                        analysis_seconds: float | None) -> tuple[dict, str]:
        """The target figures of this set's package (``write``), checked against ``budget``, and what its
        harness printed."""
        from uvsym.codegen.target_run import check_budget, differences, run_target

        with tempfile.TemporaryDirectory(prefix="uvsym-target-") as scratch:
            functions = list(self.exported)
            write_package(scratch, functions, self.package_name, precision, finite_check=finite_check,
                          example=self.example, target=chosen)
            run = run_target(scratch, functions, self.package_name, precision, chosen, analysis_seconds)
        figures = run.figures
        vectors = targets.target_vectors(functions, self.example)
        for name, difference in differences(functions, vectors, run, precision).items():
            figures["functions"][name]["difference"] = float(f"{difference:.3g}")
        figures["difference_unit"] = ("ulp (2^-52) of each output's scale max(1, max|Python|)" if precision == "double"
                                      else "relative to each output's scale max(1, max|Python|)")
        check_budget(figures, budget)
        return figures, run.printed


def options_of(factory: Callable[..., ObserverSet]) -> tuple[str, ...]:
    """The keyword options a factory takes."""
    return tuple(name for name, p in inspect.signature(factory).parameters.items()
                 if p.kind in (p.KEYWORD_ONLY, p.POSITIONAL_OR_KEYWORD))


def option_flags(names) -> str:
    """Options as the command line spells them: ``--vehicle, --form`` (``none`` for none)."""
    return ", ".join("--" + name.replace("_", "-") for name in names) or "none"


def make_observer_set(name: str, factory: Callable[..., ObserverSet], **options) -> ObserverSet:
    """``factory(**options)`` of the set ``name``; UnknownNameError names an option it does not take."""
    known = options_of(factory)
    unknown = sorted(set(options) - set(known))
    if unknown:
        raise UnknownNameError(f"observer set {name!r} takes no option {option_flags(unknown)}; "
                               f"its options: {option_flags(known)}")
    made = factory(**options)
    if not isinstance(made, ObserverSet):
        raise CodegenError(f"observer set {name!r}: its factory returned {type(made).__name__}, not an ObserverSet")
    return made
