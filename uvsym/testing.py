"""Assertions on certificates, for users' test suites and uvsym's own."""

from __future__ import annotations

from uvsym.verify.certificate import Certificate

__all__ = ["assert_proved", "assert_refuted"]


def assert_proved(certificate: Certificate) -> None:
    """AssertionError (with the method and the reason) unless the claim was proved."""
    if certificate.status != "proved":
        raise AssertionError(f"not proved: {certificate.claim} over {certificate.set} by {certificate.method}: "
                             f"{certificate.status} {certificate.reason}".rstrip())


def assert_refuted(certificate: Certificate) -> None:
    """AssertionError unless the claim was refuted with a counterexample."""
    if certificate.status != "refuted" or not certificate.counterexample:
        raise AssertionError(f"not refuted with a counterexample: {certificate.claim} ({certificate.status})")
