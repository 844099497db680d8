"""Unit checks of the C package writer: the unused-parameter marks on CasADi's code, the header's guard,
description and citation, the return codes a wrapper documents, the manifest's arguments, digests and stale
files, the float build's literals and math calls. Expected texts are written out by hand from the module
docstring and C's rules."""

from __future__ import annotations

import hashlib
import subprocess

import casadi as ca
import pytest

from uvsym.codegen import find_compiler
from uvsym.codegen.arguments import Entries
from uvsym.codegen.example import Example
from uvsym.codegen.package import Exported, _silence_unused, _single_precision, write_package
from uvsym.errors import CodegenError


def _halve() -> Exported:
    """halve: x (2,) -> y = x / 2 (2,); x documented per entry, y by one line of text."""
    x = ca.SX.sym("x", 2)
    function = ca.Function("halve", [x], [x / 2], ["x"], ["y"])
    return Exported(function, (Entries("x", ("a", "b"), ("m", "s")),), ("y (m, s)",), "halve")


def _twice() -> Exported:
    x = ca.SX.sym("x", 2)
    return Exported(ca.Function("twice", [x], [2 * x], ["x"], ["y"]), ("x",), ("y",), "doubles x")


# --- _silence_unused ------------------------------------------------------------------------------------------


def test_unused_work_parameters_are_marked_whichever_side_the_star_is_on():
    source = ("static int f(const casadi_real **arg, casadi_real **res, casadi_int *iw, casadi_real *w, int mem) {\n"
              "  return 0;\n}\n")
    expected = ("static int f(const casadi_real **arg, casadi_real **res, casadi_int *iw, casadi_real *w, int mem) {\n"
                "  (void)iw; (void)w; (void)mem;\n  return 0;\n}\n")
    assert _silence_unused(source) == expected


def test_the_parameter_name_is_the_last_word_of_a_declaration_spaced_around_its_star():
    source = "CASADI_SYMBOL_EXPORT int g(const casadi_real * w) {\n  return 0;\n}\n"
    assert _silence_unused(source) == ("CASADI_SYMBOL_EXPORT int g(const casadi_real * w) {\n  (void)w;\n"
                                       "  return 0;\n}\n")


def test_only_parameters_named_exactly_iw_w_or_mem_are_marked():
    source = "static int h(casadi_real *Xw, casadi_int *Xmem, int Xiw) {\n  return 0;\n}\n"
    assert _silence_unused(source) == source  # Xw is not w: nothing to mark, nothing added


def test_functions_without_work_parameters_are_left_as_they_are():
    source = ("static int none(void) {\n  return 0;\n}\n"
              "static int empty() {\n  return 1;\n}\n"
              "static casadi_real sq(casadi_real x) {\n  return x*x;\n}\n")
    assert _silence_unused(source) == source


@pytest.mark.skipif(find_compiler() is None, reason="no C compiler (set $CC or install gcc)")
def test_a_marked_function_compiles_with_unused_parameter_warnings_as_errors(tmp_path):
    source = ("typedef double casadi_real;\n"
              "static int f(const casadi_real **arg, casadi_real **res, long *iw, casadi_real *w, int mem) {\n"
              "  res[0][0] = arg[0][0];\n  return 0;\n}\n"
              "int call(const casadi_real **arg, casadi_real **res) {\n  return f(arg, res, 0, 0, 0);\n}\n")
    flags = [find_compiler(), "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-c", "-o",
             str(tmp_path / "f.o")]
    for text, compiles in ((source, False), (_silence_unused(source), True)):
        (tmp_path / "f.c").write_text(text)
        done = subprocess.run([*flags, str(tmp_path / "f.c")], capture_output=True, text=True)
        assert (done.returncode == 0) == compiles, done.stderr
        assert compiles or "unused parameter" in done.stderr


# --- _single_precision -----------------------------------------------------------------------------------------


def test_float_literals_get_their_suffix_and_out_of_range_ones_the_nearest_float_bound():
    source = ("a1=2.; a2=8.3333333333333329e-02; a3=-1.0000000000000001e+300; a4=1.0000000000000000e-300; "
              "a5=0.; a6=(2.*a5); a7=1e5;")
    assert _single_precision(source) == ("a1=2.f; a2=8.3333333333333329e-02f; a3=-3.40282347e+38f; "
                                         "a4=1.17549435e-38f; a5=0.f; a6=(2.f*a5); a7=1e5f;")


def test_math_calls_become_their_float_twins_and_nothing_else_is_renamed():
    source = "/* CasADi 3.8.2. */ x=sqrt(a)+exp (b)+atan2(a,b); y=casadi_fmax(a,b); z=fmax(a,b); w=my_sin(a); v=a12;"
    assert _single_precision(source) == ("/* CasADi 3.8.2. */ x=sqrtf(a)+expf (b)+atan2f(a,b); y=casadi_fmax(a,b); "
                                         "z=fmaxf(a,b); w=my_sin(a); v=a12;")


