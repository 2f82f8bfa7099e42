"""Gravity near a planet's surface: the same acceleration g for every particle.

f = m g,  a = g,  U = -sum_i m_i g . p_i      (lecture, "gravitational forces near a planet")
"""
from ..cache import jit

from .base import Force, EMPTY_INTS
from .._validate import vector

KIND = 2


@jit(error_model="numpy", _nrt=False)
def accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work):
    pos = state.pos
    active = state.active
    n = state.n
    dim = pos.shape[0]
    for i in range(n):
        if not active[i]:
            continue
        for k in range(dim):
            acc[k, i] += params[f0 + k]


@jit(error_model="numpy", _nrt=False)
def potential(t, state, params, f0, f1, indices, i0, i1):
    pos = state.pos
    mass = state.mass
    active = state.active
    n = state.n
    dim = pos.shape[0]
    u = 0.0
    for i in range(n):
        if not active[i]:
            continue
        for k in range(dim):
            u -= mass[i] * params[f0 + k] * pos[k, i]
    return u


class UniformGravity(Force):
    """Constant gravitational acceleration ``g`` (a vector of the simulation's dimension)."""

    KIND = KIND
    LAYOUT = (("g", ("dim",)),)
    conservative = True

    def __init__(self, g=(0.0, -9.8)):
        super().__init__()
        self._g = vector("g", g)

    @property
    def g(self):
        return self._g.copy()

    @g.setter
    def g(self, value):
        dim = self._sim.dim if self._sim is not None else None
        self._g = vector("g", value, dim)
        self._touch()

    def _check(self, sim):
        if self._g.shape[0] != sim.dim:
            raise ValueError(f"UniformGravity g must have length {sim.dim} (the simulation's dim), "
                             f"got {tuple(self._g)}")

    def _pack(self, sim):
        return self._g.copy(), EMPTY_INTS

    def __repr__(self):
        return f"UniformGravity(g={tuple(self._g)!r})"


#: the term this module implements (for ``engine.forces.registry``)
TERM = UniformGravity
