"""What a scene declares about contact: ``Collisions`` (how touching particles are resolved),
``Wall`` (a static plane they bounce off), and the record of one contact, ``Contact``.

    sim.collisions = engine.Collisions(resolve="bounce", restitution=0.9,
                                       walls=engine.box_walls(10.0, dim=2))
    sim.step(100)
    for c in sim.contacts:        # the contacts of that call, in the order they were resolved
        print(c.time, c.i, c.j, c.speed, c.action, c.energy)

A scene without collisions (``sim.collisions = None``, the default) runs none of this code and
compiles none of it.
"""
import math
from collections import namedtuple

import numpy as np

from .._validate import finite_float, one_of, vector

#: how a pair that touches is resolved
RESOLVE = ("bounce", "merge", "halt")

#: how candidate pairs are found: every pair, a uniform grid of cells, or chosen from N
SEARCH = ("auto", "direct", "grid")

#: when a contact is resolved: at the moment the spheres touch (found along their paths), or
#: at the end of the step as REBOUND does (``engine.collisions.end_of_step``)
RESOLVE_AT = ("contact", "end")

#: the codes the compiled kernels use (``RESOLVE`` and ``SEARCH`` by position)
RESOLVE_CODES = {name: k for k, name in enumerate(RESOLVE)}
SEARCH_CODES = {name: k for k, name in enumerate(SEARCH)}

#: what a contact record says was done (``Contact.action``), by the kernels' code
ACTIONS = ("bounce", "merge", "wall", "break")

Contact = namedtuple("Contact", "time i j speed action energy survivor")
Contact.__doc__ = """One contact resolved during a ``step``/``integrate`` call.

- ``time``: the simulation time at which the two spheres touched;
- ``i``, ``j``: the pair, ``i < j``; for a wall, ``i`` is the particle and ``j`` the wall's
  index in ``collisions.walls``;
- ``speed``: the speed at which they met: for a bounce or a wall, the normal component of
  the relative velocity (> 0); for a merge, the whole relative speed;
- ``action``: ``"bounce"``, ``"merge"``, ``"wall"``, or ``"break"`` (a spring broke:
  ``engine.forces.spring_yield``; ``i``, ``j`` its particles, ``speed`` the rate at which it
  was stretching, ``time`` the end of the step);
- ``energy``: the energy the contact took out of the system (``sim.energy_ledger`` gains it):
  (1 - e^2) mu v_n^2 / 2 for a bounce of restitution e; for a merge, the total energy of the
  state before it less after it (kinetic and the declared terms' potential);
- ``survivor``: for a merge, the index that goes on (``i``, unless only ``j`` is pinned); the
  other is deactivated. None for a bounce.
"""


class Wall:
    """A static plane particles bounce off: the points x with (x - point) . normal >= 0 are
    inside; a particle of radius r touches the wall when its centre is r from the plane and
    moving towards it, and bounces with the collisions' restitution (whatever ``resolve`` says:
    a wall is never merged with or halted on).

    ``normal`` need not be unit length (it is normalised); it must not be zero.
    """

    def __init__(self, point, normal):
        point = np.asarray(vector("point", point), dtype=float)
        normal = np.asarray(vector("normal", normal, dim=len(point)), dtype=float)
        length = math.sqrt(float(normal @ normal))
        if length == 0.0:
            raise ValueError(f"normal must not be zero, got {tuple(normal)!r}: a wall needs the "
                             "side particles stay on")
        self.point = point
        self.normal = normal / length

    @property
    def dim(self):
        return len(self.point)

    def __repr__(self):
        return f"Wall(point={tuple(self.point)!r}, normal={tuple(self.normal)!r})"


def box_walls(side, dim=2, center=None):
    """The 2 dim walls of the box of side ``side`` centred on ``center`` (the origin by
    default), normals pointing in: a gas in a box, a game's arena."""
    side = finite_float("side", side)
    if side <= 0.0:
        raise ValueError(f"side must be > 0, got {side!r}")
    if dim not in (2, 3):
        raise ValueError(f"dim must be 2 or 3, got {dim!r}")
    c = np.zeros(dim) if center is None else np.asarray(vector("center", center, dim=dim), float)
    walls = []
    for axis in range(dim):
        for sign in (1.0, -1.0):
            normal = np.zeros(dim)
            normal[axis] = sign
            point = c.copy()
            point[axis] -= sign * side / 2
            walls.append(Wall(point, normal))
    return tuple(walls)


