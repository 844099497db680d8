"""Every derivation's committed report is what the current code builds (numbers within tolerance)."""

from __future__ import annotations

import json

import pytest

from uvsym.derivation import load_derivations
from uvsym.testing import assert_same_folder, assert_same_text

DERIVATIONS = sorted(load_derivations())


def assert_close_json(ours, theirs, where: str) -> None:
    """Two parsed JSON documents agree: same keys and lengths, floats to 1e-7 relative (1e-12 absolute)."""
    if isinstance(theirs, dict):
        assert isinstance(ours, dict) and ours.keys() == theirs.keys(), f"{where}: keys differ"
        for key in theirs:
            assert_close_json(ours[key], theirs[key], f"{where}.{key}")
    elif isinstance(theirs, list):
        assert isinstance(ours, list) and len(ours) == len(theirs), f"{where}: lengths differ"
        for i, (a, b) in enumerate(zip(ours, theirs)):
            assert_close_json(a, b, f"{where}[{i}]")
    elif isinstance(theirs, float):
        assert ours == pytest.approx(theirs, rel=1e-7, abs=1e-12), f"stale {where}"
    else:
        assert ours == theirs, f"stale {where}"


def test_the_json_comparison_sees_a_changed_number_a_missing_key_and_a_changed_word():
    assert_close_json({"a": [1.0, {"b": "x"}]}, {"a": [1.0 + 1e-12, {"b": "x"}]}, "r")
    for ours in ({"a": [1.001, {"b": "x"}]}, {"a": [1.0, {}]}, {"a": [1.0, {"b": "y"}]}, {"a": [1.0]}):
        with pytest.raises(AssertionError):
            assert_close_json(ours, {"a": [1.0, {"b": "x"}]}, "r")


@pytest.mark.slow
@pytest.mark.parametrize("name", DERIVATIONS)
def test_committed_report_is_current(name, built_report, committed_reports):
    built, committed = built_report(name), committed_reports / name
    assert (committed / "report.md").exists(), f"reports/{name} is not committed"
    assert_same_text((built / "report.md").read_text(), (committed / "report.md").read_text(),
                     what=f"stale reports/{name}/report.md")
    if (committed / "results.json").exists():
        assert_close_json(json.loads((built / "results.json").read_text()),
                          json.loads((committed / "results.json").read_text()), f"reports/{name}/results.json")
    figures = sorted(p.name for p in committed.glob("*.svg"))
    assert figures == sorted(p.name for p in built.glob("*.svg")), f"reports/{name}: figures differ"
    for figure in figures:
        assert_same_text((built / figure).read_text(), (committed / figure).read_text(),
                         what=f"stale reports/{name}/{figure}")
    if (committed / "c").exists():
        assert_same_folder(built / "c", committed / "c")
