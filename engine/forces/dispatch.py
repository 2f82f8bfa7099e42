"""The compiled force table: one call evaluates every declared term, and only those.

A simulation's terms are packed into an ``engine.state.Model(kinds, params, param_offsets, indices, index_offsets)``:
term ``s`` has kind ``kinds[s]`` and parameters ``params[param_offsets[s]:param_offsets[s+1]]`` and
``indices[index_offsets[s]:index_offsets[s+1]]``. The branch per term per evaluation is negligible against the work of
the terms themselves, and having one signature means every integrator is compiled once and
cached, whatever the scene. Every module of ``engine.forces.registry.TERMS`` has a branch in
both dispatchers (a test holds it to that).

Kernels are compiled without numba's reference counting (``_nrt=False``: they never allocate).
With it, every array argument of a call pays atomic reference-count updates on entry and exit:
for a five-body system that was seven times the cost of the physics itself (140 ns against
20 ns per evaluation, measured). The named tuples of ``engine.state`` are passed as plain
structs, so reading their fields costs nothing.
"""
import functools

import numpy as np
from numba import njit

from ..state import Model
from . import (blast, buoyancy, coulomb, drag, gravity, point_mass, springs, thrust,
               uniform_gravity, wind)


@njit(cache=True, error_model="numpy", _nrt=False, fastmath=False)
def accelerations(t, state, model, acc, work):
    """Overwrite ``acc[:, :n]`` with the total acceleration of every declared term at time t.

    A pinned particle gets its acceleration like any other (it exerts its forces and feels
    theirs); the integrators hold it still by masking its kicks and drifts."""
    accelerations_inline(t, state, model, acc, work)


@njit(cache=True, error_model="numpy", _nrt=False, inline="always")
def accelerations_inline(t, state, model, acc, work):
    """``accelerations``, inlined into its caller by numba. For executors that step many
    small systems: a call to a compiled function with a dozen array arguments (each passed
    as ten words) measured 25 to 165 ns, more than the forces on a few particles."""
    n = state.n
    for k in range(acc.shape[0]):
        for i in range(n):
            acc[k, i] = 0.0
    kinds = model.kinds
    params = model.params
    param_offsets = model.param_offsets
    indices = model.indices
    index_offsets = model.index_offsets
    for s in range(kinds.shape[0]):
        f0 = param_offsets[s]
        f1 = param_offsets[s + 1]
        i0 = index_offsets[s]
        i1 = index_offsets[s + 1]
        kind = kinds[s]
        if kind == gravity.KIND:
            gravity.accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work)
        elif kind == point_mass.KIND:
            point_mass.accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work)
        elif kind == uniform_gravity.KIND:
            uniform_gravity.accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work)
        elif kind == coulomb.KIND:
            coulomb.accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work)
        elif kind == springs.KIND:
            springs.accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work)
        elif kind == drag.KIND:
            drag.accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work)
        elif kind == thrust.KIND:
            thrust.accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work)
        elif kind == wind.KIND:
            wind.accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work)
        elif kind == buoyancy.KIND:
            buoyancy.accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work)
        elif kind == blast.KIND:
            blast.accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work)


@njit(cache=True, error_model="numpy", _nrt=False)
def potential_terms(t, state, model, out):
    """Write each term's potential energy into ``out[s]`` (0 for non-conservative terms)."""
    kinds = model.kinds
    params = model.params
    param_offsets = model.param_offsets
    indices = model.indices
    index_offsets = model.index_offsets
    for s in range(kinds.shape[0]):
        f0 = param_offsets[s]
        f1 = param_offsets[s + 1]
        i0 = index_offsets[s]
        i1 = index_offsets[s + 1]
        kind = kinds[s]
        u = 0.0
        if kind == gravity.KIND:
            u = gravity.potential(t, state, params, f0, f1, indices, i0, i1)
        elif kind == point_mass.KIND:
            u = point_mass.potential(t, state, params, f0, f1, indices, i0, i1)
        elif kind == uniform_gravity.KIND:
            u = uniform_gravity.potential(t, state, params, f0, f1, indices, i0, i1)
        elif kind == coulomb.KIND:
            u = coulomb.potential(t, state, params, f0, f1, indices, i0, i1)
        elif kind == springs.KIND:
            u = springs.potential(t, state, params, f0, f1, indices, i0, i1)
        elif kind == drag.KIND:
            u = drag.potential(t, state, params, f0, f1, indices, i0, i1)
        elif kind == thrust.KIND:
            u = thrust.potential(t, state, params, f0, f1, indices, i0, i1)
        elif kind == wind.KIND:
            u = wind.potential(t, state, params, f0, f1, indices, i0, i1)
        elif kind == buoyancy.KIND:
            u = buoyancy.potential(t, state, params, f0, f1, indices, i0, i1)
        elif kind == blast.KIND:
            u = blast.potential(t, state, params, f0, f1, indices, i0, i1)
        out[s] = u


#: the model of no terms at all, shared (writable, as numba types read-only arrays apart and
#: would compile every kernel again for them; with no terms there is nothing to write)
EMPTY_MODEL = Model(np.zeros(0, dtype=np.int64), np.zeros(0), np.zeros(1, dtype=np.int64),
                    np.zeros(0, dtype=np.int64), np.zeros(1, dtype=np.int64))


@functools.lru_cache(maxsize=256)
def _layout(kinds, param_ends, index_ends):
    """A model's kinds and offsets arrays for these tuples, made once and shared: nothing
    writes a model's kinds or offsets (only ``Batch`` writes its parameters)."""
    return (np.array(kinds, dtype=np.int64), np.array(param_ends, dtype=np.int64),
            np.array(index_ends, dtype=np.int64))


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
        kinds, param_offsets, index_offsets = _layout((terms[0].KIND,), (0, params.shape[0]),
                                                      (0, indices.shape[0]))
        return Model(kinds, params, param_offsets, indices, index_offsets)
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
    kinds, param_offsets, index_offsets = _layout(tuple(term.KIND for term in terms),
                                                  tuple(param_ends), tuple(index_ends))
    params = np.concatenate(param_blocks)
    indices = np.concatenate(index_blocks)
    return Model(kinds, params, param_offsets, indices, index_offsets)
