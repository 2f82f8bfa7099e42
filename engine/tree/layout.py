"""Where the tree keeps its scratch: blocks of one ``Workspace``'s float and int arrays.

For n particle slots and C = ``cell_capacity(n)`` cells, the floats hold, in order:

- ``PARTICLE_FLOATS`` blocks of n: the sorted particles' x, y, z, source weight beta, target
  factor alpha, results ax, ay, az and the potential (summed only when asked for);
- ``CELL_FLOATS`` blocks of C: each cell's centre (3), multipoles (13: weight, dipole,
  quadrupole), size, radius, absolute weight and bounding box (6);
- per thread, its interaction lists: ``LIST_PARTICLES`` particles (x, y, z, beta), twice
  ``LIST_CELLS`` cells (centre and multipoles: summed at each target, or into the group's
  local expansion) and the local expansion (``LOCAL``);

and the ints: the sort's keys and slots and their copies (4 blocks of n), the radix sort's
counts, ``CELL_INTS`` blocks of C (first particle, count, first child, children, and the list
of leaves) and each thread's stack.

At 8 bytes a number that is 20 n floats and 6.5 n ints (C = n / 2): 212 bytes a particle,
plus 279 KB per thread for its lists.
"""
import numpy as np
from numba import config

from ..cache import jit
from ..state import Workspace

#: per particle slot: x, y, z, beta, alpha, ax, ay, az, potential
PARTICLE_FLOATS = 9
#: per cell: centre 3, weight 1, dipole 3, quadrupole 6, size, radius, |weight|, box 6
CELL_FLOATS = 22
#: per cell: first sorted particle, particle count, first child, number of children; leaves
CELL_INTS = 5
#: the interaction lists of one thread: particles (x, y, z, beta each) and cells (13 each)
LIST_PARTICLES = 2048
LIST_CELLS = 1024
#: a group's local expansion: field (3), gradient (6), second derivatives (10), potential (10)
LOCAL = 32
LIST_FLOATS = 4 * LIST_PARTICLES + 2 * 13 * LIST_CELLS + LOCAL
#: one thread's walk stack (a compressed tree of 64-bit keys is at most 31 levels deep, and
#: a level pushes at most 8 cells)
STACK = 512
#: the radix sort's digit: 11 bits, so 63-bit keys sort in 6 passes
RADIX_BITS = 11
RADIX = 1 << RADIX_BITS
#: threads a workspace made here has lists for (numba's largest thread count in this
#: process); compiled code reads the count from the workspace itself (``lanes``), never from
#: this value, which a cached function would keep from the process that compiled it
THREADS = int(config.NUMBA_NUM_THREADS)


@jit(error_model="numpy", inline="always")
def cell_capacity(n):
    """Cells a workspace for n particles holds: n / 2 + 64 (a leaf holds at least one
    particle and, in a compressed tree, every other cell at least two children: at most 2n - 1
    cells; the leaves hold many more than two particles in any scene of interest, and if a
    scene needs more cells the build doubles the leaf size instead)."""
    return n // 2 + 64


@jit(error_model="numpy", inline="always")
def float_count(n, threads):
    return PARTICLE_FLOATS * n + CELL_FLOATS * cell_capacity(n) + threads * LIST_FLOATS


@jit(error_model="numpy", inline="always")
def int_count(n, threads):
    return 4 * n + RADIX + 1 + CELL_INTS * cell_capacity(n) + threads * STACK


@jit(error_model="numpy", inline="always")
def particle_blocks(floats, n):
    """The particle blocks, (PARTICLE_FLOATS, n), at the start of the floats."""
    return floats[:PARTICLE_FLOATS * n].reshape((PARTICLE_FLOATS, n))


@jit(error_model="numpy", inline="always")
def cell_table(floats, n):
    """The cells' floats, (CELL_FLOATS, C): rows as ``multipoles`` names them."""
    capacity = cell_capacity(n)
    base = PARTICLE_FLOATS * n
    return floats[base:base + CELL_FLOATS * capacity].reshape((CELL_FLOATS, capacity))


@jit(error_model="numpy", inline="always")
def sort_blocks(ints, n):
    """The sort's keys, slots, their copies and the radix counts."""
    return (ints[0:n], ints[n:2 * n], ints[2 * n:3 * n], ints[3 * n:4 * n],
            ints[4 * n:4 * n + RADIX + 1])


@jit(error_model="numpy", inline="always")
def cell_links(ints, n):
    """Each cell's first particle, count, first child and children, and the group list."""
    capacity = cell_capacity(n)
    base = 4 * n + RADIX + 1
    return (ints[base:base + capacity], ints[base + capacity:base + 2 * capacity],
            ints[base + 2 * capacity:base + 3 * capacity],
            ints[base + 3 * capacity:base + 4 * capacity],
            ints[base + 4 * capacity:base + 5 * capacity])


@jit(error_model="numpy", inline="always")
def lane_lists(floats, n, lane):
    """Lane ``lane``'s particle list (x, y, z, beta), its two cell lists ((13, LIST_CELLS):
    cells summed at each target, cells summed into the local expansion) and the expansion."""
    own = PARTICLE_FLOATS * n + CELL_FLOATS * cell_capacity(n) + lane * LIST_FLOATS
    p = LIST_PARTICLES
    cells = own + 4 * p
    far = cells + 13 * LIST_CELLS
    local = far + 13 * LIST_CELLS
    return (floats[own:own + p], floats[own + p:own + 2 * p], floats[own + 2 * p:own + 3 * p],
            floats[own + 3 * p:own + 4 * p],
            floats[cells:cells + 13 * LIST_CELLS].reshape((13, LIST_CELLS)),
            floats[far:far + 13 * LIST_CELLS].reshape((13, LIST_CELLS)),
            floats[local:local + LOCAL])


@jit(error_model="numpy", inline="always")
def lane_stack(ints, n, lane):
    """Lane ``lane``'s walk stack (lane 0's also serves the build)."""
    own = int_count(n, 0) + lane * STACK
    return ints[own:own + STACK]


@jit(error_model="numpy", inline="always")
def lanes(floats, ints, n):
    """How many threads' lists and stacks a workspace for n slots holds."""
    by_floats = (floats.shape[0] - float_count(n, 0)) // LIST_FLOATS
    by_ints = (ints.shape[0] - int_count(n, 0)) // STACK
    return min(by_floats, by_ints)


@jit(error_model="numpy", inline="always")
def usable(n, work):
    """Is ``work`` a tree workspace for n slots, with lists for one thread at least (else
    the tree's callers sum directly)?"""
    return lanes(work.floats, work.ints, n) >= 1


def fits(n, work):
    """Is ``work`` (from ``workspace``) large enough for n slots? (Python's ``usable``.)"""
    return (work.floats.shape[0] >= float_count(n, THREADS)
            and work.ints.shape[0] >= int_count(n, THREADS))


def workspace(n, threads=True):
    """A workspace for the tree and for the direct-sum kernels of ``engine.forces.pairwise``
    (which use its first blocks), for n particle slots: made once per particle count by the
    simulation that steps, never per step."""
    n = max(int(n), 1)
    return Workspace(np.empty(float_count(n, THREADS)), np.empty(int_count(n, THREADS),
                                                                 dtype=np.int64), bool(threads))


def bytes_per_particle(n):
    """The workspace's bytes per particle slot at n slots (the per-thread lists included)."""
    return 8 * (float_count(n, THREADS) + int_count(n, THREADS)) / n
