"""The mutation driver's bookkeeping (benchmarks/mutation.py) and the equivalents file it reads: an entry excuses
only its own mutant, or the same change renumbered within the same function; every entry says why."""

import importlib.util
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("mutation_driver", ROOT / "benchmarks" / "mutation.py")
mutation = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(mutation)

ENTRY = {"mutant": "uvsym.m.x_f__mutmut_7", "change": "return a >= b", "reason": "a tie gives the same answer"}
EQUIVALENTS = {ENTRY["mutant"]: ENTRY}


def test_an_entry_excuses_its_own_mutant_only_while_the_diff_shows_its_change():
    assert mutation._justifying("uvsym.m.x_f__mutmut_7", "-    return a > b\n+    return a >= b", EQUIVALENTS) \
        == "uvsym.m.x_f__mutmut_7"
    assert mutation._justifying("uvsym.m.x_f__mutmut_7", "-    return a > b\n+    return a < b", EQUIVALENTS) is None


def test_a_renumbered_mutant_is_excused_by_the_same_change_in_the_same_function_only():
    moved = "-    return a > b\n+    return a >= b"
    assert mutation._justifying("uvsym.m.x_f__mutmut_9", moved, EQUIVALENTS) == "uvsym.m.x_f__mutmut_7"
    assert mutation._justifying("uvsym.m.x_g__mutmut_7", moved, EQUIVALENTS) is None  # another function
    assert mutation._justifying("uvsym.m.x_f__mutmut_9", "-    return a >= b\n+    return a > b", EQUIVALENTS) is None
    # the change must be the whole added line, not a part of it
    assert mutation._justifying("uvsym.m.x_f__mutmut_9", "-    return a > b\n+    return a >= b or c",
                                EQUIVALENTS) is None


def test_every_equivalent_names_one_mutant_of_a_mutated_module_with_its_change_and_a_reason():
    entries = tomllib.loads((ROOT / "tests" / "mutation_equivalents.toml").read_text())["equivalent"]
    names = [e["mutant"] for e in entries]
    assert len(names) == len(set(names)), "an equivalent is listed twice"
    for entry in entries:
        assert set(entry) == {"mutant", "change", "reason"}, entry["mutant"]
        assert entry["change"].strip() and len(entry["reason"]) > 15, entry["mutant"]
        module = mutation._function_of(entry["mutant"]).rsplit(".", 1)[0]
        assert (ROOT / (module.replace(".", "/") + ".py")).is_file(), f"{entry['mutant']}: no module {module}"
