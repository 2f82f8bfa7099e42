"""A control force per particle, set between steps (a ship's engine, a player's push).

a_i = f_i / m_i. It has no physical justification and no potential (lecture, "control
forces"). ``thrust.set(i, f)`` acts from the very next step: the simulation re-reads it.
"""
import numpy as np
from numba import njit

from ._kernels import add_force
from .base import Force, EMPTY_INTS
from .._validate import vector

KIND = 6


@njit(cache=True, error_model="numpy", _nrt=False)
def accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work):
    pos = state.pos
    mass = state.mass
    active = state.active
    n = state.n
    dim = pos.shape[0]
    count = min(n, (f1 - f0) // dim)
    for i in range(count):
        if not active[i]:
            continue
        f2 = params[f0 + i * dim + 2] if dim == 3 else 0.0
        add_force(acc, i, dim, params[f0 + i * dim], params[f0 + i * dim + 1], f2, mass[i])


@njit(cache=True, error_model="numpy", _nrt=False)
def potential(t, state, params, f0, f1, indices, i0, i1):
    return 0.0


class Thrust(Force):
    """Per-particle control forces; all zero until ``set``."""

    KIND = KIND
    LAYOUT = (("force", ("slots", "dim")),)

    def __init__(self):
        super().__init__()
        self._f = np.zeros((0, 0))

    def _dim(self):
        if self._sim is None:
            raise ValueError("add the Thrust to a simulation (sim.add_force) before setting it")
        return self._sim.dim

    def _index(self, i):
        n = self._sim.n
        if isinstance(i, bool) or not isinstance(i, (int, np.integer)) or not 0 <= i < n:
            raise ValueError(f"particle index must be an int in [0, {n}), got {i!r}")
        return int(i)

    def set(self, i, force):
        """Set the force on particle ``i`` (a vector of the simulation's dimension)."""
        dim = self._dim()
        i = self._index(i)
        f = vector("force", force, dim)
        if self._f.shape[0] <= i or self._f.shape[1] != dim:
            grown = np.zeros((max(i + 1, 2 * self._f.shape[0]), dim))
            if self._f.shape[1] == dim:
                grown[: self._f.shape[0]] = self._f
            self._f = grown
        self._f[i] = f
        self._touch()

    def get(self, i):
        """The force currently set on particle ``i``."""
        dim = self._dim()
        i = self._index(i)
        return self._f[i].copy() if i < self._f.shape[0] else np.zeros(dim)

    def clear(self):
        """Set every force to zero."""
        self._f[:] = 0.0
        self._touch()

    def _pack(self, sim):
        """One force per particle slot (zeros beyond those set): the layout's (slots, dim)."""
        f = np.zeros((sim.n, sim.dim))
        rows = min(sim.n, self._f.shape[0])
        if rows and self._f.shape[1] == sim.dim:
            f[:rows] = self._f[:rows]
        return f.reshape(-1), EMPTY_INTS


#: the term this module implements (for ``engine.forces.registry``)
TERM = Thrust