class Collisions:
    """Contacts between particles' spheres (``sim.radius``), detected along each pair's path
    during every step and resolved at the moment they touch.

    - ``resolve``: ``"bounce"`` (hard spheres with coefficient of ``restitution``),
      ``"merge"`` (the pair becomes one body: mass, momentum and charge kept, radius from the
      summed volume in 3-D or area in 2-D), or ``"halt"`` (the step raises
      ``engine.Collision`` and the state is left at the start of that step);
    - ``restitution``: e in [0, 1], the ratio of the normal relative speeds after and before
      a bounce (walls use it too);
    - ``merge_below``: with ``resolve="bounce"``, a speed: a pair that meets slower than it
      (the normal component of the relative velocity) merges instead of bouncing (the
      accretion of rubble piles: bodies that meet slower than their escape speed stick);
      None (the default): every contact bounces;
    - ``walls``: static planes (``Wall``, ``box_walls``) every particle bounces off;
    - ``search``: how candidate pairs are found: ``"direct"`` (every pair), ``"grid"`` (a
      uniform grid of cells as large as the largest distance a sphere sweeps in a step), or
      ``"auto"`` (the grid from ``GRID_FROM`` active particles on);
    - ``resolve_at``: ``"contact"`` (the default: each contact at the moment the spheres
      touch, exact for force-free motion) or ``"end"`` (REBOUND's way, to compare with its
      ``collision = "line"``: pairs that came within reach on the segments traced back from
      the end of the step, resolved with their end-of-step state, approaching or not, by
      the lower index then the higher: ``engine.collisions.end_of_step``; every pair is
      tested, and there are no walls).
    """

    def __init__(self, resolve="bounce", restitution=1.0, walls=(), search="auto",
                 merge_below=None, resolve_at="contact"):
        resolve = one_of(*RESOLVE)("resolve", resolve)
        resolve_at = one_of(*RESOLVE_AT)("resolve_at", resolve_at)
        if merge_below is not None:
            merge_below = finite_float("merge_below", merge_below)
            if merge_below < 0.0:
                raise ValueError(f"merge_below must be >= 0 (a speed), got {merge_below!r}")
            if resolve != "bounce":
                raise ValueError(f"merge_below={merge_below!r} chooses between a bounce and a "
                                 f"merge; it needs resolve='bounce', got resolve={resolve!r}")
        restitution = finite_float("restitution", restitution)
        if not 0.0 <= restitution <= 1.0:
            raise ValueError(f"restitution must be in [0, 1], got {restitution!r} (0: the pair "
                             "stops along the line of centres; 1: no energy lost)")
        search = one_of(*SEARCH)("search", search)
        walls = tuple(walls)
        for k, wall in enumerate(walls):
            if not isinstance(wall, Wall):
                raise TypeError(f"walls[{k}] must be an engine.Wall, got {wall!r}")
        dims = {wall.dim for wall in walls}
        if len(dims) > 1:
            raise ValueError(f"walls must all have one dimension, got {sorted(dims)}")
        if resolve_at == "end" and walls:
            raise ValueError(f"resolve_at='end' resolves pairs as REBOUND does and has no "
                             f"walls; got {len(walls)} walls (use resolve_at='contact')")
        if resolve_at == "end" and search == "grid":
            raise ValueError("resolve_at='end' tests every pair, as REBOUND's line search; "
                             "got search='grid' (use search='auto' or 'direct', or "
                             "resolve_at='contact')")
        self.resolve = resolve
        self.restitution = restitution
        self.walls = walls
        self.search = search
        self.merge_below = merge_below
        self.resolve_at = resolve_at

    def wall_arrays(self, dim):
        """The walls' points and unit normals as two (3, W) arrays (z = 0 in 2-D)."""
        points = np.zeros((3, len(self.walls)))
        normals = np.zeros((3, len(self.walls)))
        for k, wall in enumerate(self.walls):
            if wall.dim != dim:
                raise ValueError(f"walls[{k}] is {wall.dim}-D and the simulation {dim}-D")
            points[:dim, k] = wall.point
            normals[:dim, k] = wall.normal
        return points, normals

    def __repr__(self):
        return (f"Collisions(resolve={self.resolve!r}, restitution={self.restitution!r}, "
                f"walls={len(self.walls)} walls, search={self.search!r}, "
                f"merge_below={self.merge_below!r}, resolve_at={self.resolve_at!r})")


def checked(value, dim):
    """``value`` if it can be a ``dim``-D scene's collisions (an ``engine.Collisions`` whose
    walls are ``dim``-D, or None), else the error naming it: what ``sim.collisions = ...`` and
    ``batch.collisions = ...`` check before anything changes."""
    if value is not None and not isinstance(value, Collisions):
        raise TypeError(f"collisions must be an engine.Collisions or None, got {value!r}")
    if value is not None:
        value.wall_arrays(dim)  # walls of another dimension: refused now
    return value


class DeclaresCollisions:
    """The ``collisions`` property a ``Simulation`` and a ``Batch`` share (their ``dim`` names
    the walls' dimension)."""

    @property
    def collisions(self):
        """How particles' spheres meet: an ``engine.Collisions``, or None (the default:
        particles pass through each other, and no contact code is compiled or run)."""
        return self._collisions

    @collisions.setter
    def collisions(self, value):
        self._collisions = checked(value, self.dim)
