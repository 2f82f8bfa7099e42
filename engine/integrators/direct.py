"""Calling a compiled kernel without numba's type dispatch, for arguments of known types.

A numba dispatcher works out the numba type of every argument on every call, to pick the
compiled version. For arrays and numbers that is fast (a C-level fingerprint), but the named
tuples of ``engine.state`` fall back to Python-level typing: about 4 us for a ``State`` and
12 us for a Wisdom-Holman call, measured, against a kernel that may run 1 us. A simulation
that steps in short calls (a game frame, a sweep's fresh runs) would spend most of its time
there.

``call(dispatcher, args)`` calls the dispatcher normally the first time, finds the compiled
version it used, and from then on calls that version's entry point directly (about 1 us).
It is only sound when every later call has the same numba types, so it is used only where the
caller builds the arguments itself with fixed types: ``Simulation``'s own arrays
(``Particles``: C-contiguous float64 and bool), packed models (``dispatch.pack``), workspaces
and plans, with every scalar converted to float, int or bool before the call
(``scalars``). Code of your own should call the dispatchers themselves.
"""

from ..cache import jit_disabled

_ENTRIES = {}
#: verify every call's numba types against the fixed signature (slow: for tests)
CHECK = False


def call(dispatcher, args):
    """``dispatcher(*args)``, through the compiled entry point found on the first call."""
    entry = _ENTRIES.get(dispatcher)
    if entry is not None:
        if CHECK:
            _check(dispatcher, args)
        return entry(*args)
    result = dispatcher(*args)
    if jit_disabled():  # a plain function: nothing compiled to call directly
        return result
    signature = tuple(dispatcher.typeof_pyval(a) for a in args)
    compiled = dispatcher.overloads.get(signature)
    if compiled is not None:
        _ENTRIES[dispatcher] = compiled.entry_point
    return result


def signature_of(dispatcher):
    """The numba signature ``call`` fixed for ``dispatcher`` (None before its first call):
    for tests that hold every caller to one signature."""
    entry = _ENTRIES.get(dispatcher)
    if entry is None:
        return None
    for signature, compiled in dispatcher.overloads.items():
        if compiled.entry_point is entry:
            return signature
    return None


def _check(dispatcher, args):
    fixed = signature_of(dispatcher)
    actual = tuple(dispatcher.typeof_pyval(a) for a in args)
    if actual != fixed:
        raise TypeError(f"{dispatcher.__name__} called directly with types {actual}, but its entry "
                        f"point was compiled for {fixed}")
