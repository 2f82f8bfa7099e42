"""Compiled code kept across runs and edits, and never stale: ``jit``, a dependency-keyed cache.

numba's on-disk cache (``cache=True``) keys a function's machine code on its own source file
only. But a compiled function carries the code of every compiled function it calls or inlines
(numba links callees into their callers) and the values of the globals it reads (frozen in as
constants): after an edit to a callee in another module, numba would load the caller's stale
code. This project's cache keys each function instead on the sources it is *built from*:

    stamp(f) = hash(f's own file, the values of the plain globals f reads,
                    stamp(g) for every compiled or Python function g that f names,
                    the files of the modules whose classes or intrinsics f names)

read from f's bytecode (globals and ``module.attribute`` chains), recursively, the first time
f is loaded or saved in a process. An edit to a module recompiles exactly the functions built
from it: an edit to ``forces/drag.py`` recompiles Drag's kernels and nothing the integrators
or other forces use (the force table calls kernels through their addresses,
``engine.forces.calls``, so it names none), and an edit to ``integrators/common.py``
recompiles the integrators. An upgrade is an edit of many files, and recompiles what changed.

Everything lives in one directory (``cache_dir()``; ``NUMBA_CACHE_DIR`` or
``$XDG_CACHE_HOME/nbody-spacewar``, under ``compiled/``), with numba's own layout inside (a
subdirectory per source directory, an index and data files per function). numba's index also
holds its version and the processor (its target and features) in every key.

    from engine.cache import jit

    @jit(error_model="numpy")
    def kernel(...): ...

``jit(**options)`` is ``numba.njit(cache=True, **options)`` with this cache, and one more
change: a compiled function called from compiled code with a constant argument is compiled
for the argument's type, not for the constant (numba's default makes ``f(x, 0)`` and
``f(x, k)`` two specialisations, each compiled in full: the Wisdom-Holman kernels were
compiled four times each that way). Functions inlined into their callers (``inline="always"``)
keep their constants, which is what lets an inlined branch on a constant fold away.
"""
import contextlib
import dis
import functools
import hashlib
import os
import shutil
import sys
import time
import types as pytypes
from pathlib import Path

_ROOT = Path(__file__).resolve().parent.parent

#: the packages whose compiled functions use this cache (``compiler(package)``); each one's
#: compiled code may be built from the engine's
SOURCES = {"engine": ("engine",), "spacewar": ("engine", "spacewar"),
           "validation": ("engine", "validation")}

#: the directory name, under the cache's base, of the compiled code
COMPILED = "compiled"


def _check_package(package):
    if package not in SOURCES:
        raise ValueError(f"package must be one of {', '.join(SOURCES)}, got {package!r}")
    return package


@functools.lru_cache(maxsize=None)
def numpy_dot_kind():
    """How numpy's ``a @ b`` of two float64 2-vectors rounds on this machine: ``"fused"``
    (``fma(a1, b1, a0 b0)``, OpenBLAS's ddot kernel on CPUs it gives FMA kernels, e.g.
    SkylakeX), ``"plain"`` (``a0 b0 + a1 b1``, e.g. its Haswell kernel on an AMD EPYC) or
    ``"other"``. Measured once on 256 fixed pairs against the exact fused value (fractions).
    Compiled code that mirrors numpy's arithmetic (``spacewar.game.compiled_bots.dot_blas``)
    is compiled for the kind found (a global that the functions reading it are keyed on)."""
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


def cache_base():
    """The base directory of this project's caches (``NUMBA_CACHE_DIR`` when set, else
    ``$XDG_CACHE_HOME/nbody-spacewar``, ``~/.cache/nbody-spacewar`` by default)."""
    return os.environ.get("NUMBA_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache"),
        "nbody-spacewar")


def cache_dir(package="engine"):
    """The directory of the compiled code (the same for every package: each function is keyed
    on its own sources; numba makes a subdirectory per source directory inside)."""
    _check_package(package)
    return os.path.join(cache_base(), COMPILED)


# -- what a function is built from --------------------------------------------------------------
def _project_file(obj):
    """The source file of ``obj`` (a module, class or function) if it is one of this
    project's, else None."""
    module = obj if isinstance(obj, pytypes.ModuleType) else sys.modules.get(
        getattr(obj, "__module__", None) or "")
    path = getattr(module, "__file__", None)
    return _project_path(path) if path else None