@pytest.mark.skipif(find_compiler() is None, reason="no C compiler (set $CC or install gcc)")
def test_a_float_package_keeps_a_guard_against_zero_that_float_cannot_hold(tmp_path):
    """y = sqrt(x) / max(x, 1e-300): 0 at x = 0 in double; 1e-300 is 0 in float (0/0 = NaN) unless it
    becomes float's smallest normal number."""
    x = ca.SX.sym("x")
    function = ca.Function("guarded", [x], [ca.sqrt(x) / ca.fmax(x, 1e-300)], ["x"], ["y"])
    write_package(tmp_path, [Exported(function, ("x (-)",), ("y (-)",), "guarded")], "tiny", "float",
                  finite_check=False)
    assert "sqrtf(" in (tmp_path / "src" / "tiny_casadi.c").read_text()
    (tmp_path / "main.c").write_text('#include <stdio.h>\n#include "tiny.h"\nint main(void) {\n'
                                     '  tiny_real x[1] = {0.0f}, y[1];\n  int rc = tiny_guarded(x, y);\n'
                                     '  printf("%d %g\\n", rc, (double)y[0]);\n  return 0;\n}\n')
    exe = tmp_path / "main"
    done = subprocess.run([find_compiler(), "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-I",
                           str(tmp_path / "include"), str(tmp_path / "main.c"), str(tmp_path / "src" / "tiny_casadi.c"),
                           str(tmp_path / "src" / "tiny.c"), "-o", str(exe), "-lm"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert subprocess.run([str(exe)], capture_output=True, text=True).stdout.split() == ["0", "0"]


# --- header -----------------------------------------------------------------------------------------------------


def test_the_header_is_guarded_by_the_upper_case_name_and_falls_back_to_the_name(tmp_path):
    write_package(tmp_path, [_halve()], "tiny")
    header = (tmp_path / "include" / "tiny.h").read_text()
    assert header.startswith("/* tiny: wrapper API generated by uvsym. Precision: double.\n"
                             "   Units in brackets; README.md describes the API. */\n"
                             "#ifndef TINY_H\n#define TINY_H\n\ntypedef double tiny_real;\n")
    assert header.endswith("\n#endif /* TINY_H */\n")
    assert "Implements" not in header


def test_the_description_and_citation_head_the_header_and_fill_the_manifest(tmp_path):
    manifest = write_package(tmp_path, [_halve()], "tiny", "float", "Halves", citation="A. Author (2001)")
    header = (tmp_path / "include" / "tiny.h").read_text()
    assert header.startswith("/* Halves: wrapper API generated by uvsym. Precision: float.\n"
                             "   Implements: A. Author (2001)\n   Units in brackets; README.md describes the API. */\n")
    assert manifest["description"] == "Halves" and manifest["citation"] == "A. Author (2001)"


def test_description_and_citation_default_to_empty(tmp_path):
    manifest = write_package(tmp_path, [_halve()], "tiny")
    assert manifest["description"] == "" and manifest["citation"] == ""


def test_without_the_finite_check_a_wrapper_documents_two_return_codes(tmp_path):
    write_package(tmp_path, [_halve()], "tiny", finite_check=False)
    header = (tmp_path / "include" / "tiny.h").read_text()
    assert " * Returns TINY_OK or TINY_EVAL_FAILED.\n * Uses static work buffers: not reentrant. */\n" in header
    assert "NONFINITE_INPUT or" not in header


# --- manifest ---------------------------------------------------------------------------------------------------


def test_manifest_arguments_carry_entries_and_units_or_only_their_line_of_text(tmp_path):
    manifest = write_package(tmp_path, [_halve()], "tiny")
    function = manifest["functions"][0]
    assert function["inputs"] == [{"name": "x", "size": 2, "what": "x", "unit": "x: a (m), b (s)",
                                   "entries": ["a", "b"], "units": ["m", "s"]}]
    assert function["outputs"] == [{"name": "y", "size": 2, "what": "y (m, s)", "unit": "y (m, s)",
                                    "entries": None, "units": None}]


def test_manifest_gives_the_sha256_of_each_serialised_function(tmp_path):
    """The digest (module docstring: SHA-256 of each serialised Function) tells different functions apart."""
    exported = [_halve(), _twice()]
    manifest = write_package(tmp_path, exported, "pkg")
    digests = [f["sha256"] for f in manifest["functions"]]
    assert digests == [hashlib.sha256(e.function.serialize().encode()).hexdigest() for e in exported]
    assert all(len(d) == 64 for d in digests) and digests[0] != digests[1]


def test_an_example_of_an_unknown_function_names_the_package_functions(tmp_path):
    example = Example("thrice", ([[1.0, 2.0]],), "by hand")
    with pytest.raises(CodegenError, match=r"^package pkg: the example calls thrice, not one of halve, twice$"):
        write_package(tmp_path / "pkg", [_halve(), _twice()], "pkg", example=example)


def test_rewriting_removes_the_files_of_the_earlier_package_only(tmp_path):
    write_package(tmp_path, [_halve()], "old")
    (tmp_path / "notes.txt").write_text("mine")
    manifest = write_package(tmp_path, [_halve()], "new")
    for stale in ("include/old.h", "include/old_casadi.h", "src/old.c", "src/old_casadi.c"):
        assert not (tmp_path / stale).exists(), stale
    assert all((tmp_path / rel).is_file() for rel in manifest["files"])
    assert {"include/new.h", "src/new.c", "main.c"} <= set(manifest["files"])
    assert (tmp_path / "notes.txt").read_text() == "mine"
