"""The arguments every compiled kernel takes, defined once: ``State``, ``Model``, ``Workspace``.

Compiled code built on the engine (the game, learning environments, parameter sweeps) calls the
force and integrator kernels with these three named tuples, which numba passes as plain
structs (fields read without reference counting in the ``_nrt=False`` kernels):

``State(pos, vel, mass, charge, radius, active, test, pinned, n, box)``
    one system's particles: ``pos``/``vel`` of shape ``(dim, capacity)`` (component-major:
    all x, then all y), the per-particle arrays of shape ``(capacity,)``, the ``n`` slots in
    use, and the side of the periodic space (``0.0`` for open space; see ``engine.space``).
    ``active``, ``test`` and ``pinned`` are booleans.
``Model(kinds, params, param_offsets, indices, index_offsets, accumulators, potentials)``
    the packed force terms: term ``s`` has kind ``kinds[s]`` and parameters
    ``params[param_offsets[s]:param_offsets[s+1]]`` (float64) and
    ``indices[index_offsets[s]:index_offsets[s+1]]`` (int64); the names of the float
    parameters are given by each term's ``layout`` (``engine.forces.base``).
    ``accumulators[s]`` and ``potentials[s]`` are the addresses of its kernels in this process
    (``engine.forces.calls``), through which the force table calls them.
``Workspace(floats, ints, threads)``
    scratch for the large-N pair kernels (``pairwise.workspace``) and whether they may start
    a parallel region of their own (False inside a batch, whose systems already fill the cores).

With these, a force kernel is ``accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work)`` and
an integrator step is ``advance(t, h, steps, state, model, work, vdep, t_end, ...)``.
"""
import math
from collections import namedtuple

import numpy as np
from .cache import jit

State = namedtuple("State", "pos vel mass charge radius active test pinned n box")
Model = namedtuple("Model", "kinds params param_offsets indices index_offsets accumulators "
                   "potentials")
Workspace = namedtuple("Workspace", "floats ints threads")

EMPTY_WORKSPACE = Workspace(np.empty(0), np.empty(0, dtype=np.int64), False)


@jit(inline="always")
def with_motion(state, pos, vel):
    """The same particles at other positions and velocities (a Runge-Kutta stage)."""
    return State(pos, vel, state.mass, state.charge, state.radius, state.active, state.test,
                 state.pinned, state.n, state.box)


#: fields ``first_invalid`` reports, by their code
INVALID_FIELDS = ("", "pos", "vel", "mass", "charge", "radius")


@jit(error_model="numpy", inline="always")
def _bad_motion(a, i):
    for k in range(a.shape[0]):
        if not math.isfinite(a[k, i]):
            return True
    return False


@jit(error_model="numpy", inline="always")
def _bad(x, minimum):
    return not (math.isfinite(x) and x >= minimum)


@jit(error_model="numpy")
def first_invalid(state):
    """Bad input written into a state's arrays, found in one compiled pass before a step:
    0 when the state is valid, else ``field * 2**32 + particle`` (field as ``INVALID_FIELDS``)
    for the first particle with a non-finite position or velocity, else the first with a bad
    mass (non-finite or negative), charge (non-finite) or radius (non-finite or negative), in
    that order. The velocities of pinned particles are set back to zero on the way."""
    n = state.n
    for i in range(n):
        if state.pinned[i]:
            for k in range(state.vel.shape[0]):
                state.vel[k, i] = 0.0
    for i in range(n):
        if _bad_motion(state.pos, i):
            return 1 * 2 ** 32 + i
        if _bad_motion(state.vel, i):
            return 2 * 2 ** 32 + i
    for i in range(n):
        if _bad(state.mass[i], 0.0):
            return 3 * 2 ** 32 + i
    for i in range(n):
        if not math.isfinite(state.charge[i]):
            return 4 * 2 ** 32 + i
    for i in range(n):
        if _bad(state.radius[i], 0.0):
            return 5 * 2 ** 32 + i
    return 0


__all__ = ["State", "Model", "Workspace", "EMPTY_WORKSPACE", "with_motion",
           "first_invalid", "INVALID_FIELDS"]
