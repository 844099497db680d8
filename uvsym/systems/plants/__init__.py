"""Plants beyond the marine vehicles, one module each with its parameters in a TOML file beside it.

Every module exposes ``NAME``, ``DESCRIPTION`` and ``build(**overrides) -> System``; the registry
is :mod:`uvsym.systems.registry`.
"""
