"""The compiled force table: one call evaluates every declared term, and only those.

A simulation's terms are packed into ``model = (kinds, fp, foff, ip, ioff)``: term ``s`` has
kind ``kinds[s]`` and parameters ``fp[foff[s]:foff[s+1]]`` and ``ip[ioff[s]:ioff[s+1]]``. The
branch per term per evaluation is negligible against the work of the terms themselves, and
having one signature means every integrator is compiled once and cached, whatever the scene.

Kernels take plain arrays and offsets, never tuples or slices, and are compiled without numba's
reference counting (``_nrt=False``: they never allocate). With it, every array argument of a
call pays atomic reference-count updates on entry and exit: for a five-body system that was
seven times the cost of the physics itself (140 ns against 20 ns per evaluation, measured).
"""
import numpy as np
from numba import njit

from . import (blast, buoyancy, coulomb, drag, gravity, point_mass, springs, thrust,
               uniform_gravity, wind)


@njit(cache=True, error_model="numpy", _nrt=False)
def accelerations(t, pos, vel, mass, charge, radius, active, test, n, kinds, fp, foff, ip, ioff,
                  acc, work, iwork):
    """Overwrite ``acc[:, :n]`` with the total acceleration of every declared term at time t."""
    for k in range(acc.shape[0]):
        for i in range(n):
            acc[k, i] = 0.0
    for s in range(kinds.shape[0]):
        f0 = foff[s]
        f1 = foff[s + 1]
        i0 = ioff[s]
        i1 = ioff[s + 1]
        kind = kinds[s]
        if kind == gravity.KIND:
            gravity.accumulate(t, pos, vel, mass, charge, radius, active, test, n, fp, f0, f1, ip, i0,
                               i1, acc, work, iwork)
        elif kind == point_mass.KIND:
            point_mass.accumulate(t, pos, vel, mass, charge, radius, active, test, n, fp, f0, f1, ip, i0,
                               i1, acc, work, iwork)
        elif kind == uniform_gravity.KIND:
            uniform_gravity.accumulate(t, pos, vel, mass, charge, radius, active, test, n, fp, f0, f1, ip, i0,
                               i1, acc, work, iwork)
        elif kind == coulomb.KIND:
            coulomb.accumulate(t, pos, vel, mass, charge, radius, active, test, n, fp, f0, f1, ip, i0,
                               i1, acc, work, iwork)
        elif kind == springs.KIND:
            springs.accumulate(t, pos, vel, mass, charge, radius, active, test, n, fp, f0, f1, ip, i0,
                               i1, acc, work, iwork)
        elif kind == drag.KIND:
            drag.accumulate(t, pos, vel, mass, charge, radius, active, test, n, fp, f0, f1, ip, i0,
                               i1, acc, work, iwork)
        elif kind == thrust.KIND:
            thrust.accumulate(t, pos, vel, mass, charge, radius, active, test, n, fp, f0, f1, ip, i0,
                               i1, acc, work, iwork)
        elif kind == wind.KIND:
            wind.accumulate(t, pos, vel, mass, charge, radius, active, test, n, fp, f0, f1, ip, i0,
                               i1, acc, work, iwork)
        elif kind == buoyancy.KIND:
            buoyancy.accumulate(t, pos, vel, mass, charge, radius, active, test, n, fp, f0, f1, ip, i0,
                               i1, acc, work, iwork)
        elif kind == blast.KIND:
            blast.accumulate(t, pos, vel, mass, charge, radius, active, test, n, fp, f0, f1, ip, i0,
                               i1, acc, work, iwork)


@njit(cache=True, error_model="numpy", _nrt=False)
def potential_terms(t, pos, vel, mass, charge, radius, active, test, n, kinds, fp, foff, ip,
                    ioff, out):
    """Write each term's potential energy into ``out[s]`` (0 for non-conservative terms)."""
    for s in range(kinds.shape[0]):
        f0 = foff[s]
        f1 = foff[s + 1]
        i0 = ioff[s]
        i1 = ioff[s + 1]
        kind = kinds[s]
        u = 0.0
        if kind == gravity.KIND:
            u = gravity.potential(t, pos, vel, mass, charge, radius, active, test, n, fp, f0, f1, ip, i0, i1)
        elif kind == point_mass.KIND:
            u = point_mass.potential(t, pos, vel, mass, charge, radius, active, test, n, fp, f0, f1, ip, i0, i1)
        elif kind == uniform_gravity.KIND:
            u = uniform_gravity.potential(t, pos, vel, mass, charge, radius, active, test, n, fp, f0, f1, ip, i0, i1)
        elif kind == coulomb.KIND:
            u = coulomb.potential(t, pos, vel, mass, charge, radius, active, test, n, fp, f0, f1, ip, i0, i1)
        elif kind == springs.KIND:
            u = springs.potential(t, pos, vel, mass, charge, radius, active, test, n, fp, f0, f1, ip, i0, i1)
        elif kind == buoyancy.KIND:
            u = buoyancy.potential(t, pos, vel, mass, charge, radius, active, test, n, fp, f0, f1, ip, i0, i1)
        out[s] = u


def pack(terms, sim):
    """Concatenate the terms' parameters into the model tuple the kernels take.

    Every term is re-checked against ``sim`` first (indices in range, dimension), so nothing
    changed since it was added can reach the kernels unchecked.
    """
    fps, ips = [], []
    for term in terms:
        term._check(sim)
    for term in terms:
        fp, ip = term._pack(sim)
        fps.append(np.ascontiguousarray(fp, dtype=np.float64))
        ips.append(np.ascontiguousarray(ip, dtype=np.int64))
    kinds = np.array([term.KIND for term in terms], dtype=np.int64)
    foff = np.zeros(len(terms) + 1, dtype=np.int64)
    ioff = np.zeros(len(terms) + 1, dtype=np.int64)
    foff[1:] = np.cumsum([a.shape[0] for a in fps]) if terms else []
    ioff[1:] = np.cumsum([a.shape[0] for a in ips]) if terms else []
    fp = np.concatenate(fps) if fps else np.zeros(0)
    ip = np.concatenate(ips) if ips else np.zeros(0, dtype=np.int64)
    return kinds, fp, foff, ip, ioff
