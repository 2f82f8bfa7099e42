"""The broad phase: which pairs can touch during a step, in O(N) for many particles.

Each body sweeps an axis-aligned box over the step (its path from start to end, grown by its
radius). The grid's cells are as wide as the widest such box, so two boxes that overlap have
their lower corners in the same or in neighbouring cells: a body is listed under the cell of
its box's lower corner, and only the 3^dim cells around a body's cell are searched for its
partners. In open space the cells are hashed into a table of a power of two at least twice
the bodies (cells that share a slot only add candidates the narrow phase turns down); in a
periodic box of at least 3 cells a side they wrap around it. Bodies are sorted by slot with a
counting sort. (Teschner et al. 2003, "Optimized spatial hashing for collision detection of
deformable objects", give the hash; any grid text gives the rest.)

A body whose path a contact changes is listed again, from then on, under every cell its new
box covers (the box may be wider than a cell now), so the bodies searched after it find it.

One fast body widens every cell (a torpedo among slow ships): the search stays correct but
grows towards N^2; ``Collisions(search="direct")`` is then as good. ``"auto"`` takes the grid
from ``GRID_FROM`` active particles on.
"""
import math
from collections import namedtuple

import numpy as np

from ..cache import jit
from ..space import wrap_scalar
import heapq

from .narrow import NEVER, pair_time, position
from .queue import just_met, push_pair

#: from this many active particles on, ``search="auto"`` uses the grid (below it every pair)
GRID_FROM = 64

#: ``search`` codes (``settings.SEARCH`` by position)
AUTO, DIRECT, GRID = 0, 1, 2

#: the grid: whether it is used, the cell side, cells a side of a periodic box (0: open
#: space, hashed), table slots, and each slot's list of bodies (``head[slot]`` the first
#: entry, ``entries[0, e]`` its body and ``entries[1, e]`` the next entry, -1 ending it;
#: ``used[0]`` the entries in use). For the first search, the bodies sorted by slot:
#: ``start[slot]`` to ``start[slot + 1]`` index ``ids`` (their numbers) and copies of their
#: paths and radii, ``Xs``, ``Ds``, ``rs``, so that neighbouring cells' bodies are
#: neighbours in memory (at 10^5 bodies the search by index order waited on memory)
Cells = namedtuple("Cells", "use side per_side slots head entries used start ids Xs Ds rs")

#: the hash's primes (Teschner et al. 2003)
_P1, _P2, _P3 = 73856093, 19349663, 83492791


@jit(error_model="numpy", inline="always")
def _sweep(X, D, radius, k, axis, box):
    """The lower and upper edge, along ``axis``, of the box body k sweeps over the step (from
    its start, taken into the periodic box)."""
    a = wrap_scalar(X[axis, k], box)
    b = a + D[axis, k]
    r = radius[k]
    return min(a, b) - r, max(a, b) + r


@jit(error_model="numpy", inline="always")
def _cell(x, side, per_side, box):
    """The cell coordinate of x: its index in a periodic box, an unbounded integer in open
    space."""
    if per_side > 0:
        c = int(math.floor((x + 0.5 * box) / side)) % per_side
        return c if c >= 0 else c + per_side
    return int(math.floor(x / side))


@jit(error_model="numpy", inline="always")
def _slot(cx, cy, cz, slots):
    """The table slot of cell (cx, cy, cz)."""
    return ((cx * _P1) ^ (cy * _P2) ^ (cz * _P3)) & (slots - 1)


@jit(error_model="numpy", inline="always")
def _slot_of(cx, cy, cz, per_side, slots):
    """The slot of a cell: its index in a periodic box (wrapped), its hash in open space."""
    if per_side > 0:
        cx %= per_side
        cy %= per_side
        cz %= per_side
        return (cz * per_side + cy) * per_side + cx
    return _slot(cx, cy, cz, slots)


@jit(error_model="numpy", inline="always")
def _corner_cells(X, D, radius, k, side, per_side, box):
    """The cell coordinates of body k's box's lower corner."""
    dim = X.shape[0]
    cx = _cell(_sweep(X, D, radius, k, 0, box)[0], side, per_side, box)
    cy = _cell(_sweep(X, D, radius, k, 1, box)[0], side, per_side, box)
    cz = _cell(_sweep(X, D, radius, k, 2, box)[0], side, per_side, box) if dim == 3 else 0
    return cx, cy, cz


