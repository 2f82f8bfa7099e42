"""Damped Hooke springs between particle pairs (mass-spring ropes, cloth, soft bodies).

For a spring from a to b with d = p_b - p_a, r = |d|, stiffness k, rest length l, damping c:

    f_a = k (r - l) d/r + c ((v_b - v_a) . d/r) d/r,     f_b = -f_a

(the lecture's Hooke's law, plus a dashpot acting along the spring only, so it damps stretching
but not rigid rotation).     U = sum 1/2 k (r - l)^2  (the damping part is not conservative).

k, l and c may be scalars or one value per spring. A zero-length spring (l = 0) is linear,
f_a = k d, and is well defined even with a and b coincident; a spring with l > 0 whose ends
coincide has no direction and makes the step fail loudly.

``yield_strain``, ``break_strain`` and ``flow_rate`` make springs plastic and breakable
(``engine.forces.spring_yield``: after each step, past the yield strain the rest length flows
towards the current length at ``flow_rate`` per unit time; past the break strain the spring
breaks). Strains are measured against the current rest length.
"""
import math

import numpy as np
from ..cache import jit

from ._kernels import add_force, delta, delta_periodic
from .base import Force, read_only
from .._validate import index_array, per_item, vector, positive_float, nonnegative_float

KIND = 4


@jit(error_model="numpy", _nrt=False)
def accumulate(t, state, params, f0, f1, indices, i0, i1, acc, work):
    pos = state.pos
    vel = state.vel
    mass = state.mass
    active = state.active
    box = state.box  # a spring across the edge of a periodic space joins the nearest images
    dim = pos.shape[0]
    m = (i1 - i0) // 2
    for s in range(m):
        a = indices[i0 + 2 * s]
        b = indices[i0 + 2 * s + 1]
        if not (active[a] and active[b]):
            continue
        k = params[f0 + s]
        rest = params[f0 + m + s]
        c = params[f0 + 2 * m + s]
        dx, dy, dz = delta_periodic(pos, a, b, dim, box)
        r2 = dx * dx + dy * dy + dz * dz
        r = math.sqrt(r2)
        scale = k if rest == 0.0 else k * (1.0 - rest / r)
        if c != 0.0 and r2 > 0.0:
            dvx, dvy, dvz = delta(vel, a, b, dim)
            scale += c * (dvx * dx + dvy * dy + dvz * dz) / r2
        add_force(acc, a, dim, scale * dx, scale * dy, scale * dz, mass[a])
        add_force(acc, b, dim, -scale * dx, -scale * dy, -scale * dz, mass[b])


@jit(error_model="numpy", _nrt=False)
def potential(t, state, params, f0, f1, indices, i0, i1):
    pos = state.pos
    active = state.active
    box = state.box
    dim = pos.shape[0]
    m = (i1 - i0) // 2
    u = 0.0
    for s in range(m):
        a = indices[i0 + 2 * s]
        b = indices[i0 + 2 * s + 1]
        if not (active[a] and active[b]):
            continue
        dx, dy, dz = delta_periodic(pos, a, b, dim, box)
        stretch = math.sqrt(dx * dx + dy * dy + dz * dz) - params[f0 + m + s]
        u += 0.5 * params[f0 + s] * stretch * stretch
    return u


