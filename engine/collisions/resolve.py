"""What a contact does to the two bodies (or the body and the wall) at the moment they touch.

Each body carries its path over the step (``engine.collisions.narrow``: at X at fraction a,
moving D per whole step), its velocity at the start and at the end of the step (v0, v1; its
velocity at fraction s is taken as v0 + s (v1 - v0)), and its end-of-step position (what the
state holds: X + (1 - a) D, wrapped). A contact at fraction s re-anchors the bodies it touches
at s and changes D, v0 and v1 by the same velocity change dv (D by h dv): after the contact
each goes on along a straight line with its new velocity for the rest of the step. Exact for
force-free motion; under forces the velocity at contact is good to O(h^2).

Bounce (hard spheres, coefficient of restitution e; e.g. Goldstein, Classical Mechanics, or
any text on impulsive collisions): with n the unit vector from i to j and u_n the normal
component of the relative velocity u_j - u_i (< 0: approaching), the impulse along n is

    J = -(1 + e) u_n / (1/m_i + 1/m_j),   dv_i = -J n / m_i,   dv_j = +J n / m_j,

which keeps the momentum and turns u_n into -e u_n; the kinetic energy falls by
(1 - e^2) mu u_n^2 / 2 with mu = m_i m_j / (m_i + m_j). A pinned body has infinite mass
(1/m = 0); a massless one takes the whole change (the limit m -> 0).

Merge: the bodies become one, where their centre of mass is, with their summed mass, momentum
and charge and the radius of their summed volume (3-D) or area (2-D); REBOUND's
``reb_collision_resolve_merge`` does the same. The lower index survives (so indices a game holds
stay valid and match REBOUND's choice), unless the higher one is pinned: a pinned body
absorbs what hits it and stays where it is.
"""
import math

from ..cache import jit
from ..space import wrap_scalar
from .narrow import position, separation


@jit(error_model="numpy", inline="always")
def inverse_mass(mass, pinned, k):
    """1/m_k: 0 for a pinned body (infinite mass), infinity for a massless one."""
    if pinned[k]:
        return 0.0
    if mass[k] > 0.0:
        return 1.0 / mass[k]
    return math.inf


@jit(error_model="numpy", inline="always")
def contact_velocity(v0, v1, k, s, axis):
    """Body k's velocity component at fraction s of the step."""
    return v0[axis, k] + s * (v1[axis, k] - v0[axis, k])


@jit(error_model="numpy", inline="always")
def reanchor(X, D, anchor, k, s):
    """Body k's path restarted at fraction s from where it is then."""
    dim = X.shape[0]
    for axis in range(dim):
        X[axis, k] = position(X, D, anchor, k, s, axis)
    anchor[k] = s


@jit(error_model="numpy", inline="always")
def end_position(X, D, anchor, pos, k, box):
    """The state's position of k: where its path ends, in the box."""
    dim = X.shape[0]
    for axis in range(dim):
        pos[axis, k] = wrap_scalar(X[axis, k] + (1.0 - anchor[k]) * D[axis, k], box)


@jit(error_model="numpy", inline="always")
def kick(X, D, anchor, v0, v1, pos, k, s, h, box, nx, ny, nz, amount):
    """Body k's velocity changes by ``amount`` along n at fraction s: D, v0, v1 and the end
    position follow."""
    dim = X.shape[0]
    reanchor(X, D, anchor, k, s)
    n = (nx, ny, nz)
    for axis in range(dim):
        dv = amount * n[axis]
        D[axis, k] += h * dv
        v0[axis, k] += dv
        v1[axis, k] += dv
    end_position(X, D, anchor, pos, k, box)


@jit(error_model="numpy", inline="always")
def normal_speed(v0, v1, i, j, s, nx, ny, nz):
    """u_n = (u_j - u_i) . n at fraction s."""
    dim = v0.shape[0]
    n = (nx, ny, nz)
    un = 0.0
    for axis in range(dim):
        un += (contact_velocity(v0, v1, j, s, axis) - contact_velocity(v0, v1, i, s, axis)) * n[axis]
    return un