@jit(error_model="numpy")
def build(X, D, radius, active, n, box, search, live):
    """The grid of this step's swept boxes, or an unused one (``use`` False) when every pair
    is to be searched: ``search`` direct, or auto below ``GRID_FROM`` active particles, or a
    periodic box too small for 3 cells a side."""
    dim = X.shape[0]
    none = Cells(False, 1.0, 0, 1, np.full(1, -1, dtype=np.int64),
                 np.zeros((2, 1), dtype=np.int64), np.zeros(1, dtype=np.int64),
                 np.zeros(2, dtype=np.int64), np.zeros(1, dtype=np.int64), np.zeros((dim, 1)),
                 np.zeros((dim, 1)), np.zeros(1))
    if search == DIRECT or (search == AUTO and live < GRID_FROM):
        return none
    side = 0.0
    for k in range(n):
        if active[k]:
            for axis in range(dim):
                lo, hi = _sweep(X, D, radius, k, axis, box)
                side = max(side, hi - lo)
    if side == 0.0:
        side = 1.0  # nothing has extent: any cell size finds the coincident pairs
    per_side = 0
    if box > 0.0:
        per_side = int(math.floor(box / side))
        if per_side < 3:
            return none
        slots = per_side ** dim
    else:
        slots = 1
        while slots < 2 * live:
            slots *= 2
    keys = np.empty(n, dtype=np.int64)
    start = np.zeros(slots + 1, dtype=np.int64)
    for k in range(n):
        if active[k]:
            cx, cy, cz = _corner_cells(X, D, radius, k, side, per_side, box)
            keys[k] = _slot_of(cx, cy, cz, per_side, slots)
            start[keys[k] + 1] += 1
    for c in range(slots):
        start[c + 1] += start[c]
    fill = start[:slots].copy()
    ids = np.empty(live, dtype=np.int64)
    Xs = np.empty((dim, live))
    Ds = np.empty((dim, live))
    rs = np.empty(live)
    for k in range(n):
        if active[k]:
            a = fill[keys[k]]
            fill[keys[k]] += 1
            ids[a] = k
            for axis in range(dim):
                Xs[axis, a] = X[axis, k]
                Ds[axis, a] = D[axis, k]
            rs[a] = radius[k]
    cells = Cells(True, side, per_side, slots, np.full(slots, -1, dtype=np.int64),
                  np.empty((2, 2 * live + 16), dtype=np.int64), np.zeros(1, dtype=np.int64),
                  start, ids, Xs, Ds, rs)
    # listed in descending index order, so that each slot's list runs in ascending order
    for k in range(n - 1, -1, -1):
        if active[k]:
            cells = _list(cells, keys[k], k)
    return cells


@jit(error_model="numpy", inline="always")
def _list(cells, key, k):
    """Body k listed under slot ``key`` (at the head of its list); the entries grow (doubled)
    when full, so the grid that comes back may be a new one."""
    used = cells.used[0]
    entries = cells.entries
    if used == entries.shape[1]:
        grown = np.empty((2, 2 * used), dtype=np.int64)
        grown[:, :used] = entries
        entries = grown
        cells = Cells(cells.use, cells.side, cells.per_side, cells.slots, cells.head, entries,
                      cells.used, cells.start, cells.ids, cells.Xs, cells.Ds, cells.rs)
    entries[0, used] = k
    entries[1, used] = cells.head[key]
    cells.head[key] = used
    cells.used[0] = used + 1
    return cells


@jit(error_model="numpy", inline="always")
def _span(lo, hi, side, per_side, box):
    """The cells an interval [lo, hi] covers along one axis, unwrapped (every cell of a
    periodic axis when it spans them all)."""
    first = _cell(lo, side, 0, box) if per_side == 0 else \
        int(math.floor((lo + 0.5 * box) / side))
    last = _cell(hi, side, 0, box) if per_side == 0 else \
        int(math.floor((hi + 0.5 * box) / side))
    if per_side > 0 and last - first + 1 >= per_side:
        return 0, per_side - 1
    return first, last


