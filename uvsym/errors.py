"""Typed exceptions of uvsym.

Every error a user can cause is one of these, and its message names the problem
(the parameter, the input, the option) rather than pointing into CasADi.
"""

__all__ = [
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
    "VerificationError",
    "DerivationError",
    "CovarianceError",
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
    """Blocks cannot be joined into a loop (names the signal: unread, published twice, undriven
    plant input, algebraic loop)."""


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
