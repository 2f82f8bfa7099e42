"""Force kernels called through their addresses, so that what calls them is compiled once.

A compiled function that names a kernel (``drag.accumulate(...)``) carries that kernel's
machine code inside its own: numba links the callee into the caller. The force table used to
name all ten terms' kernels, so every integrator compiled all ten (inlined, several times over
in the Wisdom-Holman kernels) whatever the scene declared, and an edit to any force module
invalidated every integrator's compiled code. Here a kernel is compiled on its own, once, for
one fixed signature (``ARGUMENTS``), when a scene first declares its term; the packed ``Model``
carries the addresses of its terms' kernels; and the table calls each through its address
(``call_accumulate``), an indirect call with numba's own calling convention. The integrators'
code then depends on no force module at all.

The cost of a call through an address is that of a direct call (measured with the splitting
executor, which called the table already). The callee must not raise (the kernels are compiled
with ``error_model="numpy"`` and without reference counting: a singular force gives a
non-finite value, which the integrators check for).

Addresses are those of this process: a ``Model`` is never pickled or sent elsewhere (``pack``
makes one from the terms, in the process that steps).
"""
import functools

import numpy as np
from numba import types
from numba.extending import intrinsic

from ..cache import jit_disabled
from ..address_calls import (F8_1D, F8_2D, I8_1D, call_at, check_call, entry_address,
                             python_function)


@functools.lru_cache(maxsize=None)
def argument_types():
    """The numba types of ``accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work)``
    and of ``potential(t, state, params, f0, f1, indices, i0, i1)``: every kernel is compiled
    for exactly these (C-contiguous float64 arrays, int64 indices, boolean flags)."""
    from numba import typeof

    from ..state import State, Workspace

    state = typeof(State(np.zeros((2, 1)), np.zeros((2, 1)), np.zeros(1), np.zeros(1),
                         np.zeros(1), np.zeros(1, dtype=np.bool_), np.zeros(1, dtype=np.bool_),
                         np.zeros(1, dtype=np.bool_), 1, 0.0))
    work = typeof(Workspace(np.zeros(1), np.zeros(1, dtype=np.int64), False))
    head = (types.float64, state, F8_1D, types.int64, types.int64, I8_1D, types.int64,
            types.int64)
    return head + (F8_2D, work), head


@intrinsic
def call_accumulate(typingctx, address, t, state, params, f0, f1, indices, i0, i1, acc, work):
    """``accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work)`` of the kernel at
    ``address`` (an int64 from ``accumulate_address``)."""
    given = (t, state, params, f0, f1, indices, i0, i1, acc, work)
    wanted = argument_types()[0]
    check_call(given, wanted, "call_accumulate")

    def codegen(context, builder, signature, args):
        call_at(context, builder, args[0], types.none, wanted, given, args[1:])
        return context.get_dummy_value()
    return types.none(address, *given), codegen


@intrinsic
def call_potential(typingctx, address, t, state, params, f0, f1, indices, i0, i1):
    """``potential(t, state, params, f0, f1, indices, i0, i1)`` of the kernel at ``address``
    (from ``potential_address``): the term's potential energy."""
    given = (t, state, params, f0, f1, indices, i0, i1)
    wanted = argument_types()[1]
    check_call(given, wanted, "call_potential")

    def codegen(context, builder, signature, args):
        return call_at(context, builder, args[0], types.float64, wanted, given, args[1:])
    return types.float64(address, *given), codegen


if jit_disabled():  # the kernels are plain functions (``entry_address``): call them so
    def call_accumulate(address, t, state, params, f0, f1, indices, i0, i1, acc,  # noqa: F811
                        work):
        python_function(address)(t, state, params, f0, f1, indices, i0, i1, acc, work)

    def call_potential(address, t, state, params, f0, f1, indices, i0, i1):  # noqa: F811
        return python_function(address)(t, state, params, f0, f1, indices, i0, i1)


@functools.lru_cache(maxsize=None)
def accumulate_address(module):
    """The address of ``module.accumulate`` compiled for the kernels' signature (compiled on
    the first call in a process, or loaded from the compiled-code cache)."""
    return entry_address(module.accumulate, types.none(*argument_types()[0]))


@functools.lru_cache(maxsize=None)
def potential_address(module):
    """The address of ``module.potential`` compiled for the kernels' signature."""
    return entry_address(module.potential, types.float64(*argument_types()[1]))


__all__ = ["argument_types", "call_accumulate", "call_potential", "accumulate_address",
           "potential_address"]
