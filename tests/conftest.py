"""Shared fixtures: the reference data and the vehicle library."""

import json
from pathlib import Path

import pytest

REFERENCE_FILE = Path(__file__).resolve().parents[1] / "derivations" / "data" / "fossen_pvs_reference.json"


@pytest.fixture(scope="session")
def reference():
    """Fossen's Python Vehicle Simulator outputs for given states and inputs."""
    return json.loads(REFERENCE_FILE.read_text())
