"""The walk: for each group of neighbours, the lists of what acts on them, then their sums.

The groups are the largest cells of at most ``field.GROUP_SIZE`` particles. For a group's
particles together (Barnes 1990, J. Comput. Phys. 87, 161: one walk per group of neighbours
rather than per particle), a cell is taken by its multipoles when

    size < theta * d   and   d > radius

with d the distance from the group's bounding box to the cell's centre, ``size`` the cell's
largest side and ``radius`` the largest distance of its particles from its centre
(``multipoles``; the second condition keeps every target outside the sphere where the
expansion converges, whatever theta). Since d is measured from the group's
nearest point, no particle of the group gets a coarser answer than the criterion would give it
alone. A cell so taken that holds at most ``small`` particles goes on the particle list
instead (as cheap, and exact); so do the leaves that are not taken, while other cells are
opened. theta = 0 takes no cell: every pair is summed directly, as the direct sum does.

A cell well separated from the whole group (its radius plus the group's below ``LOCAL_SHARE *
theta`` times the distance between their centres, and more than 4 ``small`` particle pairs
between them: fewer are summed pair by pair, as cheap and exact) goes on a third list, whose
cells are summed once into a local expansion about the group's centre (field, gradient and
second derivatives: the cell-to-group step, M2L, of a fast multipole method, Greengard &
Rokhlin 1987, J. Comput. Phys. 73, 325, to total order 2 in the cell's radius and the target's
offset), evaluated once at each target (L2P): a cell costs one M2L for the group instead of one
multipole sum per target (``local``). Its error is of the same (third) order as the
multipoles' own. ``fmm`` takes the same steps for the cells above the groups, and at the
groups takes what is left as ``walk_group`` does.

The lists are summed for each target in loops without branches (``sum_particles``,
``sum_cells``, ``cells_to_local``) that the compiler vectorises; a list that fills is summed and emptied, so the
lists are fixed scratch (``layout``) whatever the scene. A group's own particles are summed
with the pair of a particle with itself dropped by a select, as the direct sum leaves it out;
any other coincident pair without softening still gives NaN, as in the direct sum, and the
step fails.
"""
import math

from numba import prange

from ..cache import jit

from . import layout, local, multipoles as mp

#: a far cell whose radius plus the group's is below LOCAL_SHARE * theta times the distance
#: between their centres acts through one local expansion about the group's centre (its field,
#: gradient and second derivatives: Greengard & Rokhlin 1987's M2L, to total order 2) summed
#: once for the group, instead of its multipoles at every target; nearer far cells keep the
#: per-target sum, whose error is smaller at the same distance
LOCAL_SHARE = 0.75

#: the vectorising flags of ``engine.forces.pairwise`` (never 'nnan'/'ninf': NaN must survive)
SIMD_MATH = local.SIMD_MATH


@jit(fastmath=SIMD_MATH, error_model="numpy")
def sum_particles(px, py, pz, s, e, lx, ly, lz, lb, count, eps2, ax, ay, az, phi, potential):
    """Targets [s, e) += the field (and, if ``potential``, the potential) of the listed
    particles."""
    for i in range(s, e):
        xi = px[i]
        yi = py[i]
        zi = pz[i]
        sx = 0.0
        sy = 0.0
        sz = 0.0
        if potential:
            sp = 0.0
            for j in range(count):
                dx = lx[j] - xi
                dy = ly[j] - yi
                dz = lz[j] - zi
                inv = 1.0 / math.sqrt(dx * dx + dy * dy + dz * dz + eps2)
                bj = lb[j] * inv
                sp += bj
                bj *= inv * inv
                sx += bj * dx
                sy += bj * dy
                sz += bj * dz
            phi[i] += sp
        else:
            for j in range(count):
                dx = lx[j] - xi
                dy = ly[j] - yi
                dz = lz[j] - zi
                r2 = dx * dx + dy * dy + dz * dz + eps2
                bj = lb[j] / (r2 * math.sqrt(r2))
                sx += bj * dx
                sy += bj * dy
                sz += bj * dz
        ax[i] += sx
        ay[i] += sy
        az[i] += sz


