"""Where numba keeps each package's compiled code, so that it is never stale.

numba's on-disk cache (``cache=True``) is keyed on the source file of each function only: a
kernel inlined into a caller from another module (every force kernel is, in the dispatcher)
would keep its old machine code after an edit or an upgrade. So a package's compiled code
lives in a directory named after a hash of the sources it is built from: the engine's of the
engine's sources alone, the game's of the engine's and the game's (its frame inlines engine
kernels). An edit to the game leaves the engine's compiled code in place; an edit to the
engine selects fresh directories for both. Only functions defined by the package's modules use
it: numba's setting is switched while they are imported and restored afterwards.

    with project_cache("spacewar"):
        from . import core            # compiled into (or loaded from) the game's directory
"""
import contextlib
import functools
import hashlib
import os
import shutil
import time
from pathlib import Path

_ROOT = Path(__file__).resolve().parent.parent

#: package -> the packages whose sources its compiled code is built from
SOURCES = {"engine": ("engine",), "spacewar": ("engine", "spacewar"),
           "validation": ("engine", "validation")}


def _check_package(package):
    if package not in SOURCES:
        raise ValueError(f"package must be one of {', '.join(SOURCES)}, got {package!r}")
    return package


@functools.lru_cache(maxsize=None)
def source_hash(package="engine"):
    """A hash of the sources ``package``'s compiled code is built from (read once)."""
    digest = hashlib.sha1()
    for name in SOURCES[_check_package(package)]:
        for path in sorted((_ROOT / name).rglob("*.py")):
            digest.update(str(path.relative_to(_ROOT)).encode())
            digest.update(path.read_bytes())
    return digest.hexdigest()[:16]


@functools.lru_cache(maxsize=None)
def numpy_dot_kind():
    """How numpy's ``a @ b`` of two float64 2-vectors rounds on this machine: ``"fused"``
    (``fma(a1, b1, a0 b0)``, OpenBLAS's ddot kernel on CPUs it gives FMA kernels, e.g.
    SkylakeX), ``"plain"`` (``a0 b0 + a1 b1``, e.g. its Haswell kernel on an AMD EPYC) or
    ``"other"``. Measured once on 256 fixed pairs against the exact fused value (fractions).
    Compiled code that mirrors numpy's arithmetic (``spacewar.compiled_bots.dot_blas``)
    is compiled for the kind found, and the game's compiled-code directory is named by it."""
    from fractions import Fraction

    import numpy as np

    rng = np.random.default_rng(20261202)
    a, b = rng.normal(size=(256, 2)), rng.normal(size=(256, 2))
    plain = fused = 0
    for x, y in zip(a.tolist(), b.tolist()):
        got = float(np.array(x) @ np.array(y))
        head = x[0] * y[0]
        plain += got == head + x[1] * y[1]
        fused += got == float(Fraction(x[1]) * Fraction(y[1]) + Fraction(head))
    return "fused" if fused == len(a) else "plain" if plain == len(a) else "other"


KEEP = 6  # compiled-code directories kept (for the sources seen most recently) ...
MIN_AGE = 24 * 3600  # ... and none younger than a day is removed (a long run may be using it)


def cache_dir(package="engine"):
    """The directory of ``package``'s compiled code for the current sources."""
    base = os.environ.get("NUMBA_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache"),
        "nbody-spacewar")
    if package == "spacewar":  # its bots mirror numpy's dot, which rounds by machine
        return os.path.join(base, f"numba-{package}-{source_hash(package)}{numpy_dot_kind()[0]}")
    return os.path.join(base, f"numba-{package}-{source_hash(package)}")


def prune(current):
    """Remove all but the most recently used compiled-code directories of the same package
    beside ``current``."""
    parent = os.path.dirname(current)
    prefix = os.path.basename(current).rsplit("-", 1)[0] + "-"
    try:
        entries = [os.path.join(parent, d) for d in os.listdir(parent) if d.startswith(prefix)]
        entries.sort(key=os.path.getmtime, reverse=True)
    except OSError:
        return
    now = time.time()
    for old in entries[KEEP:]:
        try:
            stale = now - os.path.getmtime(old) > MIN_AGE
        except OSError:
            continue
        if old != current and stale:
            shutil.rmtree(old, ignore_errors=True)


@contextlib.contextmanager
def project_cache(package="engine"):
    """Import ``package``'s compiled modules inside this block."""
    from numba.core import config

    previous = config.CACHE_DIR
    current = cache_dir(package)
    if os.path.isdir(current):
        try:
            os.utime(current)  # mark it recently used, so pruning keeps it
        except OSError:
            pass  # a cache we may read but not touch (a bot's sandbox): use it as it is
    else:
        prune(current)
    config.CACHE_DIR = current
    try:
        yield
    finally:
        config.CACHE_DIR = previous


def compiler(package, **defaults):
    """A decorator factory like ``numba.njit(cache=True, ...)`` whose compiled code lives in
    ``package``'s directory whatever imported the module first (numba fixes a function's
    cache location when it is decorated, so a module imported outside ``project_cache`` would
    otherwise cache beside its source, keyed on that file alone)::

        jit = compiler("spacewar")

        @jit()
        def step_match(...): ...
    """
    _check_package(package)

    def jit(**options):
        def decorate(function):
            import numba

            with project_cache(package):
                return numba.njit(cache=True, **{**defaults, **options})(function)
        return decorate
    return jit
