"""Compiled functions called through their addresses, so that each is compiled once.

numba links a compiled callee's code into its caller's, then optimises and translates the
whole again, for every caller up the chain: a large function called from three levels of
small ones is compiled four times over. A function compiled on its own for one fixed
signature, its entry address passed down as an int64 and called through it (an indirect call
with numba's own calling convention) is compiled once; the call costs what a direct call to a
function that is not inlined costs. The force table calls its kernels so
(``engine.forces.calls``), and the Wisdom-Holman kernels their operators and the Kepler
drift's fallback (``engine.integrators.wisdom_holman``, ``kepler_drift``).

The callee must not raise (its status is not read): these functions compile with
``error_model="numpy"``, and report failure in their results. Addresses are those of the
process that made them: they are never pickled or sent elsewhere.
"""
from numba import types
from numba.core.errors import TypingError

from .cache import jit_disabled

#: the C-contiguous array types the functions called through addresses are compiled for
F8_1D = types.Array(types.float64, 1, "C")
F8_2D = types.Array(types.float64, 2, "C")
I8_1D = types.Array(types.int64, 1, "C")


def check_call(given, wanted, what):
    """Refuse, at compile time, a call through an address whose arguments are not of the
    callee's types ``wanted`` (numbers of another width are cast; nothing else can be)."""
    if len(given) != len(wanted):
        raise TypingError(f"{what} takes {len(wanted)} arguments, got {len(given)}")
    for k, (g, w) in enumerate(zip(given, wanted)):
        g = types.unliteral(g)
        castable = (isinstance(g, types.Integer) and isinstance(w, (types.Integer, types.Float))
                    or isinstance(g, types.Float) and isinstance(w, types.Float)
                    or isinstance(g, types.Boolean) and isinstance(w, types.Boolean))
        if g != w and not castable:
            raise TypingError(f"{what}: argument {k} is {g}, the callee takes {w}")


def call_at(context, builder, address, restype, wanted, given, args):
    """Code calling the compiled function at ``address`` (numba's calling convention,
    argument types ``wanted``) with ``args`` of types ``given``, cast; its return value."""
    args = [context.cast(builder, a, g, w) for a, g, w in zip(args, given, wanted)]
    fnty = context.call_conv.get_function_type(restype, wanted)
    pointer = builder.inttoptr(address, fnty.as_pointer())
    _, value = context.call_conv.call_function(builder, pointer, restype, wanted, args)
    return value


#: with numba's JIT off (``NUMBA_DISABLE_JIT=1``: everything runs as the Python it is written
#: in, for a debugger or a coverage tool), the functions an "address" stands for: its index here
_PYTHON_FUNCTIONS = []


def python_function(address):
    """With the JIT off, the Python function ``entry_address`` gave ``address`` for."""
    return _PYTHON_FUNCTIONS[address]


def entry_address(dispatcher, signature):
    """Compile (or load from the cache) ``dispatcher`` for ``signature`` (a numba signature
    with its return type); the address of its compiled function. With the JIT off, the
    function's index for ``python_function``."""
    if jit_disabled():  # a plain function: its index
        if dispatcher not in _PYTHON_FUNCTIONS:
            _PYTHON_FUNCTIONS.append(dispatcher)
        return _PYTHON_FUNCTIONS.index(dispatcher)
    compiled = dispatcher.overloads.get(signature.args)
    if compiled is None:
        dispatcher.compile(signature)
        compiled = dispatcher.overloads[signature.args]
    return compiled.library.get_pointer_to_function(compiled.fndesc.llvm_func_name)


__all__ = ["F8_1D", "F8_2D", "I8_1D", "call_at", "check_call", "entry_address",
           "python_function"]
