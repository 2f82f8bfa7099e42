"""Kernels compiled with contracted multiply-adds do not hand that flag to what they call.

numba compiles a called function at its first use with the caller's ``fastmath`` unless the
callee declares its own (its flags inherit from the caller's), and keeps that machine code for
every later caller, on disk too. A function first compiled from a contracted kernel
(``fastmath={"contract"}``: ias15's steps, whfast's interaction and Kepler drifts) would then
round differently from the same function first compiled from anywhere else, and results would
depend on which ran first in the process that filled the cache. It happened: the force table
compiled from ias15 first broke the bit-identity of the fused splitting path with the general
one (``test_fused_gravity``) in a fresh checkout's test run. So every compiled function such a
kernel reaches without inlining declares ``fastmath`` itself; here the engine's kernels are
walked and checked. (Replayed by hand in a fresh compiled-code directory, ias15 and whfast
first: 5 of 6 fused-against-general comparisons differed before the force table, ias15's
``root7`` and the drift's fallback declared ``fastmath=False``, none after. A test of that
order would compile the integrators again in a subprocess, minutes of CI for one check.)
"""
import importlib
import pkgutil

from numba.core.registry import CPUDispatcher

import engine
from engine.cache import named_objects


def _engine_dispatchers():
    found = {}
    for info in pkgutil.walk_packages(engine.__path__, "engine."):
        module = importlib.import_module(info.name)
        for name, obj in vars(module).items():
            if isinstance(obj, CPUDispatcher) and obj.py_func.__module__ == module.__name__:
                found[f"{module.__name__}.{name}"] = obj
    return found


def _named_dispatchers(dispatcher):
    """The compiled functions a function's code loads: globals (``root7``) and attributes of
    the modules it loads (``dispatch.accelerations``), read from its bytecode by the walk the
    compiled-code cache keys its functions with (``engine.cache.named_objects``)."""
    return [obj for obj in named_objects(dispatcher.py_func) if isinstance(obj, CPUDispatcher)]


def _inlined(dispatcher):
    return dispatcher.targetoptions.get("inline", "never") == "always"


def test_what_contracted_kernels_call_declares_its_own_fastmath():
    kernels = {name: d for name, d in _engine_dispatchers().items()
               if d.targetoptions.get("fastmath") and not _inlined(d)}
    assert {"engine.integrators.ias15._advance", "engine.integrators.kepler_drift.drift_columns_at",
            "engine.integrators.wisdom_holman._gravity_interaction"} <= set(kernels)
    offenders = []
    for name, kernel in kernels.items():
        seen = set()
        stack = [kernel]
        while stack:
            for callee in _named_dispatchers(stack.pop()):
                if id(callee) in seen:
                    continue
                seen.add(id(callee))
                if _inlined(callee):
                    stack.append(callee)  # compiled into the kernel: follow what it calls
                elif "fastmath" not in callee.targetoptions:
                    offenders.append(f"{name} -> {callee.py_func.__module__}."
                                     f"{callee.py_func.__name__}")
    assert not offenders, offenders

