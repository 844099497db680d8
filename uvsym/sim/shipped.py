"""The scenarios shipped with uvsym and with the installed derivations, found by name from their files:
neither the simulator nor a derivation is imported (``uvsym simulate NAME`` answers a misspelt name at once)."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

__all__ = ["every_shipped_scenario", "shipped_scenarios"]


def shipped_scenarios(kind: str = "vehicle") -> dict[str, Path]:
    """Example scenarios shipped with uvsym: name -> path; ``kind`` "vehicle" (``scenarios/``) or
    "plant" (scenarios over a registered plant, ``scenarios/plants/``)."""
    folder = resources.files("uvsym.sim") / "scenarios"
    folder = folder / "plants" if kind == "plant" else folder
    return {Path(str(p)).stem: Path(str(p)) for p in sorted(folder.iterdir(), key=str) if str(p).endswith(".toml")}


def every_shipped_scenario() -> dict[str, Path]:
    """Every scenario shipped by uvsym (vehicles, plants) and by the installed derivations: name -> path."""
    from uvsym.derivation import study_scenarios

    return {**shipped_scenarios(), **shipped_scenarios("plant"),
            **{name: file for name, (_, file) in study_scenarios().items()}}
