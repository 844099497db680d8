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


@pytest.fixture(scope="session")
def browser():
    """A headless Debian chromium driven by Playwright; skipped, with the reason, where there is none
    (``scripts/install-test-browser.sh`` installs it, as ``.ci/run`` does)."""
    playwright = pytest.importorskip("playwright.sync_api", reason="playwright is not installed (.[test] has it)")
    path = _find_chromium()
    if path is None:
        pytest.skip("no chromium on PATH (scripts/install-test-browser.sh installs Debian's package as root)")
    with playwright.sync_playwright() as p:
        instance = p.chromium.launch(executable_path=path, args=CHROMIUM_ARGS)
        yield instance
        instance.close()
