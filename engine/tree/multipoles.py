"""Cartesian multipoles about a cell's centre, to quadrupole order, with Plummer softening.

A cell of sources with weights beta_j at c + s_j has

    M = sum_j beta_j,   D_a = sum_j beta_j s_ja,   Q_ab = sum_j beta_j s_ja s_jb

(Greengard 1988, The Rapid Evaluation of Potential Fields in Particle Systems; Salmon &
Warren 1994, J. Comput. Phys. 111, 136), about the centre c of the weights' absolute values,
sum_j |beta_j| p_j / sum_j |beta_j| (the centre of the bounding box if they are all 0). For
gravity that is the centre of mass, where the dipole vanishes and the expansion is good to
the third order in the cell's radius (about the bounding box's centre the dipole takes a
place, and on the development machine's 10^6-body Plummer sphere the median force error
at theta = 0.65 was twice as large, its 99th percentile 8 times); charges of both signs have
no centre of charge (their total may be 0), and keep their dipole about c. A cell's
``radius`` is the largest distance of a particle from c: exact for a leaf, for a parent the
smaller of its children's bound, max_k(|c_k - c| + radius_k), and the farthest corner of its
bounding box.

Its field at a target x, with d = c - x and r^2 = |d|^2 + eps^2 (the softened kernel
expanded in s to second order; every derivative taken of (|d|^2 + eps^2)^(-1/2)):

    sum_j beta_j (d + s_j) / |d + s_j|_eps^3
        ~ d (M / r^3 - 3 (D.d) / r^5 + 15/2 (d.Q.d) / r^7 - 3/2 tr(Q) / r^5)
          + D / r^3 - 3 (Q d) / r^5

    sum_j beta_j / |d + s_j|_eps ~ M / r - (D.d) / r^3 + 3/2 (d.Q.d) / r^5 - 1/2 tr(Q) / r^3

A child's moments move to its parent's centre with t = c_child - c_parent (s = s' + t):
M += M', D += D' + M' t, Q += Q' + D' t^T + t D'^T + M' t t^T (exact: no truncation).

Without softening the error of the p-th order expansion of a cell of radius b at distance
r > b is at most sum_j |beta_j| ((p + 2)(b/r)^(p+1) - (p + 1)(b/r)^(p+2)) / (r - b)^2 for
the field (Salmon & Warren 1994, eq. 19): it falls as (b/r)^(p+1).
"""
import math

from ..cache import jit

from . import morton

# rows of the cell table (``layout.CELL_FLOATS`` of them)
CX, CY, CZ = 0, 1, 2
M, DX, DY, DZ = 3, 4, 5, 6
QXX, QYY, QZZ, QXY, QXZ, QYZ = 7, 8, 9, 10, 11, 12
#: the rows a cell's interaction needs (centre and moments), copied into the lists
MOMENTS = 13
SIZE, RADIUS, ABSW = 13, 14, 15
LOX, LOY, LOZ, HIX, HIY, HIZ = 16, 17, 18, 19, 20, 21

#: the expansion orders offered: 0 monopole, 1 dipole, 2 quadrupole
ORDERS = (0, 1, 2)


@jit(error_model="numpy", inline="always")
def leaf_box(px, py, pz, s, e, cells, c):
    """The bounding box of particles [s, e), its centre, largest side and half diagonal (the
    cell's centre and radius until ``leaf_moments`` sets them)."""
    lx, ly, lz, hx, hy, hz = morton.range_box(px, py, pz, s, e)
    set_box(cells, c, lx, ly, lz, hx, hy, hz)


@jit(error_model="numpy", inline="always")
def set_box(cells, c, lx, ly, lz, hx, hy, hz):
    cells[LOX, c] = lx
    cells[LOY, c] = ly
    cells[LOZ, c] = lz
    cells[HIX, c] = hx
    cells[HIY, c] = hy
    cells[HIZ, c] = hz
    cells[CX, c] = 0.5 * (lx + hx)
    cells[CY, c] = 0.5 * (ly + hy)
    cells[CZ, c] = 0.5 * (lz + hz)
    sx = hx - lx
    sy = hy - ly
    sz = hz - lz
    cells[SIZE, c] = max(sx, sy, sz)
    cells[RADIUS, c] = 0.5 * math.sqrt(sx * sx + sy * sy + sz * sz)


@jit(error_model="numpy", inline="always")
def clear_moments(cells, c):
    for row in range(M, MOMENTS):
        cells[row, c] = 0.0
    cells[ABSW, c] = 0.0


@jit(error_model="numpy", inline="always")
def leaf_moments(px, py, pz, beta, s, e, cells, c):
    """P2M: the centre (``weighted_centre`` of the particles [s, e)), their moments about it
    and the radius: the largest distance of a particle from it."""
    clear_moments(cells, c)
    a = 0.0
    wx = wy = wz = 0.0
    for k in range(s, e):
        b = abs(beta[k])
        a += b
        wx += b * px[k]
        wy += b * py[k]
        wz += b * pz[k]
    if a > 0.0:
        cells[CX, c] = wx / a
        cells[CY, c] = wy / a
        cells[CZ, c] = wz / a
    cx = cells[CX, c]
    cy = cells[CY, c]
    cz = cells[CZ, c]
    m = 0.0
    dx = dy = dz = 0.0
    qxx = qyy = qzz = qxy = qxz = qyz = 0.0
    r2 = 0.0
    for k in range(s, e):
        b = beta[k]
        x = px[k] - cx
        y = py[k] - cy
        z = pz[k] - cz
        r2 = max(r2, x * x + y * y + z * z)
        m += b
        dx += b * x
        dy += b * y
        dz += b * z
        qxx += b * x * x
        qyy += b * y * y
        qzz += b * z * z
        qxy += b * x * y
        qxz += b * x * z
        qyz += b * y * z
    store(cells, c, m, dx, dy, dz, qxx, qyy, qzz, qxy, qxz, qyz, a)
    cells[RADIUS, c] = math.sqrt(r2)


