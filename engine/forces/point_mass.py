"""A fixed attractor (Spacewar's star): a body of gravitational parameter mu pinned at c.

a_i = -mu (p_i - c) / (|p_i - c|^2 + eps^2)^(3/2),   U = -sum_i mu m_i / sqrt(|p_i - c|^2 + eps^2)

The attractor itself never moves and takes no reaction, so momentum is not conserved by this
term (the star is an external body). Moving it between steps (``pm.pos = ...``) acts from the
next step on.
"""
import math

from ..cache import jit

from ._kernels import nearest_image
from .base import Force, check_particles, particle_list
from .._validate import positive_float, nonnegative_float, vector

import numpy as np

KIND = 1


@jit(error_model="numpy", inline="always")
def _target(indices, i0, i1, k):
    """The k-th particle the attractor acts on: every particle, or only those listed in indices."""
    return k if i1 == i0 else indices[i0 + k]


@jit(error_model="numpy", _nrt=False)
def accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work):
    pos = state.pos
    active = state.active
    n = state.n
    box = state.box
    mu = params[f0]
    eps2 = params[f0 + 1]
    dim = pos.shape[0]
    cx = params[f0 + 2]
    cy = params[f0 + 3]
    cz = params[f0 + 4] if dim == 3 else 0.0
    for k in range(n if i1 == i0 else i1 - i0):
        i = _target(indices, i0, i1, k)
        if i >= n or not active[i]:
            continue
        dx = nearest_image(pos[0, i] - cx, box)  # the nearest image of the attractor
        dy = nearest_image(pos[1, i] - cy, box)
        dz = nearest_image(pos[2, i] - cz, box) if dim == 3 else 0.0
        r2 = dx * dx + dy * dy + dz * dz + eps2
        s = mu / (r2 * math.sqrt(r2))
        acc[0, i] -= s * dx
        acc[1, i] -= s * dy
        if dim == 3:
            acc[2, i] -= s * dz


@jit(error_model="numpy", _nrt=False)
def potential(t, state, params, f0, f1, indices, i0, i1):
    pos = state.pos
    mass = state.mass
    active = state.active
    n = state.n
    box = state.box
    mu = params[f0]
    eps2 = params[f0 + 1]
    dim = pos.shape[0]
    u = 0.0
    for j in range(n if i1 == i0 else i1 - i0):
        i = _target(indices, i0, i1, j)
        if i >= n or not active[i]:
            continue
        r2 = eps2
        for k in range(dim):
            d = nearest_image(pos[k, i] - params[f0 + 2 + k], box)
            r2 += d * d
        u -= mu * mass[i] / math.sqrt(r2)
    return u


class PointMass(Force):
    """Fixed attractor of gravitational parameter ``mu`` (= G M) at ``pos``.

    ``particles``: the indices it acts on (default: every particle), e.g. Spacewar's star pulls
    the ships but not the (weightless) torpedoes.
    """

    KIND = KIND
    LAYOUT = (("mu", ()), ("softening_squared", ()), ("pos", ("dim",)))
    BOUNDS = {"mu": (0.0, True), "softening_squared": (0.0, False)}
    conservative = True
    _settable = {"softening": nonnegative_float}

    def __init__(self, mu=1.0, pos=(0.0, 0.0), softening=0.0, particles=None):
        super().__init__()
        self._mu = positive_float("mu", mu)
        self._pos = vector("pos", pos)
        self.softening = nonnegative_float("softening", softening)
        self.particles = particle_list("particles", particles)

    @property
    def mu(self):
        return self._mu

    @mu.setter
    def mu(self, value):
        self._mu = positive_float("mu", value)
        self._touch()

    @property
    def pos(self):
        return self._pos.copy()

    @pos.setter
    def pos(self, value):
        dim = self._sim.dim if self._sim is not None else None
        self._pos = vector("pos", value, dim)
        self._touch()

    def _check(self, sim):
        if self._pos.shape[0] != sim.dim:
            raise ValueError(f"PointMass pos must have length {sim.dim} (the simulation's dim), "
                             f"got {tuple(self._pos)}")
        check_particles("particles", self.particles, sim)

    def _pack(self, sim):
        params = np.empty(2 + self._pos.shape[0])
        params[0] = self._mu
        params[1] = self.softening ** 2
        params[2:] = self._pos
        return params, self.particles.copy()

    def __repr__(self):
        return f"PointMass(mu={self._mu!r}, pos={tuple(self._pos)!r}, softening={self.softening!r})"


#: the term this module implements (for ``engine.forces.registry``)
TERM = PointMass
