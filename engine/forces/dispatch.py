"""The compiled force table: one call evaluates every declared term, and only those.

A simulation's terms are packed into an ``engine.state.Model``: term ``s`` has kind
``kinds[s]``, parameters ``params[param_offsets[s]:param_offsets[s+1]]`` and
``indices[index_offsets[s]:index_offsets[s+1]]``, and its kernels at the addresses
``accumulators[s]`` and ``potentials[s]`` (``engine.forces.calls``). The table calls each
declared term's kernel through its address: it names no force module, so the integrators built
on it are compiled once whatever the scene, a scene compiles the kernels of its own terms only
(the first time it is packed), and an edit to one force module recompiles that module's kernels
and nothing else.

Kernels are compiled without numba's reference counting (``_nrt=False``: they never allocate).
With it, every array argument of a call pays atomic reference-count updates on entry and exit:
for a five-body system that was seven times the cost of the physics itself (140 ns against
20 ns per evaluation, measured). The named tuples of ``engine.state`` are passed as plain
structs, so reading their fields costs nothing.
"""
import functools

import numpy as np
from ..cache import jit

from ..state import Model
from .calls import accumulate_address, call_accumulate, call_potential, potential_address


@jit(error_model="numpy", _nrt=False, fastmath=False)
def accelerations(t, state, model, acc, work):
    """Overwrite ``acc[:, :n]`` with the total acceleration of every declared term at time t.

    A pinned particle gets its acceleration like any other (it exerts its forces and feels
    theirs); the integrators hold it still by masking its kicks and drifts."""
    accelerations_inline(t, state, model, acc, work)


@jit(error_model="numpy", _nrt=False, inline="always")
def clear(acc, n):
    """``acc[:, :n] = 0`` as a loop (a slice in a caller's hot loop would cost reference
    counting): what a force function does before its terms add to ``acc``."""
    for k in range(acc.shape[0]):
        for i in range(n):
            acc[k, i] = 0.0


@jit(error_model="numpy", _nrt=False, inline="always")
def accelerations_inline(t, state, model, acc, work):
    """``accelerations``, inlined into its caller by numba (the loop over the terms; each
    term's kernel is called through its address). For executors that step many small
    systems: a call to a compiled function with a dozen array arguments (each passed as ten
    words) measured 25 to 165 ns, more than the forces on a few particles."""
    clear(acc, state.n)
    params = model.params
    param_offsets = model.param_offsets
    indices = model.indices
    index_offsets = model.index_offsets
    accumulators = model.accumulators
    for s in range(accumulators.shape[0]):
        call_accumulate(accumulators[s], t, state, params, param_offsets[s],
                        param_offsets[s + 1], indices, index_offsets[s], index_offsets[s + 1],
                        acc, work)


@jit(error_model="numpy", _nrt=False)
def potential_terms(t, state, model, out):
    """Write each term's potential energy into ``out[s]`` (0 for non-conservative terms)."""
    params = model.params
    param_offsets = model.param_offsets
    indices = model.indices
    index_offsets = model.index_offsets
    potentials = model.potentials
    for s in range(potentials.shape[0]):
        out[s] = call_potential(potentials[s], t, state, params, param_offsets[s],
                                param_offsets[s + 1], indices, index_offsets[s],
                                index_offsets[s + 1])


#: the model of no terms at all, shared (writable, as numba types read-only arrays apart and
#: would compile every kernel again for them; with no terms there is nothing to write)
EMPTY_MODEL = Model(np.zeros(0, dtype=np.int64), np.zeros(0), np.zeros(1, dtype=np.int64),
                    np.zeros(0, dtype=np.int64), np.zeros(1, dtype=np.int64),
                    np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64))


@functools.lru_cache(maxsize=None)
def kernel_addresses(kind):
    """The addresses of the ``accumulate`` and ``potential`` kernels of force ``kind`` in this
    process (each compiled, or loaded from the cache, on its first use)."""
    from .registry import by_kind

    module = by_kind(kind).module
    return accumulate_address(module), potential_address(module)


@functools.lru_cache(maxsize=256)
def _layout(kinds, param_ends, index_ends):
    """A model's kinds, offsets and kernel-address arrays for these tuples, made once and
    shared: nothing writes them (only ``Batch`` writes a model's parameters)."""
    addresses = [kernel_addresses(kind) for kind in kinds]
    return (np.array(kinds, dtype=np.int64), np.array(param_ends, dtype=np.int64),
            np.array(index_ends, dtype=np.int64),
            np.array([a for a, _ in addresses], dtype=np.int64),
            np.array([p for _, p in addresses], dtype=np.int64))


def pack(terms, sim):
    """Concatenate the terms' parameters into the ``Model`` the kernels take.

    Every term is re-checked against ``sim`` first (indices in range, dimension), so nothing
    changed since it was added can reach the kernels unchecked.
    """
    for term in terms:
        term._check(sim)
    if not terms:
        return EMPTY_MODEL
    if len(terms) == 1:
        # the common scene, taken straight through (this runs on a simulation's first call,
        # where each small numpy call adds to what a short run costs): the term's own arrays,
        # copied (a term's may be shared)
        params, indices = terms[0]._pack(sim)
        params = np.array(params, dtype=np.float64, order="C")
        indices = np.array(indices, dtype=np.int64, order="C")
        layout = _layout((terms[0]._kind(sim),), (0, params.shape[0]), (0, indices.shape[0]))
        return Model(layout[0], params, layout[1], indices, layout[2], layout[3], layout[4])
    param_blocks, index_blocks = [], []
    param_ends, index_ends = [0], [0]
    for term in terms:
        params, indices = term._pack(sim)
        params = np.ascontiguousarray(params, dtype=np.float64)
        indices = np.ascontiguousarray(indices, dtype=np.int64)
        param_blocks.append(params)
        index_blocks.append(indices)
        # offsets summed in Python: a simulation calls this once per change of its terms,
        # and for a few terms numpy's per-call cost would be most of the work
        param_ends.append(param_ends[-1] + params.shape[0])
        index_ends.append(index_ends[-1] + indices.shape[0])
    layout = _layout(tuple(term._kind(sim) for term in terms), tuple(param_ends),
                     tuple(index_ends))
    params = np.concatenate(param_blocks)
    indices = np.concatenate(index_blocks)
    return Model(layout[0], params, layout[1], indices, layout[2], layout[3], layout[4])
