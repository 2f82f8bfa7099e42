"""The cells: sorted ranges split where their keys part, then boxes and moments bottom-up.

Cell 0 is every particle. A cell of more than ``leaf_size`` particles is split at the
highest level where its first and last keys differ (in a sorted range, every key between
shares the bits above): its children are the runs of equal digits at that level, found by
one scan. Levels where all its particles fall in one child are skipped, so no cell has a
single child and a cell's size is that of its particles, not of a fixed grid (a compressed
octree: Bern, Eppstein & Teng 1999). Cells are numbered breadth first (a cell's children are
consecutive and numbered after it), so one pass from the last cell to the first computes every
cell after its children: leaves from their particles, the others from their children
(``multipoles``). The leaves are then listed in key order, the order the walk takes them.
"""
from ..cache import jit

from . import morton, multipoles


@jit(error_model="numpy", inline="always")
def highest_bit(x):
    """The index of the highest set bit of x > 0."""
    top = 0
    if x >> 32:
        x >>= 32
        top += 32
    if x >> 16:
        x >>= 16
        top += 16
    if x >> 8:
        x >>= 8
        top += 8
    if x >> 4:
        x >>= 4
        top += 4
    if x >> 2:
        x >>= 2
        top += 2
    if x >> 1:
        top += 1
    return top


@jit(error_model="numpy", inline="always")
def gather(pos, part, slots, s, e):
    """Sorted particles [s, e): coordinates from ``pos``, and beta and alpha from their
    by-slot rows 5 and 6, into rows 0 to 4 (z = 0 in 2-D)."""
    dim = pos.shape[0]
    for k in range(s, e):
        i = slots[k]
        part[0, k] = pos[0, i]
        part[1, k] = pos[1, i]
        part[2, k] = pos[2, i] if dim == 3 else 0.0
        part[3, k] = part[5, i]
        part[4, k] = part[6, i]


@jit(error_model="numpy", inline="always")
def rekey(pos, part, keys, slots, keys_tmp, slots_tmp, counts, s, e, dim):
    """Particles [s, e) that share one key but not one position (a cluster far from an
    escaper: 2^21 key cells an axis cannot tell its bodies apart) get keys in their own
    bounding cube, sorted by them; False if they really coincide."""
    if not morton.range_keys(part[0], part[1], part[2], s, e, dim, keys):
        return False
    morton.sort(keys[s:e], slots[s:e], keys_tmp[s:e], slots_tmp[s:e], e - s, dim, counts)
    gather(pos, part, slots, s, e)
    return True


@jit(error_model="numpy", inline="always")
def split(keys, slots, keys_tmp, slots_tmp, counts, pos, part, m, dim, leaf_size, start, count,
          child, children, capacity):
    """Number the cells of the m sorted particles breadth first; returns the cell count, or
    -1 if more than ``capacity`` cells are needed (the caller then takes larger leaves).

    Cell c holds sorted particles [start[c], start[c] + count[c]); its children are
    [child[c], child[c] + children[c]) (none for a leaf). A cell of more than ``leaf_size``
    particles with one key is keyed again in its own cube (``rekey``), so that only particles
    at one point share a leaf of any size."""
    mask = (1 << dim) - 1
    start[0] = 0
    count[0] = m
    cells = 1
    c = 0
    while c < cells:
        s = start[c]
        e = s + count[c]
        child[c] = cells
        children[c] = 0
        if e - s > leaf_size and keys[s] == keys[e - 1]:
            if not rekey(pos, part, keys, slots, keys_tmp, slots_tmp, counts, s, e, dim):
                c += 1
                continue
        if e - s > leaf_size:
            shift = (highest_bit(keys[s] ^ keys[e - 1]) // dim) * dim
            k = s
            while k < e:
                digit = (keys[k] >> shift) & mask
                j = k + 1
                while j < e and ((keys[j] >> shift) & mask) == digit:
                    j += 1
                if cells == capacity:
                    return -1
                start[cells] = k
                count[cells] = j - k
                cells += 1
                k = j
            children[c] = cells - child[c]
        c += 1
    return cells


@jit(error_model="numpy", inline="always")
def list_groups(count, child, children, group_size, groups, stack):
    """The groups in key order (depth first, children in order): the largest cells of at most
    ``group_size`` particles, and leaves of more (coincident particles). How many."""
    found = 0
    stack[0] = 0
    top = 1
    while top > 0:
        top -= 1
        c = stack[top]
        if children[c] == 0 or count[c] <= group_size:
            groups[found] = c
            found += 1
            continue
        # pushed last child first, so that the first child comes off the stack first
        for k in range(child[c] + children[c] - 1, child[c] - 1, -1):
            stack[top] = k
            top += 1
    return found


@jit(error_model="numpy", inline="always")
def moments(px, py, pz, beta, start, count, child, children, cells, ncell):
    """Every cell's box, centre, size, radius and moments, children before parents."""
    for c in range(ncell - 1, -1, -1):
        if children[c] == 0:
            s = start[c]
            e = s + count[c]
            multipoles.leaf_box(px, py, pz, s, e, cells, c)
            multipoles.leaf_moments(px, py, pz, beta, s, e, cells, c)
        else:
            multipoles.parent_moments(cells, c, child[c], children[c])
