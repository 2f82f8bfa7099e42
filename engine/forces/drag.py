"""Attrition: a force opposing the velocity, linear and quadratic in speed.

f_i = -c1 v_i - c2 |v_i| v_i,   a_i = f_i / m_i     (lecture, "effect of integration errors on
energy": always include attrition). Not conservative: it has no potential.
"""
import math

from ..cache import jit

from ._kernels import add_force
from .base import Force, floats, EMPTY_INTS
from .._validate import nonnegative_float

KIND = 5


@jit(error_model="numpy", _nrt=False)
def accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work):
    pos = state.pos
    vel = state.vel
    mass = state.mass
    active = state.active
    n = state.n
    c1 = params[f0]
    c2 = params[f0 + 1]
    dim = pos.shape[0]
    for i in range(n):
        if not active[i]:
            continue
        vx = vel[0, i]
        vy = vel[1, i]
        vz = vel[2, i] if dim == 3 else 0.0
        s = -(c1 + c2 * math.sqrt(vx * vx + vy * vy + vz * vz))
        add_force(acc, i, dim, s * vx, s * vy, s * vz, mass[i])


@jit(error_model="numpy", _nrt=False)
def potential(t, state, params, f0, f1, indices, i0, i1):
    return 0.0


class Drag(Force):
    """Drag force ``-linear * v - quadratic * |v| v`` on every active particle."""

    KIND = KIND
    LAYOUT = (("linear", ()), ("quadratic", ()))
    BOUNDS = {"linear": (0.0, False), "quadratic": (0.0, False)}
    _settable = {"linear": nonnegative_float, "quadratic": nonnegative_float}

    def __init__(self, linear=0.0, quadratic=0.0):
        super().__init__()
        self.linear = linear
        self.quadratic = quadratic

    @property
    def velocity_dependent(self):
        return self.linear > 0.0 or self.quadratic > 0.0

    def _pack(self, sim):
        return floats(self.linear, self.quadratic), EMPTY_INTS

    def __repr__(self):
        return f"Drag(linear={self.linear!r}, quadratic={self.quadratic!r})"


#: the term this module implements (for ``engine.forces.registry``)
TERM = Drag
