"""Wind pressure on triangles (cloth, sails, leaves), in 3-D.

For a triangle (p0, p1, p2) and wind pressure vector w:

    f = | 1/2 (p1 - p0) x (p2 - p0) . w |  w / |w|

applied one third on each vertex (lecture, "wind pressure"): the more of the area faces the
wind, the larger the push, always along the wind. Not conservative.
"""
import math

import numpy as np
from ..cache import jit

from ._kernels import add_force, delta_periodic
from .base import Force
from .._validate import index_array, vector

KIND = 7


@jit(error_model="numpy", _nrt=False)
def accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work):
    pos = state.pos
    mass = state.mass
    active = state.active
    box = state.box
    wx, wy, wz = params[f0], params[f0 + 1], params[f0 + 2]
    wn = math.sqrt(wx * wx + wy * wy + wz * wz)
    if wn == 0.0:
        return
    for s in range((i1 - i0) // 3):
        a = indices[i0 + 3 * s]
        b = indices[i0 + 3 * s + 1]
        c = indices[i0 + 3 * s + 2]
        if not (active[a] and active[b] and active[c]):
            continue
        ux, uy, uz = delta_periodic(pos, a, b, 3, box)  # edges by the nearest image
        vx, vy, vz = delta_periodic(pos, a, c, 3, box)
        nx = uy * vz - uz * vy
        ny = uz * vx - ux * vz
        nz = ux * vy - uy * vx
        # third of the triangle's force, per unit wind direction
        f = abs(0.5 * (nx * wx + ny * wy + nz * wz)) / (3.0 * wn)
        for v in (a, b, c):
            add_force(acc, v, 3, f * wx, f * wy, f * wz, mass[v])


@jit(error_model="numpy", _nrt=False)
def potential(t, state, params, f0, f1, indices, i0, i1):
    return 0.0


class Wind(Force):
    """Wind pressure ``w`` (3-vector) on ``triangles`` (M x 3 particle indices); 3-D only.

    ``triangles`` is a read-only array (checked when the term is added and when packed).
    """

    KIND = KIND
    LAYOUT = (("w", (3,)),)

    def __init__(self, w, triangles):
        super().__init__()
        self._w = vector("w", w, 3)
        tri = index_array("triangles", triangles, 3)
        if tri.ndim != 2 or tri.shape[1] != 3:
            raise ValueError(f"triangles must have shape (M, 3), got shape {tri.shape}")
        self.triangles = tri

    @property
    def w(self):
        return self._w.copy()

    @w.setter
    def w(self, value):
        self._w = vector("w", value, 3)
        self._touch()

    def _check(self, sim):
        if sim.dim != 3:
            raise ValueError(f"Wind acts on triangles and needs dim=3, the simulation has dim={sim.dim}")
        bad = (self.triangles < 0) | (self.triangles >= sim.n)
        if np.any(bad):
            s, c = np.argwhere(bad)[0]
            raise ValueError(f"triangles[{s}][{c}] = {self.triangles[s, c]} is out of range "
                             f"(the simulation has {sim.n} particles)")

    def _pack(self, sim):
        return self._w.copy(), self.triangles.reshape(-1).copy()


def grid_triangles(indices):
    """The two triangles of every cell of an ``(nu, nv)`` index grid (e.g. from ``cloth``)."""
    idx = np.asarray(indices)
    a, b = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel()
    c, d = idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    return np.concatenate((np.column_stack((a, b, c)), np.column_stack((a, c, d))))


#: the term this module implements (for ``engine.forces.registry``)
TERM = Wind
