"""Assertions on certificates, for users' test suites and uvsym's own."""

from __future__ import annotations

import math
import re
from pathlib import Path

from uvsym.verify.certificate import Certificate

__all__ = ["assert_checked", "assert_proved", "assert_refuted", "assert_same_folder", "assert_same_text"]


def assert_proved(certificate: Certificate) -> None:
    """AssertionError (with the method and the reason) unless the claim was proved rigorously
    (numerical evidence, status ``checked``, is not a proof and fails)."""
    if certificate.status != "proved":
        raise AssertionError(f"not proved: {certificate.claim} over {certificate.set} by {certificate.method}: "
                             f"{certificate.status} {certificate.reason}".rstrip())


def assert_checked(certificate: Certificate) -> None:
    """AssertionError unless the claim was checked numerically (sampled, not proved, not refuted)."""
    if certificate.status != "checked":
        raise AssertionError(f"not checked: {certificate.claim} by {certificate.method}: {certificate.status} "
                             f"{certificate.reason}".rstrip())


def assert_refuted(certificate: Certificate) -> None:
    """AssertionError unless the claim was refuted with a counterexample."""
    if certificate.status != "refuted" or not certificate.counterexample:
        raise AssertionError(f"not refuted with a counterexample: {certificate.claim} ({certificate.status})")


_NUMBER = re.compile(r"(?<![A-Za-z0-9_.])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?![A-Za-z0-9_])")


def assert_same_text(built: str, committed: str, rtol: float = 1e-6, atol: float = 1e-9, what: str = "text") -> None:
    """AssertionError unless two texts (a report, an SVG, C source) agree: the same words and
    punctuation, and every number within ``atol + rtol |committed|`` (golden files that pass on
    any machine: rounding residues such as 1.1e-14 vs 1.4e-14 differ by less than atol)."""
    words_built, words_committed = _NUMBER.split(built), _NUMBER.split(committed)
    if words_built != words_committed:
        for i, (a, b) in enumerate(zip(words_built, words_committed)):
            if a != b:
                raise AssertionError(f"{what}: text differs near {a[:80]!r} vs {b[:80]!r} (after {i} numbers)")
        raise AssertionError(f"{what}: {len(words_built) - 1} numbers built, {len(words_committed) - 1} committed")
    for a, b in zip(_NUMBER.findall(built), _NUMBER.findall(committed)):
        if not math.isclose(float(a), float(b), rel_tol=rtol, abs_tol=atol):
            raise AssertionError(f"{what}: number {a} differs from the committed {b}")


def assert_same_folder(built, committed, rtol: float = 1e-6, atol: float = 1e-9) -> None:
    """:func:`assert_same_text` for every file under two folders, which must hold the same files.

    A manifest's SHA-256 of a serialised Function or of a file moves with the last bit of its
    constants, so SHA-256 strings (64 hex digits in quotes) are not compared.
    """
    built, committed = Path(built), Path(committed)
    files = sorted(p.relative_to(built) for p in built.rglob("*") if p.is_file())
    expected = sorted(p.relative_to(committed) for p in committed.rglob("*") if p.is_file())
    if files != expected:
        raise AssertionError(f"{built} holds {[str(f) for f in files]}, {committed} holds {[str(f) for f in expected]}")
    for relative in files:
        texts = [re.sub(r'"[0-9a-f]{64}"', '"<sha256>"', (root / relative).read_text())
                 for root in (built, committed)]
        assert_same_text(*texts, rtol=rtol, atol=atol, what=f"stale {relative}")
