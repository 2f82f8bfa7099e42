"""A blast: a radial push away from a point, falling off with distance, for explosions.

    f_i = s r_hat / (1 + (r / L)^2)     while  t0 <= t < t0 + duration

with r = |p_i - c|, strength s, length scale L (the push halves at r = L and falls off like
1/r^2 far away), c the centre. A particle exactly at the centre has no outward direction and
feels nothing. It is a shock, not a field: not conservative. Its impulse is s * duration at
the centre's edge, so a short, strong blast is an explosion and a long weak one is a wind.
"""
import math

import numpy as np
from ..cache import jit

from ._kernels import add_force, nearest_image
from .base import Force, EMPTY_INTS
from .._validate import finite_float, positive_float, vector

KIND = 9


@jit(error_model="numpy", _nrt=False)
def accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work):
    pos = state.pos
    mass = state.mass
    active = state.active
    n = state.n
    box = state.box
    strength, scale, t0, duration = params[f0], params[f0 + 1], params[f0 + 2], params[f0 + 3]
    if not (t0 <= t < t0 + duration):
        return
    dim = pos.shape[0]
    cz = params[f0 + 6] if dim == 3 else 0.0
    for i in range(n):
        if not active[i]:
            continue
        dx = nearest_image(pos[0, i] - params[f0 + 4], box)  # from the nearest image of the centre
        dy = nearest_image(pos[1, i] - params[f0 + 5], box)
        dz = nearest_image(pos[2, i] - cz, box) if dim == 3 else 0.0
        r = math.sqrt(dx * dx + dy * dy + dz * dz)
        if r == 0.0:
            continue
        q = r / scale
        s = strength / ((1.0 + q * q) * r)
        add_force(acc, i, dim, s * dx, s * dy, s * dz, mass[i])


@jit(error_model="numpy", _nrt=False)
def potential(t, state, params, f0, f1, indices, i0, i1):
    return 0.0


def _duration(name, value):
    if isinstance(value, bool) or not (isinstance(value, (int, float, np.floating))
                                       and value > 0 and not math.isnan(value)):
        raise ValueError(f"{name} must be > 0 (inf allowed), got {value!r}")
    return float(value)


class Blast(Force):
    """Outward push of ``strength`` from ``center`` with length ``scale``, from ``start`` for
    ``duration`` (simulation time; ``duration=inf`` keeps it on)."""

    KIND = KIND
    LAYOUT = (("strength", ()), ("scale", ()), ("start", ()), ("duration", ()), ("center", ("dim",)))
    BOUNDS = {"scale": (0.0, True), "duration": (0.0, True)}
    _settable = {"center": vector, "strength": finite_float, "scale": positive_float,
                 "start": finite_float, "duration": _duration}

    def __init__(self, center, strength, scale=1.0, start=0.0, duration=math.inf):
        super().__init__()
        self.center = center
        self.strength = strength
        self.scale = scale
        self.start = start
        self.duration = duration

    def _check(self, sim):
        if self.center.shape[0] != sim.dim:
            raise ValueError(f"Blast center must have length {sim.dim}, got {tuple(self.center)}")

    def _pack(self, sim):
        head = np.array([self.strength, self.scale, self.start, self.duration])
        return np.concatenate((head, self.center)), EMPTY_INTS


#: the term this module implements (for ``engine.forces.registry``)
TERM = Blast
