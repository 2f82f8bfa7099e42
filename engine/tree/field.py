"""One tree evaluation: sort, build, walk. What a tree force term calls every evaluation.

The walk is the fast multipole walk (``fmm``: ``method="fmm"`` and ``"auto"``) or the
Barnes-Hut walk (``walk``: ``method="tree"``, and the fast multipole walk's stand-in below
``FMM_THETA_MIN`` or when its scratch runs out); both share the build and the groups' sums.

The caller (``engine.forces.gravity_tree``, ``coulomb_tree``) lists the m particles that take
part in ``slots`` (the workspace's ints block 1) and writes, by slot, each one's source weight
beta into float block 5 and its target factor alpha into block 6; ``solve`` leaves, in key
order, the slots (ints block 1), alpha (float block 4) and the field sum_j beta_j d / r^3 of
every particle (float blocks 5 to 7; 8: the potential sum_j beta_j / r, when asked for).
"""
from ..cache import jit

from . import build, fmm, layout, morton, walk

#: most particles in a leaf (except particles at one point: ``build.split``); 8 to 64 cost
#: the same to 10% on the bench's Plummer sphere at N = 10^5, with groups of 16 to 128
LEAF_SIZE = 16
#: most particles in a group, the targets that share one walk and its lists
GROUP_SIZE = 64
#: the same for the fast multipole walk, whose groups inherit their far field: at equal
#: median error (1e-3) 96 was 10% faster than 64 at 10^5 bodies and at 10^6 (80 to 128 within
#: 5% of it), on the development machine
FMM_GROUP_SIZE = 96
#: a cell taken whole of at most this many particles is summed particle by particle: as
#: cheap as its expansion (a cell's interaction costs about 3.3 particles' on the development
#: machine), and exact
SMALL_CELL = 4
#: from this many particles on the walk uses every core (below, starting the threads costs
#: more than it saves)
THREADS_MIN = 2048
#: the fast multipole walk's cells act on a target cell through its local expansion when
#: their radii sum to less than theta times their distance (``fmm.resolve``); below this
#: theta it would hand down lists of nearly every cell, and ``walk`` is used instead
FMM_THETA_MIN = 0.2


@jit(error_model="numpy", inline="always")
def blocks(floats, n):
    """The particle blocks: (PARTICLE_FLOATS, n) over the workspace's floats."""
    return layout.particle_blocks(floats, n)


@jit(error_model="numpy", inline="always")
def slots_of(ints, n):
    return ints[n:2 * n]


@jit(error_model="numpy")
def solve(pos, n, m, floats, ints, theta, eps2, order, potential, threads, multipole,
          leaf_size=LEAF_SIZE, group_size=GROUP_SIZE, small=SMALL_CELL,
          fmm_group_size=FMM_GROUP_SIZE):
    """The field (and potential) of the m listed particles on each other (module doc), by
    the fast multipole walk (``fmm``) if ``multipole``, else by the Barnes-Hut walk."""
    dim = pos.shape[0]
    keys, slots, keys_tmp, slots_tmp, counts = layout.sort_blocks(ints, n)
    part = layout.particle_blocks(floats, n)
    cells = layout.cell_table(floats, n)
    start, count, child, children, groups = layout.cell_links(ints, n)
    stack = layout.lane_stack(ints, n, 0)
    capacity = layout.cell_capacity(n)
    ncell = -1
    while ncell < 0:
        # from the top each time: a failed split may have keyed some ranges again
        morton.keys(pos, slots, m, keys)
        morton.sort(keys, slots, keys_tmp, slots_tmp, m, dim, counts)
        build.gather(pos, part, slots, 0, m)
        ncell = build.split(keys, slots, keys_tmp, slots_tmp, counts, pos, part, m, dim,
                            leaf_size, start, count, child, children, capacity)
        # a scene that needs more cells than the workspace has: larger leaves
        leaf_size *= 2
    build.moments(part[0], part[1], part[2], part[3], start, count, child, children, cells,
                  ncell)
    parallel = threads and m >= THREADS_MIN
    if multipole and theta >= FMM_THETA_MIN:
        lanes = layout.lanes(floats, ints, n) if parallel else 1
        if parallel:
            fmm.descend(floats, ints, n, m, theta * theta, eps2, order, potential,
                        small, fmm_group_size, lanes)
        else:
            fmm.descend_serial(floats, ints, n, m, theta * theta, eps2, order,
                               potential, small, fmm_group_size, 1)
        if fmm.succeeded(ints, n, lanes):
            return ncell
    ngroups = build.list_groups(count, child, children, group_size, groups, stack)
    if parallel:
        walk.walk(floats, ints, n, ngroups, theta * theta, eps2, order, potential, small,
                  layout.lanes(floats, ints, n))
    else:
        walk.walk_serial(floats, ints, n, ngroups, theta * theta, eps2, order,
                         potential, small, 1)
    return ncell


@jit(error_model="numpy", inline="always")
def scatter(acc, n, m, floats, ints):
    """acc[:, slot] += alpha * field, for the m sorted particles ``solve`` left."""
    part = layout.particle_blocks(floats, n)
    slots = slots_of(ints, n)
    dim = acc.shape[0]
    for k in range(m):
        i = slots[k]
        a = part[4, k]
        if part[5, k] == 0.0 and part[6, k] == 0.0 and part[7, k] == 0.0:
            continue  # as the direct sum skips a zero force: a massless particle stays finite
        acc[0, i] += a * part[5, k]
        acc[1, i] += a * part[6, k]
        if dim == 3:
            acc[2, i] += a * part[7, k]


@jit(error_model="numpy", inline="always")
def add_field(pos, n, m, floats, ints, theta, eps2, order, threads, multipole, acc):
    """acc += alpha * the tree's field of the m listed particles, and True; False (acc
    untouched) when there are none."""
    if m == 0:
        return False
    solve(pos, n, m, floats, ints, theta, eps2, order, False, threads, multipole)
    scatter(acc, n, m, floats, ints)
    return True