class Springs(Force):
    """Springs between index ``pairs``; ``k``, ``rest_length``, ``damping`` scalar or per spring.

    The indices are checked against the simulation when the term is added (and again whenever
    the simulation packs its model). ``pairs``, ``k``, ``rest_length`` and ``damping`` are
    read-only arrays: an index written in place would reach the compiled kernels unchecked.
    """

    KIND = KIND
    LAYOUT = (("k", ("items",)), ("rest_length", ("items",)), ("damping", ("items",)))
    BOUNDS = {"k": (0.0, False), "rest_length": (0.0, False), "damping": (0.0, False)}
    conservative = True

    def __init__(self, pairs, k=10.0, rest_length=1.0, damping=0.0, yield_strain=None,
                 break_strain=None, flow_rate=1.0):
        super().__init__()
        arr = index_array("pairs", pairs, 2)
        if arr.ndim != 2 or arr.shape[1] != 2:
            raise ValueError(f"pairs must have shape (M, 2), got shape {arr.shape}")
        if np.any(arr[:, 0] == arr[:, 1]):
            bad = int(np.flatnonzero(arr[:, 0] == arr[:, 1])[0])
            raise ValueError(f"pairs[{bad}] joins particle {arr[bad, 0]} to itself")
        count = arr.shape[0]
        self.pairs = arr
        self.k = per_item("k", k, count, minimum=0.0)
        self.rest_length = per_item("rest_length", rest_length, count, minimum=0.0)
        self.damping = per_item("damping", damping, count, minimum=0.0)
        limits = {}
        for name, value in (("yield_strain", yield_strain), ("break_strain", break_strain)):
            limits[name] = np.full(count, np.inf) if value is None else \
                per_item(name, value, count, minimum=0.0, strictly=True)
        rate = per_item("flow_rate", flow_rate, count, minimum=0.0)
        crossed = np.isfinite(limits["yield_strain"]) & \
            (limits["yield_strain"] >= limits["break_strain"])
        if np.any(crossed):
            bad = int(np.flatnonzero(crossed)[0])
            raise ValueError(f"yield_strain must be below break_strain, got yield_strain "
                             f"{float(limits['yield_strain'][bad])!r} and break_strain "
                             f"{float(limits['break_strain'][bad])!r} (spring {bad})")
        plastic = np.isfinite(limits["yield_strain"]) | np.isfinite(limits["break_strain"])
        if np.any(plastic & (self.rest_length == 0.0)):
            bad = int(np.flatnonzero(plastic & (self.rest_length == 0.0))[0])
            raise ValueError(f"rest_length[{bad}] = 0.0: a zero-length spring has no strain, so "
                             "it cannot yield or break (give it yield_strain=None, "
                             "break_strain=None)")
        self.yield_strain = limits["yield_strain"]
        self.break_strain = limits["break_strain"]
        self.flow_rate = rate

    @property
    def plastic(self):
        """Do any of these springs yield or break?"""
        return bool(np.any(np.isfinite(self.yield_strain)) or
                    np.any(np.isfinite(self.break_strain)))

    @property
    def broken(self):
        """Which springs have broken (their stiffness is 0 for good), a bool per spring."""
        return self.__dict__.get("_broken", np.zeros(len(self), dtype=bool)).copy()

    def _after_step(self, rest_length, k, damping):
        """The rest lengths, stiffnesses and damping a step's yielding and breaking left (the
        packed model holds them already: no re-pack)."""
        object.__setattr__(self, "_broken", self.broken | ((k == 0.0) & (self.k > 0.0)))
        for name, value in (("rest_length", rest_length), ("k", k), ("damping", damping)):
            object.__setattr__(self, name, read_only(value.copy()))

    def __len__(self):
        return self.pairs.shape[0]

    @property
    def velocity_dependent(self):
        return bool(np.any(self.damping > 0.0))

    def _check(self, sim):
        bad = (self.pairs < 0) | (self.pairs >= sim.n)
        if np.any(bad):
            s, end = np.argwhere(bad)[0]
            raise ValueError(f"pairs[{s}][{end}] = {self.pairs[s, end]} is out of range "
                             f"(the simulation has {sim.n} particles)")

    def _pack(self, sim):
        params = np.concatenate((self.k, self.rest_length, self.damping))
        return params, self.pairs.reshape(-1).copy()

    def __repr__(self):
        return f"Springs({len(self)} springs)"


