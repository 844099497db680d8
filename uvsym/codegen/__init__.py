"""C code generation: generate sources from CasADi Functions, compile them, load them back."""

from uvsym.codegen.compile import compile_function, compile_roll, find_compiler

__all__ = ["compile_function", "compile_roll", "find_compiler"]