@jit(error_model="numpy", inline="always")
def _around(c, per_side):
    """The cell coordinates c - 1, c, c + 1 along one axis, wrapped in a periodic box without
    a division (with ``%`` the first search took 85 ms at 10^5 bodies, 69 ms without)."""
    if per_side == 0:
        return c - 1, c, c + 1
    below = c - 1 if c > 0 else per_side - 1
    above = c + 1 if c < per_side - 1 else 0
    return below, c, above


@jit(error_model="numpy", inline="always")
def _key(cx, cy, cz, per_side, slots):
    """The slot of a cell whose coordinates are already in range (periodic), or its hash."""
    if per_side > 0:
        return (cz * per_side + cy) * per_side + cx
    return _slot(cx, cy, cz, slots)


@jit(error_model="numpy")
def all_pairs(cells, X, D, anchor, radius, box, events, version, active):
    """Queue the first contact of every pair the grid puts near each other (each pair once),
    over the bodies sorted by cell (``Cells.Xs``...; every body is at its start, version 0)."""
    dim = X.shape[0]
    per_side, slots = cells.per_side, cells.slots
    start, ids, Xs, Ds, rs = cells.start, cells.ids, cells.Xs, cells.Ds, cells.rs
    for a in range(ids.shape[0]):
        k = ids[a]
        cx, cy, cz = _corner_cells(Xs, Ds, rs, a, cells.side, per_side, box)
        xs = _around(cx, per_side)
        ys = _around(cy, per_side)
        zs = _around(cz, per_side) if dim == 3 else (cz, cz, cz)
        for iz in range(3 if dim == 3 else 1):
            for iy in range(3):
                for ix in range(3):
                    key = _key(xs[ix], ys[iy], zs[iz], per_side, slots)
                    for b in range(start[key], start[key + 1]):
                        other = ids[b]
                        if other > k:
                            # as every-pair search computes it: the lower index first
                            s = pair_time(Xs, Ds, anchor, rs, a, b, 0.0, box)
                            if s != NEVER:
                                heapq.heappush(events, (s, float(k), float(other), 0.0, 0.0))


@jit(error_model="numpy")
def for_near(cells, X, D, anchor, radius, k, s0, box, events, version, active, last_partner,
             last_time):
    """Queue body k's first contact from s0 on with every body the grid lists near k's path
    from s0 to the end of the step; then list k under every cell its new box covers. Returns
    the grid (a new one if its entries grew)."""
    dim = X.shape[0]
    side, per_side = cells.side, cells.per_side
    lo = np.zeros(3)
    hi = np.zeros(3)
    for axis in range(dim):
        a = wrap_scalar(position(X, D, anchor, k, s0, axis), box)
        b = a + (1.0 - s0) * D[axis, k]
        lo[axis] = min(a, b) - radius[k]
        hi[axis] = max(a, b) + radius[k]
    x0, x1 = _span(lo[0] - side, hi[0], side, per_side, box)
    y0, y1 = _span(lo[1] - side, hi[1], side, per_side, box)
    z0, z1 = (_span(lo[2] - side, hi[2], side, per_side, box) if dim == 3 else (0, 0))
    for cz in range(z0, z1 + 1):
        for cy in range(y0, y1 + 1):
            for cx in range(x0, x1 + 1):
                e = cells.head[_slot_of(cx, cy, cz, per_side, cells.slots)]
                while e >= 0:
                    other = cells.entries[0, e]
                    if other != k and active[other] and \
                            not just_met(last_partner, last_time, k, other, s0):
                        push_pair(events, X, D, anchor, radius, version, k, other, s0, box)
                    e = cells.entries[1, e]
    x0, x1 = _span(lo[0], hi[0], side, per_side, box)
    y0, y1 = _span(lo[1], hi[1], side, per_side, box)
    z0, z1 = (_span(lo[2], hi[2], side, per_side, box) if dim == 3 else (0, 0))
    for cz in range(z0, z1 + 1):
        for cy in range(y0, y1 + 1):
            for cx in range(x0, x1 + 1):
                cells = _list(cells, _slot_of(cx, cy, cz, per_side, cells.slots), k)
    return cells
