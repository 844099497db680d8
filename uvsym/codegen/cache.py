"""Compiled libraries kept between runs, named by the SHA-256 of everything that determines them.

The key hashes the serialised CasADi Function, the extra C source compiled with it, the compiler
flags, the compiler's identity (first line of ``cc --version``), the processor (``-march=native``
builds for it: a cache folder shared between machines keeps one library per processor) and the
CasADi version, so a library is reused only when it would be compiled again byte for byte. The folder is
``$UVSYM_CACHE_DIR``, else ``$XDG_CACHE_HOME/uvsym``, else ``~/.cache/uvsym``; deleting it (or any
file in it) is always safe. A library is compiled under a temporary name and moved into place with
``os.replace``, so two processes compiling the same key at once both end with a whole library.
An unwritable folder falls back to this process's temporary build folder, with a warning.

Within a process, :func:`memoized` keeps the results of pure builders (symbolic loops, observers,
loaded libraries) keyed by the value of their arguments (:func:`frozen`), so a rerun redoes nothing.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import itertools
import os
import platform
import subprocess
import threading
import warnings
from collections import OrderedDict
from collections.abc import Mapping
from pathlib import Path
from typing import Callable

import casadi as ca
import numpy as np

__all__ = ["CACHE_ENV", "cache_dir", "library_key", "cached_library", "clear_memos", "frozen", "memoized"]

CACHE_ENV = "UVSYM_CACHE_DIR"
_COUNTER = itertools.count()
_WARNED: set[str] = set()
_MEMOS: list = []  # every memoized function's cache, for clear_memos()


def cache_dir() -> Path:
    """``$UVSYM_CACHE_DIR``, else ``$XDG_CACHE_HOME/uvsym``, else ``~/.cache/uvsym`` (not created here)."""
    if os.environ.get(CACHE_ENV):
        return Path(os.environ[CACHE_ENV]).expanduser()
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base).expanduser() / "uvsym"


@functools.lru_cache(maxsize=None)
def _compiler_identity(compiler: str) -> str:
    """First line of ``compiler --version`` ('' when it prints nothing)."""
    done = subprocess.run([compiler, "--version"], capture_output=True, text=True)
    return (done.stdout.strip().splitlines() or [""])[0]


@functools.lru_cache(maxsize=None)
def _processor() -> str:
    """The processor's model and feature flags (Linux's /proc/cpuinfo), else what platform knows of it."""
    try:
        with open("/proc/cpuinfo") as handle:
            lines = [line for line in handle if line.startswith(("model name", "flags", "Features", "CPU part"))]
        if lines:
            return "".join(dict.fromkeys(lines))
    except OSError:
        pass
    return f"{platform.machine()} {platform.processor()} {platform.platform()}"


def machine_identity(compiler: str) -> tuple[str, ...]:
    """What a compiled library depends on besides its source and flags: the compiler's path and version, the
    processor (model and feature flags) and CasADi's version."""
    return compiler, _compiler_identity(compiler), _processor(), ca.__version__


def library_key(f: ca.Function, extra_source: str, flags: tuple[str, ...], compiler: str) -> str:
    """Hex SHA-256 of ``f.serialize()``, ``extra_source``, ``flags`` and :func:`machine_identity`."""
    digest = hashlib.sha256()
    for part in (f.serialize(), extra_source, "\0".join(flags), *machine_identity(compiler)):
        digest.update(part.encode() if isinstance(part, str) else bytes(part))
        digest.update(b"\0\1\0")
    return digest.hexdigest()


def cached_library(key: str, build: Callable[[Path], None], fallback: Path) -> Path:
    """The library for ``key`` in the cache folder, calling ``build(path)`` to compile it there first when
    it is missing. ``fallback``: the folder used (with a warning) when the cache folder cannot be written."""
    folder = cache_dir()
    try:
        folder.mkdir(parents=True, exist_ok=True)
        if not os.access(folder, os.W_OK | os.X_OK):
            raise PermissionError(f"{folder} is not writable")
    except OSError as exc:
        if str(folder) not in _WARNED:
            _WARNED.add(str(folder))
            warnings.warn(f"compile cache folder unusable ({exc}); compiling into a temporary folder instead "
                          f"(set ${CACHE_ENV} to a writable folder)", stacklevel=4)
        folder = fallback
    library = folder / f"{key}.so"
    if library.exists():
        return library
    partial = folder / f"{key}.{os.getpid()}.{next(_COUNTER)}.part"
    try:
        build(partial)
        os.replace(partial, library)
    finally:
        partial.unlink(missing_ok=True)
    return library


class _Same:
    """Hashable stand-in for an object compared by identity (held, so its id is not reused while cached)."""

    __slots__ = ("value",)

    def __init__(self, value):
        self.value = value

    def __hash__(self):
        return id(self.value)

    def __eq__(self, other):
        return isinstance(other, _Same) and other.value is self.value


def frozen(value):
    """A hashable key equal for equal values: numbers (floats bit for bit, by ``float.hex``), strings,
    arrays (dtype, shape, bytes), sequences, mappings (in order) and dataclasses (type and fields) by
    value, recursively; anything else (CasADi Functions, callables, other objects) by identity."""
    if value is None or isinstance(value, (bool, str, bytes)):
        return value
    if isinstance(value, (int, np.integer)):
        return ("i", int(value))
    if isinstance(value, (float, np.floating)):
        return ("f", float(value).hex())
    if isinstance(value, np.ndarray):
        return ("a", value.dtype.str, value.shape, value.tobytes())
    if isinstance(value, (tuple, list)):
        return (type(value).__name__, tuple(frozen(v) for v in value))
    if isinstance(value, Mapping):
        return ("m", _Same(type(value)), tuple((frozen(k), frozen(v)) for k, v in value.items()))
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return ("d", _Same(type(value)), tuple(frozen(getattr(value, f.name)) for f in dataclasses.fields(value)))
    return _Same(value)


def memoized(maxsize: int, key=None):
    """Decorator: keep the results of the last ``maxsize`` distinct calls, keyed by :func:`frozen` of the
    arguments (so a changed parameter, gain or fault is a new call), or of ``key(*args, **kwargs)``: what the
    builder reads of them, where freezing a whole argument would cost more than it saves. For pure builders
    of immutable results; ``f.cache_clear()`` empties the memo."""
    key_of = key

    def decorate(function):
        cache: OrderedDict = OrderedDict()
        lock = threading.Lock()  # threads may share the memo; a build runs outside the lock

        @functools.wraps(function)
        def wrapper(*args, **kwargs):
            key = frozen(key_of(*args, **kwargs) if key_of else (args, tuple(sorted(kwargs.items()))))
            with lock:
                if key in cache:
                    cache.move_to_end(key)
                    return cache[key]
            result = function(*args, **kwargs)
            with lock:
                cache[key] = result
                if len(cache) > maxsize:
                    cache.popitem(last=False)
            return result

        wrapper.cache_clear = cache.clear
        _MEMOS.append(cache)
        return wrapper

    return decorate


def clear_memos() -> None:
    """Empty every :func:`memoized` function's memo (the next call builds again; the on-disk compile cache stays)."""
    for cache in _MEMOS:
        cache.clear()