@jit(fastmath=SIMD_MATH, error_model="numpy")
def sum_cells(px, py, pz, s, e, lc, count, eps2, ax, ay, az, phi, potential):
    """Targets [s, e) += the field (and potential) of the listed cells' expansions."""
    for i in range(s, e):
        xi = px[i]
        yi = py[i]
        zi = pz[i]
        sx = 0.0
        sy = 0.0
        sz = 0.0
        sp = 0.0
        for j in range(count):
            fx, fy, fz, psi = mp.field_at(
                lc[mp.CX, j] - xi, lc[mp.CY, j] - yi, lc[mp.CZ, j] - zi, eps2, lc[mp.M, j],
                lc[mp.DX, j], lc[mp.DY, j], lc[mp.DZ, j], lc[mp.QXX, j], lc[mp.QYY, j],
                lc[mp.QZZ, j], lc[mp.QXY, j], lc[mp.QXZ, j], lc[mp.QYZ, j])
            sx += fx
            sy += fy
            sz += fz
            sp += psi
        ax[i] += sx
        ay[i] += sy
        az[i] += sz
        if potential:
            phi[i] += sp


@jit(fastmath=SIMD_MATH, error_model="numpy")
def sum_own_group(px, py, pz, beta, s, e, eps2, ax, ay, az, phi, potential):
    """Targets [s, e) += the field of the other sources of their own group: the pair of a
    particle with itself, and pairs with particles that are not sources (which the direct sum
    skips), dropped by a select, which keeps the loop vectorised."""
    for i in range(s, e):
        xi = px[i]
        yi = py[i]
        zi = pz[i]
        sx = 0.0
        sy = 0.0
        sz = 0.0
        sp = 0.0
        for j in range(s, e):
            dx = px[j] - xi
            dy = py[j] - yi
            dz = pz[j] - zi
            inv = 1.0 / math.sqrt(dx * dx + dy * dy + dz * dz + eps2)
            bp = beta[j] * inv
            bj = bp * inv * inv
            # selected after the products: with eps = 0 a particle's pair with itself has
            # inv = inf, and 0 * inf would be NaN
            skip = j == i or beta[j] == 0.0
            bp = 0.0 if skip else bp
            bj = 0.0 if skip else bj
            sp += bp
            sx += bj * dx
            sy += bj * dy
            sz += bj * dz
        ax[i] += sx
        ay[i] += sy
        az[i] += sz
        if potential:
            phi[i] += sp


@jit(error_model="numpy", inline="always")
def copy_cell(cells, c, lc, k, order):
    """Put cell c's centre and moments (those of ``order`` and below) on list entry k."""
    for row in range(mp.MOMENTS):
        lc[row, k] = cells[row, c]
    if order < 1:
        lc[mp.DX, k] = 0.0
        lc[mp.DY, k] = 0.0
        lc[mp.DZ, k] = 0.0
    if order < 2:
        for row in range(mp.QXX, mp.MOMENTS):
            lc[row, k] = 0.0


@jit(error_model="numpy", inline="always")
def gap(lo, hi, c):
    """The distance along one axis from the interval [lo, hi] to the point c."""
    if c < lo:
        return lo - c
    if c > hi:
        return c - hi
    return 0.0


