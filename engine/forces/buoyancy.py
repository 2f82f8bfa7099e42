"""Buoyancy (Archimedes): the weight of the displaced fluid pushes a particle up.

A particle is a ball of its ``radius`` (a disk in 2-D). With ``up`` the axis pointing up, h the
submerged height d = clamp(level - (p_up - R), 0, 2R), fluid density rho and gravity g:

    3-D: V(d) = pi d^2 (3R - d) / 3                      (spherical cap)
    2-D: A(d) = R^2 acos((R - d)/R) - (R - d) sqrt(2Rd - d^2)   (circular segment)
    f_up = rho g V(d),     U = rho g  integral_0^d V(s) ds  (+ full volume beyond d = 2R)

(lecture, "buoyancy": the opposite of the weight of the submerged part, had it been fluid).
Point particles (radius 0) displace nothing and feel no buoyancy.
"""
import math

from ..cache import jit

from ._kernels import add_force
from .base import Force, floats, ints
from .._validate import finite_float, nonnegative_float, positive_float

KIND = 8


@jit(error_model="numpy", inline="always")
def _depth(level, height, radius):
    d = level - (height - radius)
    return min(max(d, 0.0), 2.0 * radius)


@jit(error_model="numpy")
def submerged(d, radius, dim):
    """Submerged volume (3-D) or area (2-D) of a ball of ``radius`` dipped to depth ``d``."""
    if dim == 3:
        return math.pi * d * d * (3.0 * radius - d) / 3.0
    u = radius - d
    return radius * radius * math.acos(u / radius) - u * math.sqrt(max(radius * radius - u * u, 0.0))


@jit(error_model="numpy")
def _submerged_integral(d, radius, dim):
    """integral_0^d submerged(s) ds, in closed form."""
    if dim == 3:
        return math.pi * (radius * d ** 3 - d ** 4 / 4.0) / 3.0
    u = radius - d
    w = max(radius * radius - u * u, 0.0)
    # antiderivative of A in u is R^2 u acos(u/R) - R^2 sqrt(R^2-u^2) + (R^2-u^2)^(3/2)/3, zero at u = R
    return -(radius * radius * u * math.acos(u / radius) - radius * radius * math.sqrt(w)
             + w ** 1.5 / 3.0)


@jit(error_model="numpy", _nrt=False)
def accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work):
    pos = state.pos
    mass = state.mass
    radius = state.radius
    active = state.active
    n = state.n
    level, rho_g = params[f0], params[f0 + 1]
    up = indices[i0]
    dim = pos.shape[0]
    for i in range(n):
        if not active[i] or radius[i] == 0.0:
            continue
        d = _depth(level, pos[up, i], radius[i])
        if d == 0.0:
            continue
        f = rho_g * submerged(d, radius[i], dim)
        f0 = f if up == 0 else 0.0
        f1 = f if up == 1 else 0.0
        f2 = f if up == 2 else 0.0
        add_force(acc, i, dim, f0, f1, f2, mass[i])


@jit(error_model="numpy", _nrt=False)
def potential(t, state, params, f0, f1, indices, i0, i1):
    pos = state.pos
    radius = state.radius
    active = state.active
    n = state.n
    level, rho_g = params[f0], params[f0 + 1]
    up = indices[i0]
    dim = pos.shape[0]
    u = 0.0
    for i in range(n):
        if not active[i] or radius[i] == 0.0:
            continue
        r = radius[i]
        raw = level - (pos[up, i] - r)
        d = min(max(raw, 0.0), 2.0 * r)
        u += rho_g * _submerged_integral(d, r, dim)
        if raw > 2.0 * r:
            u += rho_g * submerged(2.0 * r, r, dim) * (raw - 2.0 * r)
    return u


def _axis(name, value):
    if isinstance(value, bool) or value not in (0, 1, 2):
        raise ValueError(f"{name} must be the axis index 0, 1 or 2, got {value!r}")
    return int(value)


class Buoyancy(Force):
    """Fluid of ``density`` filling everything below ``level`` along axis ``up`` (default y)."""

    KIND = KIND
    LAYOUT = (("level", ()), ("density_times_g", ()))
    BOUNDS = {"density_times_g": (0.0, False)}
    conservative = True
    _settable = {"level": finite_float, "density": nonnegative_float, "g": positive_float,
                 "up": _axis}

    def __init__(self, level=0.0, density=1000.0, g=9.8, up=1):
        super().__init__()
        self.level = level
        self.density = density
        self.g = g
        self.up = up

    def _check(self, sim):
        if self.up >= sim.dim:
            raise ValueError(f"up = {self.up} is not an axis of a dim={sim.dim} simulation")

    def _pack(self, sim):
        return floats(self.level, self.density * self.g), ints(self.up)


#: the term this module implements (for ``engine.forces.registry``)
TERM = Buoyancy
