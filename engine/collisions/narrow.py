"""When two moving spheres, or a sphere and a wall, first touch during a step (the narrow
phase), each body moving on a straight path over the step.

A body's path over the step is ``x(s) = X + (s - a) D`` for the step's fraction s in [a, 1]:
it was at X at fraction a and moves D per whole step (D = the step's displacement, by the
nearest image in a periodic space; a contact changes X, a and D of the bodies it touches).
For a pair, the separation d(s) = d0 + (s - s0) w with w = D_j - D_i; they touch when
|d(s)| = r_i + r_j, the smaller root of

    |w|^2 u^2 + 2 (d0 . w) u + |d0|^2 - R^2 = 0,   u = s - s0,

taken as u = c / (-b + sqrt(b^2 - a c)) (b = d0 . w < 0, c = |d0|^2 - R^2), the form without
cancellation. Only approaching pairs touch (b < 0, as in REBOUND: a pair already separating is
left alone); a pair that overlaps and approaches at s0 touches at s0. This is REBOUND's "line"
search (Rein & Liu 2012, A&A 537, A128, section 4.2) taken to the exact time of contact.
"""
import math

from ..cache import jit
from ..space import wrap_scalar

#: no contact in this step
NEVER = math.inf


@jit(error_model="numpy", inline="always")
def position(X, D, anchor, k, s, axis):
    """Component ``axis`` of body k's position at fraction s of the step."""
    return X[axis, k] + (s - anchor[k]) * D[axis, k]


@jit(error_model="numpy", inline="always")
def separation(X, D, anchor, i, j, s, box):
    """d = x_j(s) - x_i(s) by the nearest image, as three floats (z = 0 in 2-D)."""
    dim = X.shape[0]
    dx = wrap_scalar(position(X, D, anchor, j, s, 0) - position(X, D, anchor, i, s, 0), box)
    dy = wrap_scalar(position(X, D, anchor, j, s, 1) - position(X, D, anchor, i, s, 1), box)
    dz = 0.0
    if dim == 3:
        dz = wrap_scalar(position(X, D, anchor, j, s, 2) - position(X, D, anchor, i, s, 2), box)
    return dx, dy, dz


@jit(error_model="numpy", inline="always")
def relative_rate(D, i, j):
    """w = D_j - D_i: how the separation changes per whole step."""
    dim = D.shape[0]
    wz = D[2, j] - D[2, i] if dim == 3 else 0.0
    return D[0, j] - D[0, i], D[1, j] - D[1, i], wz


@jit(error_model="numpy", inline="always")
def pair_time(X, D, anchor, radius, i, j, s0, box):
    """The first fraction s in [s0, 1] at which spheres i and j touch while approaching, or
    ``NEVER``."""
    dx, dy, dz = separation(X, D, anchor, i, j, s0, box)
    wx, wy, wz = relative_rate(D, i, j)
    b = dx * wx + dy * wy + dz * wz
    if not b < 0.0:
        return NEVER
    reach = radius[i] + radius[j]
    c = dx * dx + dy * dy + dz * dz - reach * reach
    if c <= 0.0:
        return s0
    a = wx * wx + wy * wy + wz * wz
    disc = b * b - a * c
    if disc < 0.0:
        return NEVER
    s = s0 + c / (-b + math.sqrt(disc))
    return s if s <= 1.0 else NEVER


@jit(error_model="numpy", inline="always")
def wall_time(X, D, anchor, radius, k, s0, points, normals, w):
    """The first fraction s in [s0, 1] at which sphere k touches wall w while moving towards
    it, or ``NEVER``: the gap g(s) = (x(s) - q) . n - r falls to 0."""
    dim = X.shape[0]
    gap = -radius[k]
    rate = 0.0
    for axis in range(dim):
        gap += (position(X, D, anchor, k, s0, axis) - points[axis, w]) * normals[axis, w]
        rate += D[axis, k] * normals[axis, w]
    if not rate < 0.0:
        return NEVER
    if gap <= 0.0:
        return s0
    s = s0 + gap / -rate
    return s if s <= 1.0 else NEVER
