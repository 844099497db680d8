"""Pieces every report shares: the claims table (statement, set, method, status, margin) and matrices."""

from uvsym.report.html import markdown_to_html
from uvsym.report.markdown import latex_matrix
from uvsym.report.sections import claims_table

ROWS = [{"claim": "decay at 20 1/s", "set": "the linearisation", "method": "LMI, re-checked exactly",
         "status": "proved", "expected": "proved", "margin": 0.000347},
        {"claim": "negative control", "set": "a vertex", "method": "Routh-Hurwitz", "status": "proved",
         "expected": "refuted", "margin": None}]


def test_the_claims_table_has_the_five_columns_and_flags_an_unexpected_status():
    header, rule, first, second = claims_table(ROWS).splitlines()
    assert [c.strip() for c in header.strip("|").split("|")] == ["statement", "set", "method", "status", "margin"]
    assert rule == "|---|---|---|---|---|"
    assert [c.strip() for c in first.strip("|").split("|")] == ["decay at 20 1/s", "the linearisation",
                                                               "LMI, re-checked exactly", "proved", "0.000347"]
    assert [c.strip() for c in second.strip("|").split("|")][3:] == ["**proved** (expected refuted)", "-"]


def test_a_matrix_writes_its_exponents_as_powers_of_ten():
    tex = latex_matrix([[2.49e-9, 0.0], [1.5, -3.2e-5]], 3)
    assert tex == r"\begin{bmatrix} 2.49 \cdot 10^{-9} & 0 \\ 1.5 & -3.2 \cdot 10^{-5} \end{bmatrix}"
    assert "<msup><mn>10</mn>" in markdown_to_html(f"$$ Q = {tex} $$", "matrix", None)
