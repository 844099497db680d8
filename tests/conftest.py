"""Shared fixtures: the reference data and the vehicle library."""

import json
from pathlib import Path

import pytest

REFERENCE_FILE = Path(__file__).resolve().parents[1] / "derivations" / "data" / "fossen_pvs_reference.json"


@pytest.fixture(scope="session")
def reference():
    """Fossen's Python Vehicle Simulator outputs for given states and inputs."""
    return json.loads(REFERENCE_FILE.read_text())


CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync"]


def _find_chromium():
    import shutil

    return next((path for name in ("chromium", "chromium-browser") if (path := shutil.which(name))), None)


def _install_chromium() -> str:
    """Install Debian's chromium where this runs as root with apt-get; the reason when it cannot."""
    import os
    import shutil
    import subprocess

    if shutil.which("apt-get") is None or os.geteuid() != 0:
        return "no chromium on PATH, and no apt-get as root to install Debian's package"
    env = {**os.environ, "DEBIAN_FRONTEND": "noninteractive"}
    for commands in ([["apt-get", "install", "-y", "-q", "chromium"]],
                     [["apt-get", "update", "-q"], ["apt-get", "install", "-y", "-q", "chromium"]]):
        if all(subprocess.run(c, env=env, capture_output=True, timeout=900).returncode == 0 for c in commands):
            return ""
    return "apt-get could not install chromium"


@pytest.fixture(scope="session")
def browser():
    """A headless Debian chromium driven by Playwright (installed here where possible, else skipped)."""
    playwright = pytest.importorskip("playwright.sync_api", reason="playwright is not installed (.[test] has it)")
    path = _find_chromium()
    if path is None:
        reason = _install_chromium()
        path = _find_chromium()
        if path is None:
            pytest.skip(reason or "chromium was installed but is not on PATH")
    with playwright.sync_playwright() as p:
        instance = p.chromium.launch(executable_path=path, args=CHROMIUM_ARGS)
        yield instance
        instance.close()
