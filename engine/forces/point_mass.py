"""A fixed attractor (Spacewar's star): a body of gravitational parameter mu pinned at c.

a_i = -mu (p_i - c) / (|p_i - c|^2 + eps^2)^(3/2),   U = -sum_i mu m_i / sqrt(|p_i - c|^2 + eps^2)

The attractor itself never moves and takes no reaction, so momentum is not conserved by this
term (the star is an external body). Moving it between steps (``pm.pos = ...``) acts from the
next step on.
"""
import math

from numba import njit

from .base import Force, EMPTY_INTS
from .._validate import positive_float, nonnegative_float, vector, finite_float

import numpy as np

KIND = 1


@njit(cache=True, error_model="numpy")
def accumulate(t, pos, vel, prm, n, fp, ip, acc):
    active = prm[3]
    mu = fp[0]
    eps2 = fp[1]
    dim = pos.shape[0]
    cx = fp[2]
    cy = fp[3]
    cz = fp[4] if dim == 3 else 0.0
    for i in range(n):
        if not active[i]:
            continue
        dx = pos[0, i] - cx
        dy = pos[1, i] - cy
        dz = pos[2, i] - cz if dim == 3 else 0.0
        r2 = dx * dx + dy * dy + dz * dz + eps2
        s = mu / (r2 * math.sqrt(r2))
        acc[0, i] -= s * dx
        acc[1, i] -= s * dy
        if dim == 3:
            acc[2, i] -= s * dz


@njit(cache=True, error_model="numpy")
def potential(t, pos, vel, prm, n, fp, ip):
    mass = prm[0]
    active = prm[3]
    mu = fp[0]
    eps2 = fp[1]
    dim = pos.shape[0]
    u = 0.0
    for i in range(n):
        if not active[i]:
            continue
        r2 = eps2
        for k in range(dim):
            d = pos[k, i] - fp[2 + k]
            r2 += d * d
        u -= mu * mass[i] / math.sqrt(r2)
    return u


class PointMass(Force):
    """Fixed attractor of gravitational parameter ``mu`` (= G M) at ``pos``."""

    KIND = KIND
    conservative = True

    def __init__(self, mu=1.0, pos=(0.0, 0.0), softening=0.0):
        super().__init__()
        self._mu = positive_float("mu", mu)
        self._pos = vector("pos", pos)
        self.softening = nonnegative_float("softening", softening)

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

    def _pack(self, sim):
        return np.concatenate(([self._mu, self.softening ** 2], self._pos)), EMPTY_INTS

    def __repr__(self):
        return f"PointMass(mu={self._mu!r}, pos={tuple(self._pos)!r}, softening={self.softening!r})"
