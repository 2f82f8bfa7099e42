"""One step's contacts, found and resolved in the order they happen (the event loop).

After the integrator has taken a step from positions p0 and velocities v0 to the state's
positions and velocities, every body is taken to have moved on a straight path over the step
(``engine.collisions.narrow``). The loop then:

1. finds, for every candidate pair (every pair, or the pairs a uniform grid of cells puts
   near each other: ``engine.collisions.grid``) and every body and wall, the first fraction of
   the step at which they touch while approaching, and queues these events;
2. takes the earliest event (ties by the lower index, then the higher: a fixed order, so the
   result is the same on every run), drops it if a body in it has moved off the path it was
   found on, resolves it (``engine.collisions.resolve``: bounce, merge, or halt), and records
   it;
3. searches again, from that moment to the end of the step, for the bodies whose paths
   changed, against every body near their new path (the grid lists a changed body again
   under the cells of its new path), and queues what it finds;

until no event is left. A chain (Newton's cradle) is resolved within one step: each contact
sets the next pair approaching at the same moment. A pair that has just bounced is not
searched again at the same moment (under forces, the paths may still close by round-off).
"""
import heapq
import math

import numpy as np

from ..cache import jit
from ..forces.dispatch import potential_terms
from ..space import wrap_scalar
from . import grid
from .queue import just_met, push_pair, push_walls
from .resolve import (bounce, bounce_off_wall, merge, normal_speed, relative_speed,
                      survivor_of)
from .narrow import separation

#: ``resolve`` codes (``settings.RESOLVE`` by position)
BOUNCE, MERGE, HALT = 0, 1, 2
#: contact record codes (``settings.ACTIONS`` by position)
BOUNCED, MERGED, WALL = 0.0, 1.0, 2.0

#: the step's status: done, halted on a contact, or too many contacts in one step
DONE, HALTED, TOO_MANY = 0, 1, 2

#: contacts one step may resolve, per active particle (plus a constant): more means an
#: inelastic collapse (restitution < 1 can give infinitely many contacts in a finite time)
CONTACTS_PER_PARTICLE = 64


@jit(error_model="numpy", inline="always")
def total_energy(t, state, model, out):
    """The state's total energy: kinetic of the moving particles plus every term's potential."""
    dim = state.pos.shape[0]
    kinetic = 0.0
    for k in range(state.n):
        if state.active[k] and not state.pinned[k]:
            v2 = 0.0
            for axis in range(dim):
                v2 += state.vel[axis, k] * state.vel[axis, k]
            kinetic += 0.5 * state.mass[k] * v2
    out[:] = 0.0
    potential_terms(t, state, model, out)
    return kinetic + out.sum()


@jit(error_model="numpy", inline="always")
def _search_again(events, X, D, anchor, radius, version, active, k, s0, box, points, normals,
                  n, cells, last_partner, last_time):
    """Queue body k's contacts from s0 on, after its path changed: against the bodies the grid
    lists near its new path (every body when there is no grid), and the walls. Returns the
    grid (``grid.for_near`` lists k under its new cells)."""
    if cells.use:
        cells = grid.for_near(cells, X, D, anchor, radius, k, s0, box, events, version, active,
                              last_partner, last_time)
    else:
        for other in range(n):
            if other != k and active[other] and not just_met(last_partner, last_time, k,
                                                              other, s0):
                push_pair(events, X, D, anchor, radius, version, k, other, s0, box)
    push_walls(events, X, D, anchor, radius, version, k, s0, points, normals, n)
    return cells


@jit(error_model="numpy", inline="always")
def closing_speed(X, D, anchor, v0, v1, i, j, s, box):
    """-u_n: how fast i and j close along their line of centres at fraction s (0 when their
    centres coincide)."""
    dx, dy, dz = separation(X, D, anchor, i, j, s, box)
    dist = math.sqrt(dx * dx + dy * dy + dz * dz)
    if dist == 0.0:
        return 0.0
    return -normal_speed(v0, v1, i, j, s, dx / dist, dy / dist, dz / dist)