@jit(error_model="numpy", inline="always")
def store(cells, c, m, dx, dy, dz, qxx, qyy, qzz, qxy, qxz, qyz, a):
    cells[M, c] = m
    cells[DX, c] = dx
    cells[DY, c] = dy
    cells[DZ, c] = dz
    cells[QXX, c] = qxx
    cells[QYY, c] = qyy
    cells[QZZ, c] = qzz
    cells[QXY, c] = qxy
    cells[QXZ, c] = qxz
    cells[QYZ, c] = qyz
    cells[ABSW, c] = a


@jit(error_model="numpy", inline="always")
def parent_moments(cells, c, first, count):
    """M2M: cell c's box, centre, moments and radius from those of its children [first,
    first + count)."""
    lx = cells[LOX, first]
    ly = cells[LOY, first]
    lz = cells[LOZ, first]
    hx = cells[HIX, first]
    hy = cells[HIY, first]
    hz = cells[HIZ, first]
    for k in range(first + 1, first + count):
        lx = min(lx, cells[LOX, k])
        ly = min(ly, cells[LOY, k])
        lz = min(lz, cells[LOZ, k])
        hx = max(hx, cells[HIX, k])
        hy = max(hy, cells[HIY, k])
        hz = max(hz, cells[HIZ, k])
    set_box(cells, c, lx, ly, lz, hx, hy, hz)
    a = 0.0
    wx = wy = wz = 0.0
    for k in range(first, first + count):
        b = cells[ABSW, k]
        a += b
        wx += b * cells[CX, k]
        wy += b * cells[CY, k]
        wz += b * cells[CZ, k]
    if a > 0.0:
        cells[CX, c] = wx / a
        cells[CY, c] = wy / a
        cells[CZ, c] = wz / a
    cx = cells[CX, c]
    cy = cells[CY, c]
    cz = cells[CZ, c]
    m = 0.0
    dx = dy = dz = 0.0
    qxx = qyy = qzz = qxy = qxz = qyz = 0.0
    reach = 0.0
    for k in range(first, first + count):
        mk = cells[M, k]
        tx = cells[CX, k] - cx
        ty = cells[CY, k] - cy
        tz = cells[CZ, k] - cz
        reach = max(reach, math.sqrt(tx * tx + ty * ty + tz * tz) + cells[RADIUS, k])
        ex = cells[DX, k]
        ey = cells[DY, k]
        ez = cells[DZ, k]
        m += mk
        dx += ex + mk * tx
        dy += ey + mk * ty
        dz += ez + mk * tz
        qxx += cells[QXX, k] + 2.0 * ex * tx + mk * tx * tx
        qyy += cells[QYY, k] + 2.0 * ey * ty + mk * ty * ty
        qzz += cells[QZZ, k] + 2.0 * ez * tz + mk * tz * tz
        qxy += cells[QXY, k] + ex * ty + tx * ey + mk * tx * ty
        qxz += cells[QXZ, k] + ex * tz + tx * ez + mk * tx * tz
        qyz += cells[QYZ, k] + ey * tz + ty * ez + mk * ty * tz
    store(cells, c, m, dx, dy, dz, qxx, qyy, qzz, qxy, qxz, qyz, a)
    # the farthest particle is within a child's radius of its centre, and inside the box
    corner = math.sqrt(max(cx - lx, hx - cx) ** 2 + max(cy - ly, hy - cy) ** 2
                       + max(cz - lz, hz - cz) ** 2)
    cells[RADIUS, c] = min(corner, reach)


@jit(error_model="numpy", inline="always")
def field_at(dx, dy, dz, eps2, m, ex, ey, ez, qxx, qyy, qzz, qxy, qxz, qyz):
    """(f_x, f_y, f_z, psi): the expansion's field sum beta (d + s)/|d + s|^3 and potential
    sum beta / |d + s| at a target, d = centre - target (module doc)."""
    r2 = dx * dx + dy * dy + dz * dz + eps2
    inv = 1.0 / math.sqrt(r2)
    inv2 = inv * inv
    inv3 = inv * inv2
    inv5 = inv3 * inv2
    inv7 = inv5 * inv2
    dd = ex * dx + ey * dy + ez * dz
    qx = qxx * dx + qxy * dy + qxz * dz
    qy = qxy * dx + qyy * dy + qyz * dz
    qz = qxz * dx + qyz * dy + qzz * dz
    dqd = qx * dx + qy * dy + qz * dz
    trace = qxx + qyy + qzz
    common = m * inv3 - 3.0 * dd * inv5 + 7.5 * dqd * inv7 - 1.5 * trace * inv5
    fx = common * dx + inv3 * ex - 3.0 * inv5 * qx
    fy = common * dy + inv3 * ey - 3.0 * inv5 * qy
    fz = common * dz + inv3 * ez - 3.0 * inv5 * qz
    psi = m * inv - dd * inv3 + 1.5 * dqd * inv5 - 0.5 * trace * inv3
    return fx, fy, fz, psi
