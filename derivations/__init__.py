"""Studies reproduced with uvsym: each module or package exposes ``DERIVATION`` (see :mod:`uvsym.derivation`)."""