@jit(error_model="numpy", inline="always")
def walk_group(group, px, py, pz, beta, ax, ay, az, phi, cells, start, count, child, children,
               lx, ly, lz, lb, lc, ll, loc, stack, theta2, eps2, order, potential, small):
    """Everything the particles of ``group`` feel, into ax, ay, az (and phi)."""
    s = start[group]
    e = s + count[group]
    gcount = count[group]
    for i in range(s, e):
        ax[i] = 0.0
        ay[i] = 0.0
        az[i] = 0.0
        if potential:
            phi[i] = 0.0
    for k in range(loc.shape[0]):
        loc[k] = 0.0
    zx = cells[mp.CX, group]
    zy = cells[mp.CY, group]
    zz = cells[mp.CZ, group]
    reach = cells[mp.RADIUS, group]
    local2 = theta2 * LOCAL_SHARE * LOCAL_SHARE
    nlocal = 0
    glx = cells[mp.LOX, group]
    gly = cells[mp.LOY, group]
    glz = cells[mp.LOZ, group]
    ghx = cells[mp.HIX, group]
    ghy = cells[mp.HIY, group]
    ghz = cells[mp.HIZ, group]
    plist = lx.shape[0]
    clist = lc.shape[1]
    npart = 0
    ncell = 0
    stack[0] = 0
    top = 1
    while top > 0:
        top -= 1
        c = stack[top]
        if c == group:
            sum_own_group(px, py, pz, beta, s, e, eps2, ax, ay, az, phi, potential)
            continue
        if cells[mp.ABSW, c] == 0.0:
            continue
        dx = gap(glx, ghx, cells[mp.CX, c])
        dy = gap(gly, ghy, cells[mp.CY, c])
        dz = gap(glz, ghz, cells[mp.CZ, c])
        d2 = dx * dx + dy * dy + dz * dz
        size = cells[mp.SIZE, c]
        radius = cells[mp.RADIUS, c]
        far = size * size < theta2 * d2 and d2 > radius * radius
        rx = cells[mp.CX, c] - zx
        ry = cells[mp.CY, c] - zy
        rz = cells[mp.CZ, c] - zz
        spread = radius + reach
        if count[c] * gcount > 4 * small and spread * spread < local2 * (rx * rx + ry * ry
                                                                          + rz * rz):
            if nlocal == clist:
                local.flush(ll, nlocal, zx, zy, zz, eps2, loc, potential)
                nlocal = 0
            copy_cell(cells, c, ll, nlocal, order)
            nlocal += 1
        elif far and count[c] > small:
            if ncell == clist:
                sum_cells(px, py, pz, s, e, lc, ncell, eps2, ax, ay, az, phi, potential)
                ncell = 0
            copy_cell(cells, c, lc, ncell, order)
            ncell += 1
        elif far or children[c] == 0:
            for k in range(start[c], start[c] + count[c]):
                if beta[k] == 0.0:
                    continue
                if npart == plist:
                    sum_particles(px, py, pz, s, e, lx, ly, lz, lb, npart, eps2, ax, ay, az,
                                  phi, potential)
                    npart = 0
                lx[npart] = px[k]
                ly[npart] = py[k]
                lz[npart] = pz[k]
                lb[npart] = beta[k]
                npart += 1
        else:
            for k in range(child[c], child[c] + children[c]):
                stack[top] = k
                top += 1
    if npart:
        sum_particles(px, py, pz, s, e, lx, ly, lz, lb, npart, eps2, ax, ay, az, phi,
                      potential)
    if ncell:
        sum_cells(px, py, pz, s, e, lc, ncell, eps2, ax, ay, az, phi, potential)
    if nlocal:
        local.flush(ll, nlocal, zx, zy, zz, eps2, loc, potential)
        local.local_to_targets(px, py, pz, s, e, zx, zy, zz, loc, ax, ay, az, phi, potential)




@jit(error_model="numpy")
def walk_lane(lane, lanes, floats, ints, n, ngroups, theta2, eps2, order, potential, small):
    """The walks of groups lane, lane + lanes, lane + 2 lanes, ... with lane's own lists."""
    part = layout.particle_blocks(floats, n)
    cells = layout.cell_table(floats, n)
    start, count, child, children, groups = layout.cell_links(ints, n)
    lx, ly, lz, lb, lc, ll, loc = layout.lane_lists(floats, n, lane)
    stack = layout.lane_stack(ints, n, lane)
    for g in range(lane, ngroups, lanes):
        walk_group(groups[g], part[0], part[1], part[2], part[3], part[5], part[6], part[7],
                   part[8], cells, start, count, child, children, lx, ly, lz, lb, lc, ll, loc,
                   stack, theta2, eps2, order, potential, small)


#: one signature for both walks (see ``engine.forces.pairwise``: a parallel function is
#: compiled once, for one signature, so that every cached caller links the same kernel)
SIGNATURE = ("void(float64[::1], int64[::1], int64, int64, float64, float64, int64, boolean, "
             "int64, int64)")


@jit(signature=SIGNATURE, parallel=True, error_model="numpy")
def walk(floats, ints, n, ngroups, theta2, eps2, order, potential, small, lanes):
    """Walk for every group, the groups dealt round-robin to ``lanes`` lanes (the workspace's
    lists: one a thread), since neighbours in key order cost about the same. Each group's
    result depends on nothing else: the same bits at any thread count."""
    for lane in prange(lanes):
        walk_lane(lane, lanes, floats, ints, n, ngroups, theta2, eps2, order, potential,
                  small)


@jit(signature=SIGNATURE, error_model="numpy")
def walk_serial(floats, ints, n, ngroups, theta2, eps2, order, potential, small, lanes):
    """``walk`` on the calling thread (few particles, or a caller that fills the cores)."""
    walk_lane(0, 1, floats, ints, n, ngroups, theta2, eps2, order, potential, small)