@jit(error_model="numpy")
def collide(t0, h, state, model, p0, v0, resolve, restitution, points, normals, search,
            contacts, merge_below=-1.0):
    """Find and resolve the contacts of the step just taken from (p0, v0) to the state's
    positions and velocities (which it changes), from time t0 over h; with ``resolve`` BOUNCE,
    a pair meeting at a normal speed below ``merge_below`` merges. Appends to ``contacts``
    one (time, i, j, speed, action, energy, survivor) tuple per contact, in order. Returns (status,
    index of the halting contact's pair as i * n + j, its time, its speed)."""
    n = state.n
    box = state.box
    dim = state.pos.shape[0]
    pos, v1 = state.pos, state.vel
    active, pinned, radius = state.active, state.pinned, state.radius
    # the paths: each body at p0 at fraction 0, moving by its step's displacement
    X = p0.copy()
    D = np.empty((dim, n))
    for k in range(n):
        for axis in range(dim):
            D[axis, k] = wrap_scalar(pos[axis, k] - p0[axis, k], box)
    anchor = np.zeros(n)
    v0 = v0.copy()
    version = np.zeros(n, dtype=np.int64)
    last_partner = np.full(n, -1, dtype=np.int64)
    last_time = np.full(n, -1.0)
    energies = np.zeros(model.kinds.shape[0])
    events = [(0.0, 0.0, 0.0, 0.0, 0.0)]
    events.pop()
    live = 0
    for k in range(n):
        if active[k]:
            live += 1
    cells = grid.build(X, D, radius, active, n, box, search, live)
    if cells.use:
        grid.all_pairs(cells, X, D, anchor, radius, box, events, version, active)
    else:
        for i in range(n):
            if active[i]:
                for j in range(i + 1, n):
                    if active[j]:
                        push_pair(events, X, D, anchor, radius, version, i, j, 0.0, box)
    for k in range(n):
        if active[k]:
            push_walls(events, X, D, anchor, radius, version, k, 0.0, points, normals, n)
    budget = CONTACTS_PER_PARTICLE * live + 1024
    while len(events) > 0:
        s, fi, fj, vi, vj = heapq.heappop(events)
        i = int(fi)
        j = int(fj)
        if not active[i] or version[i] != int(vi):
            continue
        wall = j >= n
        if not wall and (not active[j] or version[j] != int(vj)):
            continue
        budget -= 1
        if budget < 0:
            return TOO_MANY, -1, t0 + s * h, 0.0
        if wall:
            speed, energy = bounce_off_wall(X, D, anchor, v0, v1, pos, state.mass, pinned, i,
                                            s, h, box, restitution, points, normals, j - n)
            touched = (i, i)
            action = WALL
            j_record = j - n
        elif resolve == HALT:
            return HALTED, i * n + j, t0 + s * h, closing_speed(X, D, anchor, v0, v1, i, j,
                                                                   s, box)
        elif resolve == MERGE or (merge_below > 0.0 and
                                  closing_speed(X, D, anchor, v0, v1, i, j, s, box) <
                                  merge_below):
            speed = relative_speed(v0, v1, i, j, s)
            keep, gone = survivor_of(pinned, i, j)
            before = total_energy(t0 + h, state, model, energies)
            merge(X, D, anchor, v0, v1, pos, state.mass, state.charge, radius, pinned, active,
                  keep, gone, s, box)
            energy = before - total_energy(t0 + h, state, model, energies)
            touched = (keep, keep)
            action = MERGED
            j_record = j
        else:
            un, energy = bounce(X, D, anchor, v0, v1, pos, state.mass, pinned, i, j, s, h, box,
                                restitution)
            speed = -un
            last_partner[i] = j
            last_time[i] = s
            last_partner[j] = i
            last_time[j] = s
            touched = (i, j)
            action = BOUNCED
            j_record = j
            if not un < 0.0:
                continue  # not approaching at that moment: nothing done, nothing recorded
        contacts.append((t0 + s * h, float(i), float(j_record), speed, action, energy,
                         float(touched[0]) if action == MERGED else -1.0))
        for k in touched:
            version[k] += 1
        cells = _search_again(events, X, D, anchor, radius, version, active, touched[0], s,
                              box, points, normals, n, cells, last_partner, last_time)
        if touched[1] != touched[0]:
            cells = _search_again(events, X, D, anchor, radius, version, active, touched[1], s,
                                  box, points, normals, n, cells, last_partner, last_time)
    return DONE, -1, 0.0, 0.0