@functools.lru_cache(maxsize=None)
def _project_path(path):
    """``path`` resolved if it lies in one of this project's packages, else None (asked for
    every object every compiled function names: once per file)."""
    path = Path(path).resolve()
    return path if any(_ROOT / package in path.parents for package in SOURCES) else None


@functools.lru_cache(maxsize=None)
def _file_digest(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def _code_objects(code):
    yield code
    for const in code.co_consts:  # nested functions (an intrinsic's codegen), comprehensions
        if isinstance(const, pytypes.CodeType):
            yield from _code_objects(const)


@functools.lru_cache(maxsize=None)
def named_objects(function):
    """The objects ``function``'s code reads from its globals: each global it loads, and for
    a loaded module each ``module.attribute`` (chains followed as far as they go), and its
    closure's cells. What numba resolves when it compiles the function: the functions it calls
    or inlines, the constants it freezes in."""
    scope = function.__globals__
    found = []
    for code in _code_objects(function.__code__):
        held = None  # the module the previous instruction loaded
        for ins in dis.get_instructions(code):
            if ins.opname == "LOAD_GLOBAL":
                name = ins.argval
                held = scope.get(name)  # None for a builtin
                if held is not None:
                    found.append(held)
                continue
            if ins.opname in ("LOAD_ATTR", "LOAD_METHOD") and isinstance(held, pytypes.ModuleType):
                held = getattr(held, ins.argval, None)
                if held is not None:
                    found.append(held)
                continue
            held = None
    if function.__closure__:
        for cell in function.__closure__:
            try:
                found.append(cell.cell_contents)
            except ValueError:  # an empty cell
                pass
    return tuple(found)


_PLAIN = (bool, int, float, complex, str, bytes, type(None))


def _plain_value(value):
    """A stable text of a global numba freezes into compiled code (numbers, strings, tuples of
    them, numpy arrays and scalars), else None."""
    if isinstance(value, _PLAIN):
        return repr(value)
    if isinstance(value, tuple):
        parts = [_plain_value(v) for v in value]
        return None if any(p is None for p in parts) else "(" + ",".join(parts) + ")"
    import numpy as np

    if isinstance(value, np.ndarray):
        return f"{value.dtype.str}{value.shape}{hashlib.sha256(value.tobytes()).hexdigest()}"
    if isinstance(value, np.generic):
        return f"{value.dtype.str}{value!r}"
    return None


def _python_function(obj):
    """The Python function behind a compiled function, an intrinsic or a plain function."""
    from numba.core.dispatcher import Dispatcher

    if isinstance(obj, Dispatcher):
        return obj.py_func
    if isinstance(obj, pytypes.FunctionType):
        return obj
    definition = getattr(obj, "_defn", None)  # numba.extending.intrinsic
    return definition if isinstance(definition, pytypes.FunctionType) else None


def dependencies(function):
    """The project's source files ``function`` (a compiled function or its Python function)
    is built from and the plain globals it freezes in: ``(files, values)``, sorted, following
    every function it names."""
    files, values, seen = set(), set(), set()
    pending = [_python_function(function) or function]
    while pending:
        f = pending.pop()
        if id(f) in seen:
            continue
        seen.add(id(f))
        own = _project_file(f)
        if own is None:
            continue  # numba's, numpy's: versioned by numba's own key
        files.add(str(own))
        for obj in named_objects(f):
            inner = _python_function(obj)
            if inner is not None:
                pending.append(inner)
                continue
            text = _plain_value(obj)
            if text is not None:
                values.add(text)
                continue
            # a module, a class (a named tuple of the kernels' arguments) or an instance of
            # one of the project's classes: its module's file
            holder = obj if isinstance(obj, (type, pytypes.ModuleType)) else type(obj)
            path = _project_file(holder)
            if path is not None:
                files.add(str(path))
    return sorted(files), sorted(values)


def dependency_stamp(function):
    """The key of ``function``'s compiled code: a hash of the contents of the files it is
    built from, the plain globals it freezes in, and numpy's version."""
    import numpy as np

    files, values = dependencies(function)
    digest = hashlib.sha256(f"numpy {np.__version__}\n".encode())
    for path in files:
        digest.update(f"{Path(path).relative_to(_ROOT)} {_file_digest(path)}\n".encode())
    for text in values:
        digest.update(text.encode() + b"\n")
    return digest.hexdigest()


#: a symbol of numba's thread pool (``numba.np.ufunc.parallel``), in the machine code of every
#: function that runs a ``prange`` loop or links one
_THREAD_POOL_SYMBOL = b"allocate_sched"


def _calls_thread_pool(libdata):
    """Whether a cached library (numba's ``(name, kind, data)``) calls the thread pool."""
    _, kind, data = libdata
    code = data[0] if kind == "object" else data
    return isinstance(code, (bytes, bytearray)) and _THREAD_POOL_SYMBOL in code


# -- numba's cache, keyed on the dependencies ------------------------------------------------
@functools.lru_cache(maxsize=None)
def _cache_classes():
    from numba.core.caching import CompileResultCacheImpl, FunctionCache, _CacheLocator

    class Locator(_CacheLocator):
        """Every function's index and data files under ``cache_dir()``, in a subdirectory per
        source directory (numba's naming); freshness from ``dependency_stamp``."""

        def __init__(self, py_func, py_file):
            self._py_func = py_func
            self._py_file = py_file  # numba's warning about an uncachable function names it
            self._lineno = py_func.__code__.co_firstlineno
            self._path = os.path.join(cache_dir(), self.get_suitable_cache_subpath(py_file))

        def get_cache_path(self):
            return self._path

        def get_source_stamp(self):
            return None  # set on first use (``DependencyCache``): other modules may not be
            # imported yet when the function is decorated

        def get_disambiguator(self):
            return str(self._lineno)

        @classmethod
        def from_function(cls, py_func, py_file):
            return cls(py_func, py_file)

    class Impl(CompileResultCacheImpl):
        """numba's cache of compile results, with its parallel code made to start.

        A function using ``prange`` runs its start-up (numba's thread pool, whose symbols
        its machine code calls) before it is loaded from the cache; a function that calls it
        links its code, and inherits that start-up when the callee was compiled in the same
        process, but not when the callee was loaded from the cache (numba's library of a
        loaded function forgets it). With each function cached on its own sources, a caller
        is often recompiled while its callees load from the cache: its cached code then
        aborted the next process that loaded it first ("LLVM ERROR: Symbol not found:
        allocate_sched", measured). So a loaded function's library keeps its start-up for
        its callers, and code that calls the thread pool starts it whatever its entry says."""
        _locator_classes = [Locator]

        def rebuild(self, target_context, payload):
            libdata, reload_init = payload[0], payload[7]
            if not reload_init and _calls_thread_pool(libdata):
                from numba.np.ufunc.parallel import _launch_threads

                _launch_threads()
            compiled = super().rebuild(target_context, payload)
            compiled.library._reload_init.update(compiled.reload_init)
            return compiled

    class DependencyCache(FunctionCache):
        """numba's function cache, its index stamped with ``dependency_stamp``: an edit to
        any source the function is built from makes its index stale."""
        _impl_class = Impl

        def _stamped(self):
            if self._cache_file._source_stamp is None:
                self._cache_file._source_stamp = dependency_stamp(self._py_func)

        def load_overload(self, sig, target_context):
            self._stamped()
            loaded = super().load_overload(sig, target_context)
            if loaded is not None:
                for recorder in _RECORDERS:
                    recorder.loaded.add(self._py_func)
            return loaded

        def save_overload(self, sig, data):
            self._stamped()
            _prune_legacy_once()
            with _one_saver():
                return super().save_overload(sig, data)

    return DependencyCache


@contextlib.contextmanager
def _one_saver():
    """Compiled code saved by one process at a time (an exclusive lock on ``save.lock`` in
    ``cache_dir()``). numba saves a function's code by reading its index, naming the data file
    with the first number the index does not use, writing the data, then the index: two
    processes saving two signatures of one function at once (the test suite's workers) could
    both take the same number, and the index kept could name the other signature's code. A
    process that may not lock (a confined bot: ``flock`` is refused) saves without the lock."""
    try:
        import fcntl
        os.makedirs(cache_dir(), exist_ok=True)
        lock = open(os.path.join(cache_dir(), "save.lock"), "a")
    except (ImportError, OSError):  # not POSIX, or a directory this process may not write
        lock = None
    if lock is None:
        yield
        return
    with lock:
        try:
            fcntl.flock(lock, fcntl.LOCK_EX)
            locked = True
        except OSError:
            locked = False
        try:
            yield
        finally:
            if locked:
                fcntl.flock(lock, fcntl.LOCK_UN)


_RECORDERS = []


class _LoadRecorder:
    def __init__(self):
        self.loaded = set()
        _RECORDERS.append(self)

    def stop(self):
        _RECORDERS.remove(self)
        return self.loaded


def record_loads():
    """Start recording the functions whose compiled code is loaded from the cache; ``stop()``
    on the result ends it and returns them (their Python functions)."""
    return _LoadRecorder()


def is_project_function(function):
    """Is ``function`` defined in one of this project's source files?"""
    return _project_file(function) is not None


def _call_types(dispatcher, fixed=None):
    """Make compiled callers call ``dispatcher`` with their arguments' types, not constants'
    (``Literal[int](0)`` becomes ``int64``), so that it is compiled once for both; or, given
    ``fixed`` argument types, always with those (the callers' arguments cast to them)."""
    from numba.core import types

    typed = dispatcher.get_call_template

    def get_call_template(args, kws):
        if fixed is not None:
            return typed(fixed, {})
        return typed(tuple(types.unliteral(a) for a in args),
                     {k: types.unliteral(v) for k, v in kws.items()})
    dispatcher.get_call_template = get_call_template


def jit_disabled():
    """Is numba's JIT off (``NUMBA_DISABLE_JIT=1``)? Then ``jit`` gives the plain Python
    functions, and what would take their compiled code (addresses, entry points) takes them."""
    from numba import config

    return bool(config.DISABLE_JIT)


def jit(signature=None, **options):
    """``numba.njit(cache=True, **options)`` with the dependency-keyed cache (module doc).

    ``signature`` (numba's text, e.g. ``"void(float64[::1], int64)"``): the one signature the
    function is compiled for, on its first call from compiled code rather than when it is
    defined (numba's eager compilation would compile it on every import of its module whether
    anything uses it or not)."""
    import numba
    from numba.core import sigutils

    fixed = None
    if signature is not None:
        fixed = tuple(sigutils.normalize_signature(signature)[0])

    def decorate(function):
        dispatcher = numba.njit(cache=False, **options)(function)
        if jit_disabled():  # the function as written
            return dispatcher
        dispatcher._cache = _cache_classes()(function)
        if options.get("inline", "never") == "never":
            _call_types(dispatcher, fixed)
        return dispatcher
    return decorate


def compiler(package, **defaults):
    """``jit`` with ``defaults`` for ``package``'s functions::

        jit = compiler("spacewar")

        @jit()
        def step_match(...): ...
    """
    _check_package(package)

    def package_jit(**options):
        return jit(**{**defaults, **options})
    return package_jit


# -- the directories of earlier versions ------------------------------------------------------
MIN_AGE = 24 * 3600  # a directory younger than a day is never removed (a long run may use it)


def prune_legacy(base=None):
    """Remove the compiled-code directories of earlier versions of this project
    (``numba-<package>-<hash of all sources>``, one per edit) unused for a day."""
    base = base or cache_base()
    try:
        names = [d for d in os.listdir(base) if d.startswith("numba-")]
    except OSError:
        return
    now = time.time()
    for name in names:
        path = os.path.join(base, name)
        try:
            stale = now - os.path.getmtime(path) > MIN_AGE
        except OSError:
            continue
        if stale:
            shutil.rmtree(path, ignore_errors=True)


@functools.lru_cache(maxsize=None)
def _prune_legacy_once():
    """``prune_legacy`` once in a process that compiles something (never on a warm start)."""
    prune_legacy()


@contextlib.contextmanager
def project_cache(package="engine"):
    """Kept for code of earlier versions: a block whose ``numba.njit(cache=True)`` functions
    cache under ``cache_dir()`` (keyed by numba on their own files only; this project's own
    functions use ``jit``)."""
    from numba.core import config

    previous = config.CACHE_DIR
    config.CACHE_DIR = cache_dir(_check_package(package))
    try:
        yield
    finally:
        config.CACHE_DIR = previous
