"""Every study's report renders its observers' equations as math, from the CasADi graph."""

import re

from derivations.motor_hybrid_observer.design import L1
from derivations.motor_hybrid_observer.text import observers_section as hybrid_section
from derivations.uio_zonotope.design import design as uio_design
from derivations.uio_zonotope.report import observers_section as uio_section
from derivations.usv_fukf_mmae.report import filters_section
from derivations.usv_fukf_mmae.scenario import read
from uvsym.report.html import markdown_to_html


def test_the_usv_report_shows_both_filters_in_their_structured_form():
    text = filters_section(read())
    assert text.count("**Model**") == 1  # the two filters share their model
    for part in ("Jacobians", "Prediction", "Gain", "Update"):
        assert text.count(f"**{part}**") == 2  # the UKF and the EKF
    assert r"K_k = P_{xz} P_{zz}^{-1}" in text and r"K_k = P_{k|k-1} H_k^{\top} S_k^{-1}" in text
    assert r"\dot{\alpha_{T,L}} = 0" in text  # the left model's efficiency state
    assert re.search(r"- \$F_\{\d,\d\}\$: (at least )?\d+ operations written out, more than the guard of 400", text)
    page = markdown_to_html(text, "usv", None)
    assert page.count("<math") >= 30 and "<details" in page


def test_the_hybrid_report_shows_each_observer_with_its_gains():
    text = hybrid_section()
    assert [line for line in text.splitlines() if line.startswith("**")] == [
        "**Hybrid detection observer (eqs. 5-6)** (`detection`)", "**Hybrid fault estimator (eq. 18)** (`estimator`)",
        "**Baseline UIO [11]** (`baseline`)", "**Corrected design (f_s as a constant state)** (`corrected`)"]
    detection = text.split("**Hybrid fault estimator")[0]
    assert rf"\dot{{\hat{{\omega}}_{{m}}}} = {L1:g} \omega_{{m}} - {L1:g} \hat{{\omega}}_{{m}}" in detection
    assert not re.search(r"\d \\cdot 10\^\{-1[3-9]\}", text)  # no rounding residues of T = I - H C
    assert markdown_to_html(text, "hybrid", None).count("<math") == text.count("$$") // 2


def test_the_uio_report_shows_every_bank_observer():
    bank = uio_design().bank.observers
    text = uio_section()
    assert all(f"{obs.name}" in text for obs in bank)
    per_observer = sum(obs.state.size + obs.publishes.size for obs in bank)
    assert text.count("$$") == 2 * per_observer
    assert markdown_to_html(text, "uio", None).count("<math") == per_observer
