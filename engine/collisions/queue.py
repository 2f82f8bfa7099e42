"""The event queue of a step's contacts: a binary heap of (fraction of the step, lower index,
higher index, the two bodies' path versions), all floats so numba keeps one tuple type. The
heap's order is the contacts' order: by time, then by the lower index, then the higher (a
wall w counts as index n + w). An event whose body has since changed its path (its version
moved on) is stale and dropped when it comes up."""
import heapq

from ..cache import jit
from .narrow import NEVER, pair_time, wall_time


@jit(error_model="numpy", inline="always")
def push_pair(events, X, D, anchor, radius, version, i, j, s0, box):
    """Queue the first contact of i and j from s0 on, if any."""
    lo, hi = (i, j) if i < j else (j, i)
    s = pair_time(X, D, anchor, radius, lo, hi, s0, box)
    if s != NEVER:
        heapq.heappush(events, (s, float(lo), float(hi), float(version[lo]),
                                float(version[hi])))


@jit(error_model="numpy", inline="always")
def push_walls(events, X, D, anchor, radius, version, k, s0, points, normals, n):
    """Queue body k's first contact with each wall from s0 on (wall w as index n + w)."""
    for w in range(points.shape[1]):
        s = wall_time(X, D, anchor, radius, k, s0, points, normals, w)
        if s != NEVER:
            heapq.heappush(events, (s, float(k), float(n + w), float(version[k]), 0.0))


@jit(error_model="numpy", inline="always")
def just_met(last_partner, last_time, i, j, s):
    """Did i and j bounce off each other at exactly fraction s? (Then they are not searched
    again at s: under forces their paths may still close by round-off.)"""
    return (last_partner[i] == j and last_time[i] == s) or \
        (last_partner[j] == i and last_time[j] == s)
