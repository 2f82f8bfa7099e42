"""A control force per particle, set between steps (a ship's engine, a player's push).

a_i = f_i / m_i. It has no physical justification and no potential (lecture, "control
forces"). ``thrust.set(i, f)`` acts from the very next step: the simulation re-reads it.
"""
import numpy as np
from ..cache import jit

from ._kernels import add_force
from .base import Force, check_particles, particle_list
from .._validate import vector

KIND = 6


@jit(error_model="numpy", _nrt=False)
def accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work):
    pos = state.pos
    mass = state.mass
    active = state.active
    n = state.n
    dim = pos.shape[0]
    listed = i1 > i0  # row r acts on particle indices[i0 + r]; else row i on particle i
    count = (i1 - i0) if listed else min(n, (f1 - f0) // dim)
    for r in range(count):
        i = indices[i0 + r] if listed else r
        if i >= n or not active[i]:
            continue
        f2 = params[f0 + r * dim + 2] if dim == 3 else 0.0
        add_force(acc, i, dim, params[f0 + r * dim], params[f0 + r * dim + 1], f2, mass[i])


@jit(error_model="numpy", _nrt=False)
def potential(t, state, params, f0, f1, indices, i0, i1):
    return 0.0


class Thrust(Force):
    """Per-particle control forces; all zero until ``set``.

    ``particles``: the indices it may push (default: every particle slot). A game's engines
    push only its ships: listing them keeps the term's parameters to one row per ship.
    """

    KIND = KIND
    LAYOUT = (("force", ("rows", "dim")),)

    def __init__(self, particles=None):
        super().__init__()
        self._f = np.zeros((0, 0))
        self.particles = particle_list("particles", particles)

    def _rows(self, sim):
        """Rows of the packed forces: one per listed particle, else one per particle slot."""
        return self.particles.size if self.particles.size else sim.n

    def _dim(self):
        if self._sim is None:
            raise ValueError("add the Thrust to a simulation (sim.add_force) before setting it")
        return self._sim.dim

    def _row(self, i):
        n = self._sim.n
        if isinstance(i, bool) or not isinstance(i, (int, np.integer)) or not 0 <= i < n:
            raise ValueError(f"particle index must be an int in [0, {n}), got {i!r}")
        if self.particles.size:
            where = np.flatnonzero(self.particles == i)
            if where.size == 0:
                raise ValueError(f"particle {i} is not one this Thrust pushes "
                                 f"(particles={self.particles.tolist()})")
            return int(where[0])
        return int(i)

    def _check(self, sim):
        check_particles("particles", self.particles, sim)

    def set(self, i, force):
        """Set the force on particle ``i`` (a vector of the simulation's dimension)."""
        dim = self._dim()
        r = self._row(i)
        f = vector("force", force, dim)
        if self._f.shape[0] <= r or self._f.shape[1] != dim:
            grown = np.zeros((max(r + 1, 2 * self._f.shape[0]), dim))
            if self._f.shape[1] == dim:
                grown[: self._f.shape[0]] = self._f
            self._f = grown
        self._f[r] = f
        self._touch()

    def get(self, i):
        """The force currently set on particle ``i``."""
        dim = self._dim()
        r = self._row(i)
        return self._f[r].copy() if r < self._f.shape[0] else np.zeros(dim)

    def clear(self):
        """Set every force to zero."""
        self._f[:] = 0.0
        self._touch()

    def _pack(self, sim):
        """One force per row (zeros beyond those set): the layout's (rows, dim)."""
        rows = self._rows(sim)
        f = np.zeros((rows, sim.dim))
        kept = min(rows, self._f.shape[0])
        if kept and self._f.shape[1] == sim.dim:
            f[:kept] = self._f[:kept]
        return f.reshape(-1), self.particles.copy()


#: the term this module implements (for ``engine.forces.registry``)
TERM = Thrust
