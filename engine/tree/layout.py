"""Where the tree keeps its scratch: blocks of one ``Workspace``'s float and int arrays.

For n particle slots and C = ``cell_capacity(n)`` cells, the floats hold, in order:

- ``PARTICLE_FLOATS`` blocks of n: the sorted particles' x, y, z, source weight beta, target
  factor alpha, results ax, ay, az and the potential (summed only when asked for);
- ``CELL_FLOATS`` blocks of C: each cell's centre (3), multipoles (13: weight, dipole,
  quadrupole), size, radius, absolute weight and bounding box (6);
- per thread, its interaction lists: ``LIST_PARTICLES`` particles (x, y, z, beta), twice
  ``LIST_CELLS`` cells (centre and multipoles: summed at each target, or into the group's
  local expansion) and the local expansion (``LOCAL``), and the fast multipole walk's local
  expansion for each of ``DEPTH`` levels;

and the ints: the sort's keys and slots and their copies (4 blocks of n), the radix sort's
counts, ``CELL_INTS`` blocks of C (first particle, count, first child, children, and the list
of leaves) and each thread's stack, the fast multipole walk's candidates and frames and its
outcome.

At 8 bytes a number that is 20 n floats and 6.5 n ints (C = n / 2): 212 bytes a particle,
plus 1.4 MB per thread (320 KB of lists, 1 MB of the fast multipole walk's candidates).
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
#: the fast multipole walk's frames (``fmm``): a cell's level in the tree, at most (a deeper
#: tree, from ranges keyed again in their own cubes, is walked by ``walk`` instead)
DEPTH = 160
LIST_FLOATS = 4 * LIST_PARTICLES + 2 * 13 * LIST_CELLS + LOCAL + DEPTH * LOCAL
#: one thread's walk stack (a compressed tree of 64-bit keys is at most 31 levels deep, and
#: a level pushes at most 8 cells)
STACK = 512
#: the fast multipole walk's candidates: the lists of the cells on the path from the root and
#: the cell being resolved (a scene that needs more is walked by ``walk`` instead), and as many
#: for a cell's deferred list; a frame per level: cell, next child, list start and length;
#: and the lane's outcome (0, or -1 if the scratch ran out)
CANDIDATES = 1 << 16
FRAME_INTS = 4
LANE_INTS = STACK + 2 * CANDIDATES + FRAME_INTS * DEPTH + 1
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
    return 4 * n + RADIX + 1 + CELL_INTS * cell_capacity(n) + threads * LANE_INTS


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
    own = int_count(n, 0) + lane * LANE_INTS
    return ints[own:own + STACK]


@jit(error_model="numpy", inline="always")
def lane_descent(floats, ints, n, lane):
    """Lane ``lane``'s scratch for the fast multipole walk: the candidates, the deferred
    list, the frames (cell, next child, list start, list length) and each frame's local
    expansion, (DEPTH, LOCAL)."""
    own = int_count(n, 0) + lane * LANE_INTS + STACK
    cand = ints[own:own + CANDIDATES]
    deferred = ints[own + CANDIDATES:own + 2 * CANDIDATES]
    f = own + 2 * CANDIDATES
    frames = ints[f:f + FRAME_INTS * DEPTH].reshape((FRAME_INTS, DEPTH))
    base = (PARTICLE_FLOATS * n + CELL_FLOATS * cell_capacity(n) + lane * LIST_FLOATS
            + 4 * LIST_PARTICLES + 2 * 13 * LIST_CELLS + LOCAL)
    locals_ = floats[base:base + DEPTH * LOCAL].reshape((DEPTH, LOCAL))
    return cand, deferred, frames[0], frames[1], frames[2], frames[3], locals_


@jit(error_model="numpy", inline="always")
def lane_status(ints, n, lane):
    """Lane ``lane``'s outcome of the fast multipole walk, a 1-element block."""
    own = int_count(n, 0) + (lane + 1) * LANE_INTS - 1
    return ints[own:own + 1]


@jit(error_model="numpy", inline="always")
def lanes(floats, ints, n):
    """How many threads' lists and stacks a workspace for n slots holds."""
    by_floats = (floats.shape[0] - float_count(n, 0)) // LIST_FLOATS
    by_ints = (ints.shape[0] - int_count(n, 0)) // LANE_INTS
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
