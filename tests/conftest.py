"""Shared fixtures: the reference data, the reports as committed and as built (once per session), a browser."""

import io
import json
import shutil
import subprocess
import tarfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
REFERENCE_FILE = ROOT / "derivations" / "data" / "fossen_pvs_reference.json"


def pytest_configure(config):
    config.addinivalue_line("markers", "slow: builds a whole report or runs a long study (deselect with -m 'not slow')")


@pytest.fixture(scope="session")
def committed_reports(tmp_path_factory) -> Path:
    """reports/ as the last commit holds it (CI rebuilds the working tree's reports/ before the tests, so
    comparing with the working tree would compare the build with itself); the working tree's outside git."""
    if shutil.which("git") and (ROOT / ".git").exists():
        listed = subprocess.run(["git", "-C", str(ROOT), "ls-files", "reports"], capture_output=True, text=True)
        if listed.returncode == 0 and listed.stdout.strip():
            archive = subprocess.run(["git", "-C", str(ROOT), "archive", "HEAD", "reports"], capture_output=True,
                                     check=True)
            out = tmp_path_factory.mktemp("committed")
            with tarfile.open(fileobj=io.BytesIO(archive.stdout)) as tar:
                tar.extractall(out, **({"filter": "data"} if hasattr(tarfile, "data_filter") else {}))
            return out / "reports"
    return ROOT / "reports"


@pytest.fixture(scope="session")
def built_report(tmp_path_factory):
    """``built_report(name)``: the folder ``uvsym report name`` writes, built once per session; the
    working tree's reports/NAME when ``uvsym report`` built it from exactly this code (its build
    stamp's source fingerprint is the current one, as after the README's first command)."""
    from uvsym.cli import BUILD_STAMP, main
    from uvsym.derivation import derivation, source_fingerprint

    root, built = tmp_path_factory.mktemp("built"), {}

    def build(name: str) -> Path:
        if name not in built:
            stamp = ROOT / "reports" / name / BUILD_STAMP
            if stamp.exists() and json.loads(stamp.read_text()).get("source_fingerprint") == \
                    source_fingerprint(derivation(name)):
                built[name] = stamp.parent
            else:
                assert main(["report", name, "--out", str(root)]) == 0, f"uvsym report {name} failed"
                built[name] = root / name
        return built[name]

    return build


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
