"""Contacts found and resolved at the end of the step, as REBOUND does
(``Collisions(resolve_at="end")``): for comparing with REBOUND's ``collision = "line"``.

REBOUND's "line" search (Rein & Liu 2012, A&A 537, A128, section 4.2; ``src/collision.c``)
looks at each pair once the step is over. It traces the pair back from its end positions
along its end velocities over the step just taken, h, and flags it when the closest
approach on that segment is within the summed radii:

    d1 = x_j - x_i (end, nearest image),   u = v_j - v_i (end),   d2 = d1 - h u,
    t* = (d1 . u) / |u|^2,   r_min^2 = min(|d1|^2, |d2|^2, |d1 - t* u|^2 if 0 <= t* <= h),

whether the pair is approaching or not. Each flagged pair is then resolved with its
end-of-step state: a merge puts the merged body at the pair's centre of mass at the end of
the step with its summed momentum; a bounce changes the end velocities only, and only when
the pair approaches at the end (REBOUND's ``hardsphere``). A body absorbed by a merge takes
part in no later contact of that step; the survivor does, with its merged state.

Where this differs from REBOUND: REBOUND resolves the flagged pairs in an order shuffled by
its random seed; here they go by the lower index, then the higher (the order is documented
and the same on every run). Every pair is tested (O(N^2), as REBOUND's "line" search);
walls need ``resolve_at="contact"``.

``engine.collisions.events`` is the default: each contact at the moment of touching, found
along the bodies' paths, exact for force-free motion.
"""
import numpy as np

from ..cache import jit
from ..space import wrap_scalar
from .events import (BOUNCED, DONE, HALT, HALTED, MERGE, MERGED, closing_speed,
                     total_energy)
from .resolve import bounce, merge, relative_speed, survivor_of


@jit(error_model="numpy", inline="always")
def closest_approach_squared(pos, vel, i, j, h, box):
    """r_min^2: the squared least distance of i and j on the segment traced back from their
    end positions along their end velocities over h (REBOUND's "line" search)."""
    dim = pos.shape[0]
    dx = wrap_scalar(pos[0, j] - pos[0, i], box)
    dy = wrap_scalar(pos[1, j] - pos[1, i], box)
    ux = vel[0, j] - vel[0, i]
    uy = vel[1, j] - vel[1, i]
    dz = 0.0
    uz = 0.0
    if dim == 3:
        dz = wrap_scalar(pos[2, j] - pos[2, i], box)
        uz = vel[2, j] - vel[2, i]
    bx, by, bz = dx - h * ux, dy - h * uy, dz - h * uz
    least = min(dx * dx + dy * dy + dz * dz, bx * bx + by * by + bz * bz)
    uu = ux * ux + uy * uy + uz * uz
    if uu > 0.0:
        t_closest = (dx * ux + dy * uy + dz * uz) / uu
        if 0.0 <= t_closest / h <= 1.0:
            cx, cy, cz = dx - t_closest * ux, dy - t_closest * uy, dz - t_closest * uz
            least = min(least, cx * cx + cy * cy + cz * cz)
    return least


@jit(error_model="numpy")
def flagged_pairs(pos, vel, radius, active, n, h, box):
    """The pairs (i < j, in that order) whose spheres came within reach on the segments
    traced back over h: REBOUND's "line" search."""
    pairs = [(0, 0)]
    pairs.pop()
    for i in range(n):
        if not active[i]:
            continue
        for j in range(i + 1, n):
            if not active[j]:
                continue
            reach = radius[i] + radius[j]
            if closest_approach_squared(pos, vel, i, j, h, box) <= reach * reach:
                pairs.append((i, j))
    return pairs


@jit(error_model="numpy")
def collide_at_end(t0, h, state, model, p0, v0, resolve, restitution, points, normals,
                   search, contacts, merge_below=-1.0):
    """Find and resolve the contacts of the step just taken, REBOUND's way (the module's
    docstring); the same arguments and results as ``events.collide`` (``p0``, ``v0``,
    ``points``, ``normals`` and ``search`` are not used: the segments are traced back from
    the end, and walls and the grid belong to ``resolve_at="contact"``)."""
    n = state.n
    box = state.box
    dim = state.pos.shape[0]
    pos, v1 = state.pos, state.vel
    active, pinned, radius = state.active, state.pinned, state.radius
    # each body as a path that is where the state says at fraction 1 (anchored there), so
    # the resolutions of ``engine.collisions.resolve`` act on the end-of-step state
    X = pos[:, :n].copy()
    D = np.empty((dim, n))
    for k in range(n):
        for axis in range(dim):
            D[axis, k] = h * v1[axis, k]
    anchor = np.ones(n)
    vs = v1[:, :n].copy()
    energies = np.zeros(model.kinds.shape[0])
    t = t0 + h
    for i, j in flagged_pairs(pos, v1, radius, active, n, h, box):
        if not (active[i] and active[j]):
            continue  # absorbed by an earlier merge of this step
        if resolve == HALT:
            return HALTED, i * n + j, t, closing_speed(X, D, anchor, vs, v1, i, j, 1.0, box)
        if resolve == MERGE or (merge_below > 0.0 and
                                closing_speed(X, D, anchor, vs, v1, i, j, 1.0, box) <
                                merge_below):
            speed = relative_speed(vs, v1, i, j, 1.0)
            keep, gone = survivor_of(pinned, i, j)
            before = total_energy(t, state, model, energies)
            merge(X, D, anchor, vs, v1, pos, state.mass, state.charge, radius, pinned, active,
                  keep, gone, 1.0, box)
            energy = before - total_energy(t, state, model, energies)
            contacts.append((t, float(i), float(j), speed, MERGED, energy, float(keep)))
        else:
            un, energy = bounce(X, D, anchor, vs, v1, pos, state.mass, pinned, i, j, 1.0, h,
                                box, restitution)
            if un < 0.0:
                contacts.append((t, float(i), float(j), -un, BOUNCED, energy, -1.0))
    return DONE, -1, 0.0, 0.0
