"""The guides' code runs as written: in a folder holding a copy of examples/dc_motor/, each page's
``# file: NAME`` TOML blocks are written, its Python blocks run in one namespace, and every
``uvsym ...`` line of its sh blocks runs through the command's entry point and succeeds (a line for a
cross target skips, naming what is missing, where its toolchain is not installed)."""

from __future__ import annotations

import re
import shlex
import shutil
import sys
from pathlib import Path

import pytest

from uvsym.cli import main
from uvsym.codegen.target_run import missing_tools
from uvsym.codegen.targets import TARGETS

ROOT = Path(__file__).resolve().parents[1]
GUIDES = sorted((ROOT / "docs" / "guides").glob("*.md"))
BLOCK = re.compile(r"^```(\w+)\n(.*?)^```", re.M | re.S)


def test_every_guide_is_in_the_guides_index():
    index = (ROOT / "docs" / "guides" / "index.md").read_text()
    listed = re.search(r"```\{toctree\}\n(.*?)```", index, re.S).group(1).splitlines()
    pages = sorted(p.stem for p in GUIDES if p.stem != "index")
    assert sorted(n for n in listed if n and not n.startswith(":")) == pages


@pytest.mark.slow
@pytest.mark.parametrize("page", [p for p in GUIDES if p.stem != "index"], ids=lambda p: p.stem)
def test_the_guide_runs_as_written(page, tmp_path, monkeypatch, capsys):
    shutil.copytree(ROOT / "examples" / "dc_motor", tmp_path / "dc_motor")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "path", [str(tmp_path / "dc_motor"), *sys.path])
    namespace: dict = {"__name__": "guide"}
    ran = 0
    for index, (language, code) in enumerate(BLOCK.findall(page.read_text()), 1):
        where = f"docs/guides/{page.name}, code block {index}"
        if language == "toml" and code.startswith("# file: "):
            name = code.split("\n", 1)[0].removeprefix("# file: ").strip()
            (tmp_path / name).write_text(code)
        elif language == "python":
            exec(compile(code, where, "exec"), namespace)  # noqa: S102
            ran += 1
        elif language == "sh":
            for line in code.splitlines():
                if line.startswith("uvsym "):
                    _needs_the_target_of(shlex.split(line))
                    assert main(shlex.split(line)[1:]) == 0, f"{where}: {line}\n{capsys.readouterr().err[-3000:]}"
                    ran += 1
    assert ran, f"{page.name} has no code that runs"
    assert capsys.readouterr().out.strip()


def _needs_the_target_of(words: list[str]) -> None:
    """Skip, naming the missing tools, a command whose ``--target`` toolchain is not installed."""
    if "--target" in words:
        missing = missing_tools(TARGETS[words[words.index("--target") + 1]])
        if missing:
            pytest.skip(f"{', '.join(missing)} not installed (scripts/install-arm-toolchain.sh installs them)")
