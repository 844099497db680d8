"""Typed exceptions of uvsym.

Every error a user can cause is one of these, and its message names the problem
(the parameter, the input, the option) rather than pointing into CasADi.
"""

__all__ = [
    "did_you_mean",
    "UvsymError",
    "ModelError",
    "KinematicsError",
    "ConfigurationError",
    "IdentifiabilityError",
    "UnknownNameError",
    "FaultError",
    "ScenarioError",
    "SimulationError",
    "ObserverError",
    "WiringError",
    "CodegenError",
    "PrecisionError",
    "VerificationError",
    "DerivationError",
    "CovarianceError",
    "ArgumentError",
    "PathError",
    "FileFormatError",
    "SetError",
    "SetDivergenceError",
    "UIOConditionError",
    "StepSizeWarning",
    "IntegrationAccuracyWarning",
    "CampaignError",
    "CampaignSizeError",
    "ExecutorError",
]


class UvsymError(Exception):
    """Base class of every uvsym error."""


class ModelError(UvsymError, ValueError):
    """A vehicle model cannot be built from the parameters given (names the parameter)."""


class KinematicsError(UvsymError, ValueError):
    """A kinematic transformation is undefined at the requested state (e.g. theta = +-90 deg)."""


class ConfigurationError(UvsymError, ValueError):
    """An actuator configuration is malformed (sizes, angles, positions)."""


class IdentifiabilityError(UvsymError, ValueError):
    """Actuator values cannot be recovered from generalised forces for this configuration."""


class FaultError(UvsymError, ValueError):
    """A fault or its time profile is malformed (kind, value, onset, target index)."""


class ScenarioError(UvsymError, ValueError):
    """A scenario is invalid; the message names the field (e.g. ``faults[1].kind``)."""


class SimulationError(UvsymError, RuntimeError):
    """A simulation cannot run or failed (bad method or grid, non-finite state, integrator failure)."""


class ObserverError(UvsymError, ValueError):
    """An observer cannot be built or run as asked (unobservable channel, bad gain, wrong sizes)."""


class WiringError(UvsymError, ValueError):
    """Blocks cannot be joined into a loop (names the signal: unread, ambiguous, undriven plant
    input, algebraic loop)."""


class CodegenError(UvsymError, RuntimeError):
    """C code could not be generated, compiled or loaded (names the compiler command and its output)."""


class VerificationError(UvsymError, ValueError):
    """A claim cannot be checked as posed (unsupported operation, malformed region, wrong sizes)."""


class DerivationError(UvsymError, TypeError):
    """An installed derivation is malformed: its entry point, or the Derivation it names."""


class UnknownNameError(UvsymError, KeyError):
    """A vehicle, derivation or option name is not known; the message lists the known ones."""

    def __str__(self) -> str:  # KeyError quotes its argument; keep the message readable
        return str(self.args[0]) if self.args else ""


class CovarianceError(ObserverError):
    """A covariance is not symmetric positive definite: an argument (``P0``, ``Q``, ``R``, named)
    or a filter's own covariance during a run (names the filter, the sample and its time)."""


class ArgumentError(UvsymError, ValueError):
    """A Model's, System's or Observer's Function was called with an argument of the wrong size,
    an unknown name or non-finite values, or gives non-finite outputs there (names the argument
    and the entry); or a Function evaluated in place (:class:`~uvsym.evaluation.InPlace`) was given
    the wrong arguments or failed (names the Function)."""


class PathError(UvsymError, OSError):
    """A file or folder cannot be written or read as asked: missing, not a folder, not writable, an
    existing file not to be overwritten, or a folder holding files uvsym did not write (names the path)."""


class FileFormatError(UvsymError, ValueError):
    """A file's content is not what uvsym writes in that format (names the path and what is wrong)."""


class StepSizeWarning(UserWarning):
    """An adaptive filter's step size is at or beyond its stability bound (the message gives the bound)."""


class IntegrationAccuracyWarning(UserWarning):
    """The fast method's fixed-step RK4 misses its tolerance on sampled steps (the message gives the
    substeps that would meet it)."""


class SetError(UvsymError, ValueError):
    """A set operation cannot be done as asked (non-conforming sizes, a non-finite or negative bound,
    a reduction order below the dimension); the message names the argument."""


class SetDivergenceError(SetError):
    """A propagated enclosure keeps growing past a sound bound (an unstable map, or reduction wrapping)."""


class UIOConditionError(ObserverError):
    """An unknown-input observer does not exist for the matrices given: ``rank(C D) != rank(D)`` or
    ``(C, T A)`` not detectable; ``ranks`` and ``eigenvalues`` hold the evidence."""

    def __init__(self, message: str, *, ranks: tuple[int, int] | None = None, eigenvalues: tuple = ()):
        super().__init__(message)
        self.ranks = ranks
        self.eigenvalues = tuple(eigenvalues)


class PrecisionError(CodegenError):
    """A single-precision C build strays too far from double precision on its example data (names the figure)."""


class DiagnosisError(ObserverError):
    """A diagnosis setting is out of range or names an unknown observer, actuator, kind or channel
    (the message names the field, e.g. ``diagnosis.window_s``)."""


class CampaignError(ScenarioError):
    """A campaign file is invalid: a case, an axis, a draw or one of its runs' scenarios (names the
    case and the field, e.g. ``case 'thruster': grid axis 'faults[0].onset'``)."""


class CampaignSizeError(CampaignError):
    """A campaign has more runs than its ``max_runs`` and was not confirmed (gives both figures)."""


class ExecutorError(SimulationError):
    """A campaign's executor cannot run: an unreachable scheduler (names the address) or a missing
    optional dependency (names the extra to install)."""


def did_you_mean(name: str, known) -> str:
    """`` (did you mean 'x'?)`` with the closest of ``known`` to a misspelt ``name``, or "" when none is close."""
    import difflib

    near = difflib.get_close_matches(name, [str(k) for k in known], n=1)
    return f" (did you mean {near[0]!r}?)" if near else ""