def rope(sim, start, end, segments, mass, k, damping=0.0, test=False, **plastic):
    """Add a rope of ``segments`` springs from ``start`` to ``end`` at rest.

    ``mass`` is the mass of each of the ``segments + 1`` particles. The springs are added to
    ``sim`` and their rest length is the initial spacing; ``plastic`` (``yield_strain``,
    ``break_strain``, ``flow_rate``) is passed on to ``Springs``. Returns
    ``(indices, springs)``.
    """
    segments = int(segments)
    if segments < 1:
        raise ValueError(f"segments must be >= 1, got {segments!r}")
    a = vector("start", start, sim.dim)
    b = vector("end", end, sim.dim)
    positive_float("mass", mass)
    nonnegative_float("k", k)
    nonnegative_float("damping", damping)
    frac = np.linspace(0.0, 1.0, segments + 1)[:, None]
    idx = sim.add_many(mass=mass, pos=a + frac * (b - a), test=test)
    spacing = float(np.linalg.norm(b - a)) / segments
    springs = Springs(np.column_stack((idx[:-1], idx[1:])), k=k, rest_length=spacing,
                      damping=damping, **plastic)
    sim.add_force(springs)
    return idx, springs


def cloth(sim, corner, edge_u, edge_v, nu, nv, mass, k, damping=0.0, shear=True, bend=False,
          **plastic):
    """Add a cloth grid of ``nu x nv`` particles spanning ``corner + [0,1] edge_u + [0,1] edge_v``.

    Structural springs join grid neighbours; ``shear`` adds both diagonals of every cell and
    ``bend`` adds springs skipping one particle. Rest lengths are the initial distances;
    ``plastic`` (``yield_strain``, ``break_strain``, ``flow_rate``) is passed on to
    ``Springs``. Returns ``(indices, springs)`` with ``indices`` of shape ``(nu, nv)``.
    """
    nu, nv = int(nu), int(nv)
    if nu < 2 or nv < 2:
        raise ValueError(f"cloth needs nu >= 2 and nv >= 2, got nu={nu!r}, nv={nv!r}")
    c = vector("corner", corner, sim.dim)
    u = vector("edge_u", edge_u, sim.dim)
    v = vector("edge_v", edge_v, sim.dim)
    positive_float("mass", mass)
    nonnegative_float("k", k)
    nonnegative_float("damping", damping)
    fu = np.linspace(0.0, 1.0, nu)[:, None, None]
    fv = np.linspace(0.0, 1.0, nv)[None, :, None]
    grid = c + fu * u + fv * v
    idx = sim.add_many(mass=mass, pos=grid.reshape(-1, sim.dim)).reshape(nu, nv)
    pairs = [np.column_stack((idx[:-1, :].ravel(), idx[1:, :].ravel())),
             np.column_stack((idx[:, :-1].ravel(), idx[:, 1:].ravel()))]
    if shear:
        pairs.append(np.column_stack((idx[:-1, :-1].ravel(), idx[1:, 1:].ravel())))
        pairs.append(np.column_stack((idx[1:, :-1].ravel(), idx[:-1, 1:].ravel())))
    if bend:
        if nu > 2:
            pairs.append(np.column_stack((idx[:-2, :].ravel(), idx[2:, :].ravel())))
        if nv > 2:
            pairs.append(np.column_stack((idx[:, :-2].ravel(), idx[:, 2:].ravel())))
    pairs = np.concatenate(pairs)
    flat = grid.reshape(-1, sim.dim)
    lookup = {int(i): row for row, i in enumerate(idx.ravel())}
    a = flat[[lookup[int(i)] for i in pairs[:, 0]]]
    b = flat[[lookup[int(i)] for i in pairs[:, 1]]]
    rest = np.linalg.norm(b - a, axis=1)
    springs = Springs(pairs, k=k, rest_length=rest, damping=damping, **plastic)
    sim.add_force(springs)
    return idx, springs


#: the term this module implements (for ``engine.forces.registry``)
TERM = Springs