@jit(error_model="numpy", inline="always")
def bounce(X, D, anchor, v0, v1, pos, mass, pinned, i, j, s, h, box, e):
    """Hard-sphere bounce of i and j touching at fraction s. Returns (u_n, energy removed);
    u_n >= 0 (not approaching at that moment, under forces) changes nothing."""
    dx, dy, dz = separation(X, D, anchor, i, j, s, box)
    dist = math.sqrt(dx * dx + dy * dy + dz * dz)
    if dist == 0.0:
        return 0.0, 0.0  # coincident centres: no line of centres to push along
    nx, ny, nz = dx / dist, dy / dist, dz / dist
    un = normal_speed(v0, v1, i, j, s, nx, ny, nz)
    if not un < 0.0:
        return un, 0.0
    wi = inverse_mass(mass, pinned, i)
    wj = inverse_mass(mass, pinned, j)
    if math.isinf(wi) and math.isinf(wj):
        wi = 1.0  # two massless bodies: as two equal masses
        wj = 1.0
    if wi + wj == 0.0:
        return un, 0.0  # two pinned bodies: nothing can move
    if math.isinf(wi):
        change_i, change_j, mu = (1.0 + e) * un, 0.0, 0.0
    elif math.isinf(wj):
        change_i, change_j, mu = 0.0, -(1.0 + e) * un, 0.0
    else:
        impulse = -(1.0 + e) * un / (wi + wj)
        change_i, change_j, mu = -impulse * wi, impulse * wj, 1.0 / (wi + wj)
    if change_i != 0.0:
        kick(X, D, anchor, v0, v1, pos, i, s, h, box, nx, ny, nz, change_i)
    if change_j != 0.0:
        kick(X, D, anchor, v0, v1, pos, j, s, h, box, nx, ny, nz, change_j)
    return un, 0.5 * mu * un * un * (1.0 - e * e)


@jit(error_model="numpy", inline="always")
def bounce_off_wall(X, D, anchor, v0, v1, pos, mass, pinned, k, s, h, box, e, points,
                    normals, w):
    """Body k bounces off wall w at fraction s. Returns (-u_n, energy removed)."""
    dim = X.shape[0]
    nx, ny, nz = normals[0, w], normals[1, w], normals[2, w]
    un = 0.0
    n = (nx, ny, nz)
    for axis in range(dim):
        un += contact_velocity(v0, v1, k, s, axis) * n[axis]
    if not un < 0.0 or pinned[k]:
        return -un, 0.0
    kick(X, D, anchor, v0, v1, pos, k, s, h, box, nx, ny, nz, -(1.0 + e) * un)
    m = mass[k] if mass[k] > 0.0 else 0.0
    return -un, 0.5 * m * un * un * (1.0 - e * e)


@jit(error_model="numpy", inline="always")
def survivor_of(pinned, i, j):
    """The body a merge of i < j keeps: j if only j is pinned, else i."""
    if pinned[j] and not pinned[i]:
        return j, i
    return i, j


@jit(error_model="numpy", inline="always")
def relative_speed(v0, v1, i, j, s):
    """|u_j - u_i| at fraction s."""
    dim = v0.shape[0]
    total = 0.0
    for axis in range(dim):
        du = contact_velocity(v0, v1, j, s, axis) - contact_velocity(v0, v1, i, s, axis)
        total += du * du
    return math.sqrt(total)


@jit(error_model="numpy", inline="always")
def merge(X, D, anchor, v0, v1, pos, mass, charge, radius, pinned, active, keep, gone, s,
          box):
    """Body ``gone`` merges into ``keep`` at fraction s; ``gone`` is deactivated."""
    dim = X.shape[0]
    mk, mg = mass[keep], mass[gone]
    if pinned[keep]:
        wk, wg = 1.0, 0.0
    elif mk + mg > 0.0:
        wk, wg = mk / (mk + mg), mg / (mk + mg)
    else:
        wk, wg = 0.5, 0.5
    d = separation(X, D, anchor, keep, gone, s, box)
    reanchor(X, D, anchor, keep, s)
    for axis in range(dim):
        X[axis, keep] += wg * d[axis]
        D[axis, keep] = wk * D[axis, keep] + wg * D[axis, gone]
        v0[axis, keep] = wk * v0[axis, keep] + wg * v0[axis, gone]
        v1[axis, keep] = wk * v1[axis, keep] + wg * v1[axis, gone]
    mass[keep] = mk + mg
    charge[keep] += charge[gone]
    rk, rg = radius[keep], radius[gone]
    if dim == 3:
        radius[keep] = (rk * rk * rk + rg * rg * rg) ** (1.0 / 3.0)
    else:
        radius[keep] = math.sqrt(rk * rk + rg * rg)
    active[gone] = False
    end_position(X, D, anchor, pos, keep, box)
