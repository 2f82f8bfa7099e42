"""Direct-summation pair forces for many particles: each pair once, SIMD over targets, the
pair triangle spread over all cores.

Both gravity and Coulomb have the form

    a_i = alpha_i sum_{j != i} beta_j (p_j - p_i) / (|p_j - p_i|^2 + eps^2)^(3/2)

(gravity: alpha = 1, beta_j = G m_j; Coulomb: alpha_i = -k q_i / m_i, beta_j = q_j). For large
N the active particles are first copied into contiguous coordinate arrays (structure of arrays,
each block padded to an odd number of cache lines so that no two blocks fall on the same cache
sets), then the pair sum runs in compiled, vectorised loops.

**Each pair once (Newton's third law), in register tiles.** With w_ij = (p_j - p_i) / r^3,
a source's sum S_i = sum_j beta_j w_ij gains beta_j w_ij and S_j loses beta_i w_ij from one
evaluation of w_ij. The obvious loop that writes the reaction into the other body does not
vectorise (the compiler cannot prove the arrays do not overlap). So the sources are taken four
at a time, held in scalars (registers): one pass over the targets i below them evaluates the
4 pairs (i, j..j+3), adds their pull on i into the target's accumulator (the only array
write, one per target, which LLVM vectorises behind a run-time overlap check) and gathers the
four reactions in twelve scalar sums, written once after the pass. The six pairs inside the
four are done apart. Measured on the 2-core AMD EPYC (znver4) at N = 1024, one core: 0.53 ms
a field against 0.91 ms for the former loop, which visited every pair from both ends and
needed no reaction writes (``python -m validation bench`` measures it on steps, side by side
with REBOUND). Eight sources a pass measured slower (0.71 ms: too few registers); cutting the
passes into L1-sized tiles of targets measured the same as whole passes up to N = 65536.

**The same bits on any number of threads.** The pair triangle is cut into ``CHUNKS`` row
ranges of about equal work (``chunk_rows``), each with its own
accumulators; the chunks' sums are then added in chunk order. A chunk is one compiled function
that every caller runs (the multi-core driver over the cores, the one-core driver in turn), so
which thread runs it, and whether it is a ``Batch`` or a ``Simulation`` calling, changes no
bit. Test particles (targets from ``sources`` on) feel the sources one-sidedly: each sums over
all sources in a branch-free loop, as the former kernel did for everyone. The loops are
compiled with the reassociation vector reductions need, never with 'nnan'/'ninf': a
coincident pair must still produce NaN and be caught.

Gravity can also run in single precision (``NBodyGravity(precision="float32")``): the same
loops on float32 copies of the coordinates, in a frame centred on the particles and scaled to
their extent by a power of two, so that no unit system overflows r^3.
"""
import math

import numpy as np
from numba import prange

from ..cache import jit

from ..space import image
from ..state import Workspace

#: reassociation and contraction for vector reductions; never 'nnan'/'ninf' (NaN must survive)
SIMD_MATH = {"reassoc", "contract", "nsz", "arcp"}

#: single precision without 'arcp': with it LLVM turns beta / (r2 sqrt(r2)) into an estimate
#: of rsqrt(r2^3), whose r2^3 overflows float32 from r = 2.6e6 (NaN forces); as fast without
SIMD_MATH32 = {"reassoc", "contract", "nsz"}

#: from this many particle slots on, the vectorised kernels replace the scalar pair loop
#: (measured on leapfrog steps: 16 bodies 0.32 us vectorised against 0.57 us scalar at 15;
#: 8 bodies 0.25 us against 0.21 us)
PARALLEL_MIN = 12

#: from this many interacting particles on, the vectorised kernel also uses every core (a
#: parallel region costs 3 to 4 us to start: measured break-even between 128 and 256 bodies)
THREADS_MIN = 192

#: the pair triangle's row ranges, each with its own accumulators; a constant, so that the sum
#: is the same on any machine (4: even work for 1, 2 or 4 threads; 2 measured the same at
#: N = 1024 on 2 cores, 8 the same again but with twice the accumulators)
CHUNKS = 4

#: a pass's own cost (loop start, reductions, the six pairs within the four), in pair
#: evaluations per source: measured at N = 1024, a chunk of short passes took 143 us and one
#: of long passes 128 us for the same number of pairs, 0.16 us a pass of four sources
PASS_COST = 40.0

#: float blocks of the workspace: x, y, z, alpha, beta, then x, y, z accumulators per chunk
BLOCKS = 5 + 3 * CHUNKS

#: a block's padding at most, in elements (up to a whole cache line, then one more)
PADDING = 32


#: the workspace of small systems, shared: its arrays are empty, so nothing can write them
_NO_WORKSPACE = {flag: Workspace(np.empty(0), np.empty(0, dtype=np.int64), flag)
                 for flag in (False, True)}


@jit(error_model="numpy", inline="always")
def float_count(n):
    """The workspace floats (float64) the large-N kernels need for n particles, in either
    precision (a float32 call sees the same memory as twice as many float32 slots)."""
    return BLOCKS * (n + PADDING)


def workspace(n, threads=True):
    """Scratch for the large-N kernels, made once per ``step(n)`` call (in Python, so compiled
    code never allocates per force evaluation): compacted coordinates, weights and per-chunk
    results (``float_count(n)`` floats) and the index map (n ints), as an
    ``engine.state.Workspace``. Kernels given a smaller workspace use the scalar pair loop
    instead. ``threads=False`` keeps the kernels on the calling thread (a batch, whose systems
    already spread over the cores); the result is the same to the bit."""
    if n < PARALLEL_MIN:
        return _NO_WORKSPACE[bool(threads)]
    return Workspace(np.empty(float_count(n)), np.empty(n, dtype=np.int64), bool(threads))


@jit(error_model="numpy", inline="always")
def usable(n, work):
    """Does this call take the vectorised path: enough particles, and a workspace for them?"""
    return n >= PARALLEL_MIN and work.floats.shape[0] >= float_count(n) and work.ints.shape[0] >= n


@jit(error_model="numpy", inline="always")
def stride(m, line):
    """The distance between blocks of m elements, ``line`` of them to a 64-byte cache line:
    whole lines, an odd number of them. Blocks a power-of-two apart map to the same cache sets
    and collide (measured at N = 4096: 9.5 ms a field unpadded, 8.2 ms padded, one core)."""
    lines = (m + line - 1) // line
    if lines % 2 == 0:
        lines += 1
    return lines * line


@jit(fastmath=SIMD_MATH, error_model="numpy", inline="always")
def _pull(dx, dy, dz, eps2, one):
    """1 / (|d|^2 + eps^2)^(3/2): the factor every pair term shares."""
    r2 = eps2 + dx * dx + dy * dy + dz * dz
    return one / (r2 * math.sqrt(r2))


@jit(fastmath=SIMD_MATH, error_model="numpy", inline="always")
def _four_against(xs, ys, zs, bs, tx, ty, tz, tb, sx, sy, sz, eps2, box, zero, half):
    """Four sources (coordinates and weights in the 4-tuples ``xs`` .. ``bs``) against the
    targets in arrays ``tx`` .. ``tb``: each target's accumulator ``sx``/``sy``/``sz`` gains its
    pull toward the four; the four reactions come back as 12 sums (x, y, z for each source).
    The loop's indices start at 0: with a variable start numba keeps its negative-index
    wraparound, and the loop is not vectorised (measured: 2.2 ms against 0.53 ms)."""
    x0, x1, x2, x3 = xs
    y0, y1, y2, y3 = ys
    z0, z1, z2, z3 = zs
    b0, b1, b2, b3 = bs
    one = half + half
    r0x = zero
    r0y = zero
    r0z = zero
    r1x = zero
    r1y = zero
    r1z = zero
    r2x = zero
    r2y = zero
    r2z = zero
    r3x = zero
    r3y = zero
    r3z = zero
    for i in range(tx.shape[0]):
        xi = tx[i]
        yi = ty[i]
        zi = tz[i]
        dx0 = image(x0 - xi, box, half)
        dy0 = image(y0 - yi, box, half)
        dz0 = image(z0 - zi, box, half)
        dx1 = image(x1 - xi, box, half)
        dy1 = image(y1 - yi, box, half)
        dz1 = image(z1 - zi, box, half)
        dx2 = image(x2 - xi, box, half)
        dy2 = image(y2 - yi, box, half)
        dz2 = image(z2 - zi, box, half)
        dx3 = image(x3 - xi, box, half)
        dy3 = image(y3 - yi, box, half)
        dz3 = image(z3 - zi, box, half)
        f0 = _pull(dx0, dy0, dz0, eps2, one)
        f1 = _pull(dx1, dy1, dz1, eps2, one)
        f2 = _pull(dx2, dy2, dz2, eps2, one)
        f3 = _pull(dx3, dy3, dz3, eps2, one)
        g0 = b0 * f0
        g1 = b1 * f1
        g2 = b2 * f2
        g3 = b3 * f3
        sx[i] += g0 * dx0 + g1 * dx1 + g2 * dx2 + g3 * dx3
        sy[i] += g0 * dy0 + g1 * dy1 + g2 * dy2 + g3 * dy3
        sz[i] += g0 * dz0 + g1 * dz1 + g2 * dz2 + g3 * dz3
        bi = tb[i]
        h0 = bi * f0
        h1 = bi * f1
        h2 = bi * f2
        h3 = bi * f3
        r0x -= h0 * dx0
        r0y -= h0 * dy0
        r0z -= h0 * dz0
        r1x -= h1 * dx1
        r1y -= h1 * dy1
        r1z -= h1 * dz1
        r2x -= h2 * dx2
        r2y -= h2 * dy2
        r2z -= h2 * dz2
        r3x -= h3 * dx3
        r3y -= h3 * dy3
        r3z -= h3 * dz3
    return (r0x, r0y, r0z), (r1x, r1y, r1z), (r2x, r2y, r2z), (r3x, r3y, r3z)


@jit(fastmath=SIMD_MATH, error_model="numpy", inline="always")
def _four_sources(j, x, y, z, beta, eps2, box, zero, half, ax, ay, az):
    """Sources j .. j+3 against every target below j: both sides of every pair."""
    xs = (x[j], x[j + 1], x[j + 2], x[j + 3])
    ys = (y[j], y[j + 1], y[j + 2], y[j + 3])
    zs = (z[j], z[j + 1], z[j + 2], z[j + 3])
    bs = (beta[j], beta[j + 1], beta[j + 2], beta[j + 3])
    r0, r1, r2, r3 = _four_against(xs, ys, zs, bs, x[:j], y[:j], z[:j], beta[:j], ax[:j],
                                   ay[:j], az[:j], eps2, box, zero, half)
    _add(ax, ay, az, j, r0)
    _add(ax, ay, az, j + 1, r1)
    _add(ax, ay, az, j + 2, r2)
    _add(ax, ay, az, j + 3, r3)


@jit(error_model="numpy", inline="always")
def _add(ax, ay, az, j, r):
    """Accumulator j += the 3-tuple r."""
    ax[j] += r[0]
    ay[j] += r[1]
    az[j] += r[2]


@jit(fastmath=SIMD_MATH, error_model="numpy", inline="always")
def _one_source(j, x, y, z, beta, eps2, box, zero, half, ax, ay, az):
    """Source j against every target below j (the sources left over from fours)."""
    one = half + half
    xj = x[j]
    yj = y[j]
    zj = z[j]
    bj = beta[j]
    tx = x[:j]
    ty = y[:j]
    tz = z[:j]
    tb = beta[:j]
    sx = ax[:j]
    sy = ay[:j]
    sz = az[:j]
    rx = zero
    ry = zero
    rz = zero
    for i in range(tx.shape[0]):
        dx = image(xj - tx[i], box, half)
        dy = image(yj - ty[i], box, half)
        dz = image(zj - tz[i], box, half)
        f = _pull(dx, dy, dz, eps2, one)
        g = bj * f
        sx[i] += g * dx
        sy[i] += g * dy
        sz[i] += g * dz
        h = tb[i] * f
        rx -= h * dx
        ry -= h * dy
        rz -= h * dz
    _add(ax, ay, az, j, (rx, ry, rz))


@jit(fastmath=SIMD_MATH, error_model="numpy", inline="always")
def _within_four(j, x, y, z, beta, eps2, box, zero, half, ax, ay, az):
    """The six pairs among sources j .. j+3."""
    one = half + half
    for a in range(j, j + 3):
        for b in range(a + 1, j + 4):
            dx = image(x[b] - x[a], box, half)
            dy = image(y[b] - y[a], box, half)
            dz = image(z[b] - z[a], box, half)
            f = _pull(dx, dy, dz, eps2, one)
            ga = beta[b] * f
            gb = beta[a] * f
            ax[a] += ga * dx
            ay[a] += ga * dy
            az[a] += ga * dz
            ax[b] -= gb * dx
            ay[b] -= gb * dy
            az[b] -= gb * dz


@jit(error_model="numpy", inline="always")
def chunk_rows(k, sources):
    """The first source of chunk k (k = CHUNKS gives ``sources``), so that each chunk costs
    about the same: the sources below b cost b^2 / 2 pairs plus ``PASS_COST`` pairs' worth of
    overhead each, and b solves b^2 / 2 + PASS_COST b = (k / CHUNKS) of the whole; rounded
    down to a four."""
    if k >= CHUNKS:
        return sources
    whole = 0.5 * sources * sources + PASS_COST * sources
    share = whole * k / CHUNKS
    row = int(math.sqrt(PASS_COST * PASS_COST + 2.0 * share) - PASS_COST)
    return row - row % 4


@jit(error_model="numpy", inline="always")
def _accumulators(acc, k, s, m):
    """Chunk k's three accumulator blocks (x, y, z) in ``acc``, each m long, ``s`` apart."""
    base = 3 * k * s
    return acc[base:base + m], acc[base + s:base + s + m], acc[base + 2 * s:base + 2 * s + m]


@jit(fastmath=SIMD_MATH, error_model="numpy", inline="always")
def _pair_chunk(k, x, y, z, beta, sources, eps2, box, acc, s, zero, half):
    """Chunk k of the symmetric sum: sources [lo, hi) against every source below them, both
    sides of each pair, into chunk k's accumulators (zeroed first over [0, hi); chunk 0's
    over all sources, as the chunks' sums are gathered there)."""
    lo = chunk_rows(k, sources)
    hi = chunk_rows(k + 1, sources)
    ax, ay, az = _accumulators(acc, k, s, sources)
    for i in range(sources if k == 0 else hi):
        ax[i] = zero
        ay[i] = zero
        az[i] = zero
    fours = lo + (hi - lo) // 4 * 4
    for j in range(lo, fours, 4):
        _four_sources(j, x, y, z, beta, eps2, box, zero, half, ax, ay, az)
        _within_four(j, x, y, z, beta, eps2, box, zero, half, ax, ay, az)
    for j in range(fours, hi):
        _one_source(j, x, y, z, beta, eps2, box, zero, half, ax, ay, az)


@jit(error_model="numpy", inline="always")
def _combine(alpha, sources, acc, s):
    """a_c = alpha_c (the chunks' accumulators for c added in chunk order), into chunk 0's
    blocks. Compiled without fast-math, so the adds happen in the order written."""
    ax, ay, az = _accumulators(acc, 0, s, sources)
    for k in range(1, CHUNKS):
        bx, by, bz = _accumulators(acc, k, s, chunk_rows(k + 1, sources))
        for c in range(bx.shape[0]):
            ax[c] += bx[c]
            ay[c] += by[c]
            az[c] += bz[c]
    for c in range(sources):
        ax[c] *= alpha[c]
        ay[c] *= alpha[c]
        az[c] *= alpha[c]


@jit(fastmath=SIMD_MATH, error_model="numpy", inline="always")
def _test_targets(k, x, y, z, alpha, beta, sources, targets, eps2, box, acc, s, zero, half):
    """Chunk k of the test particles [sources, targets): a_c = alpha_c sum_j beta_j d / r^3 over
    all sources, in one branch-free pass that reads only, into chunk 0's blocks."""
    one = half + half
    count = targets - sources
    first = sources + k * count // CHUNKS
    last = sources + (k + 1) * count // CHUNKS
    for c in range(first, last):
        xi = x[c]
        yi = y[c]
        zi = z[c]
        sx = zero
        sy = zero
        sz = zero
        for j in range(sources):
            dx = image(x[j] - xi, box, half)
            dy = image(y[j] - yi, box, half)
            dz = image(z[j] - zi, box, half)
            g = beta[j] * _pull(dx, dy, dz, eps2, one)
            sx += g * dx
            sy += g * dy
            sz += g * dz
        acc[c] = alpha[c] * sx
        acc[s + c] = alpha[c] * sy
        acc[2 * s + c] = alpha[c] * sz


# One explicit signature each, and the work in separately compiled functions that both drivers
# call: a function compiled twice (inlined into a parallel and a serial caller) may be
# vectorised differently and round differently; one copy cannot. (Also, a parallel function
# is compiled into a kernel whose symbol every cached caller links against; two
# specialisations of it in one cache were seen to let a caller pick the wrong kernel and
# crash. So there is exactly one per precision.)
def _chunk_signature(real):
    arr = f"{real}[::1]"
    return f"void(int64, {', '.join([arr] * 4)}, int64, {real}, {real}, {arr}, int64)"


def _tests_signature(real):
    arr = f"{real}[::1]"
    return f"void(int64, {', '.join([arr] * 5)}, int64, int64, {real}, {real}, {arr}, int64)"


def _combine_signature(real):
    return f"void({real}[::1], int64, {real}[::1], int64)"


def _driver_signature(real):
    arr = f"{real}[::1]"
    return f"void({', '.join([arr] * 5)}, int64, int64, {real}, {real}, {arr}, int64)"


@jit(signature=_chunk_signature("float64"), fastmath=SIMD_MATH, error_model="numpy")
def pair_chunk(k, x, y, z, beta, sources, eps2, box, acc, s):
    """Chunk k of the symmetric float64 sum (``_pair_chunk``)."""
    _pair_chunk(k, x, y, z, beta, sources, eps2, box, acc, s, 0.0, 0.5)


@jit(signature=_chunk_signature("float32"), fastmath=SIMD_MATH32, error_model="numpy")
def pair_chunk32(k, x, y, z, beta, sources, eps2, box, acc, s):
    """Chunk k of the symmetric float32 sum (16 lanes per AVX-512 instruction instead of 8)."""
    _pair_chunk(k, x, y, z, beta, sources, eps2, box, acc, s, np.float32(0.0), np.float32(0.5))


@jit(signature=_tests_signature("float64"), fastmath=SIMD_MATH, error_model="numpy")
def test_chunk(k, x, y, z, alpha, beta, sources, targets, eps2, box, acc, s):
    """Chunk k of the float64 test particles (``_test_targets``)."""
    _test_targets(k, x, y, z, alpha, beta, sources, targets, eps2, box, acc, s, 0.0, 0.5)


@jit(signature=_tests_signature("float32"), fastmath=SIMD_MATH32, error_model="numpy")
def test_chunk32(k, x, y, z, alpha, beta, sources, targets, eps2, box, acc, s):
    """Chunk k of the float32 test particles."""
    _test_targets(k, x, y, z, alpha, beta, sources, targets, eps2, box, acc, s,
                  np.float32(0.0), np.float32(0.5))


@jit(signature=_combine_signature("float64"), error_model="numpy")
def combine(alpha, sources, acc, s):
    """The float64 chunks' sums (``_combine``)."""
    _combine(alpha, sources, acc, s)


@jit(signature=_combine_signature("float32"), error_model="numpy")
def combine32(alpha, sources, acc, s):
    """The float32 chunks' sums."""
    _combine(alpha, sources, acc, s)


@jit(signature=_driver_signature("float64"), parallel=True, error_model="numpy")
def pairs(x, y, z, alpha, beta, targets, sources, eps2, box, acc, s):
    """The symmetric float64 sum among particles [0, sources), its chunks over all cores, into
    ``acc``'s first three blocks (``s`` apart)."""
    for k in prange(CHUNKS):
        pair_chunk(k, x, y, z, beta, sources, eps2, box, acc, s)
    combine(alpha, sources, acc, s)


@jit(signature=_driver_signature("float64"), parallel=True, error_model="numpy")
def tests(x, y, z, alpha, beta, targets, sources, eps2, box, acc, s):
    """The float64 field on the test particles [sources, targets), over all cores. (Its own
    parallel function: a second parallel loop in ``pairs``, even skipped, measured 10 us a
    call at N = 1024.)"""
    for k in prange(CHUNKS):
        test_chunk(k, x, y, z, alpha, beta, sources, targets, eps2, box, acc, s)


@jit(signature=_driver_signature("float32"), parallel=True, error_model="numpy")
def pairs32(x, y, z, alpha, beta, targets, sources, eps2, box, acc, s):
    """``pairs`` in single precision."""
    for k in prange(CHUNKS):
        pair_chunk32(k, x, y, z, beta, sources, eps2, box, acc, s)
    combine32(alpha, sources, acc, s)


@jit(signature=_driver_signature("float32"), parallel=True, error_model="numpy")
def tests32(x, y, z, alpha, beta, targets, sources, eps2, box, acc, s):
    """``tests`` in single precision."""
    for k in prange(CHUNKS):
        test_chunk32(k, x, y, z, alpha, beta, sources, targets, eps2, box, acc, s)


@jit(error_model="numpy", inline="always")
def field(x, y, z, alpha, beta, targets, sources, eps2, box, acc, s):
    """The float64 field on particles [0, targets) from particles [0, sources), over all
    cores, into ``acc``'s first three blocks (``s`` apart). Particles from ``sources`` on only
    feel the field (test particles)."""
    pairs(x, y, z, alpha, beta, targets, sources, eps2, box, acc, s)
    if targets > sources:
        tests(x, y, z, alpha, beta, targets, sources, eps2, box, acc, s)


@jit(signature=_driver_signature("float64"), error_model="numpy")
def field_serial(x, y, z, alpha, beta, targets, sources, eps2, box, acc, s):
    """``field`` on one core, the same chunks in turn (the same bits): for mid-sized systems,
    where waking the other threads costs more than it saves, and for a ``Batch``."""
    for k in range(CHUNKS):
        pair_chunk(k, x, y, z, beta, sources, eps2, box, acc, s)
    combine(alpha, sources, acc, s)
    for k in range(CHUNKS if targets > sources else 0):
        test_chunk(k, x, y, z, alpha, beta, sources, targets, eps2, box, acc, s)


@jit(error_model="numpy", inline="always")
def field32(x, y, z, alpha, beta, targets, sources, eps2, box, acc, s):
    """``field`` in single precision."""
    pairs32(x, y, z, alpha, beta, targets, sources, eps2, box, acc, s)
    if targets > sources:
        tests32(x, y, z, alpha, beta, targets, sources, eps2, box, acc, s)


@jit(signature=_driver_signature("float32"), error_model="numpy")
def field32_serial(x, y, z, alpha, beta, targets, sources, eps2, box, acc, s):
    """``field32`` on one core."""
    for k in range(CHUNKS):
        pair_chunk32(k, x, y, z, beta, sources, eps2, box, acc, s)
    combine32(alpha, sources, acc, s)
    for k in range(CHUNKS if targets > sources else 0):
        test_chunk32(k, x, y, z, alpha, beta, sources, targets, eps2, box, acc, s)


@jit(error_model="numpy", inline="always")
def _blocks(work, m, s):
    """The blocks of m in ``work``, ``s`` apart: x, y, z, alpha, beta (inputs), then the
    accumulators from block 5 on (``acc``; chunk 0's x, y, z blocks get the results)."""
    return (work[0:m], work[s:s + m], work[2 * s:2 * s + m], work[3 * s:3 * s + m],
            work[4 * s:4 * s + m], work[5 * s:])


@jit(error_model="numpy", inline="always")
def _field(work, m, sources, eps2, box, threads):
    """The field of the m gathered particles in float64 ``work``."""
    s = stride(m, 8)
    x, y, z, alpha, beta, acc = _blocks(work, m, s)
    if threads and m >= THREADS_MIN:
        field(x, y, z, alpha, beta, m, sources, eps2, box, acc, s)
    else:
        field_serial(x, y, z, alpha, beta, m, sources, eps2, box, acc, s)


@jit(error_model="numpy", inline="always")
def _field32(work, m, sources, eps2, box, threads):
    """The field of the m gathered particles in float32 ``work``."""
    s = stride(m, 16)
    x, y, z, alpha, beta, acc = _blocks(work, m, s)
    e = np.float32(eps2)
    b = np.float32(box)
    if threads and m >= THREADS_MIN:
        field32(x, y, z, alpha, beta, m, sources, e, b, acc, s)
    else:
        field32_serial(x, y, z, alpha, beta, m, sources, e, b, acc, s)


@jit(error_model="numpy", inline="always")
def _power_of_two_above(x):
    """The smallest power of two >= x (1.0 for x = 0): scaling by it is exact."""
    if x == 0.0 or not math.isfinite(x):
        return 1.0
    _, exponent = math.frexp(x)
    return math.ldexp(1.0, exponent)


@jit(error_model="numpy", inline="always")
def _frame(pos, iwork, m):
    """Centre and length scale of the m chosen particles, for float32 coordinates: their mean
    position, and a power of two at least their largest distance from it along an axis. The
    kernel then sees coordinates in [-1, 1], far from float32's overflow and underflow."""
    dim = pos.shape[0]
    cx = 0.0
    cy = 0.0
    cz = 0.0
    for c in range(m):
        i = iwork[c]
        cx += pos[0, i]
        cy += pos[1, i]
        if dim == 3:
            cz += pos[2, i]
    cx /= m
    cy /= m
    cz /= m
    extent = 0.0
    for c in range(m):
        i = iwork[c]
        extent = max(extent, abs(pos[0, i] - cx), abs(pos[1, i] - cy))
        if dim == 3:
            extent = max(extent, abs(pos[2, i] - cz))
    return cx, cy, cz, _power_of_two_above(extent)


@jit(error_model="numpy", inline="always")
def _gather(pos, iwork, m, work, s, cx, cy, cz, length):
    """Copy the m chosen particles' coordinates, as (p - centre) / length, into work's first
    three blocks (``s`` apart; converted to work's precision)."""
    dim = pos.shape[0]
    for c in range(m):
        i = iwork[c]
        work[c] = (pos[0, i] - cx) / length
        work[s + c] = (pos[1, i] - cy) / length
        work[2 * s + c] = (pos[2, i] - cz) / length if dim == 3 else 0.0


@jit(error_model="numpy", inline="always")
def _scatter(acc, iwork, m, work, s, scale):
    """acc += scale * the results in work's blocks 5, 6, 7 (scale undoes the float32 frame;
    1.0, exactly, in float64)."""
    dim = acc.shape[0]
    for c in range(m):
        i = iwork[c]
        acc[0, i] += scale * work[5 * s + c]
        acc[1, i] += scale * work[6 * s + c]
        if dim == 3:
            acc[2, i] += scale * work[7 * s + c]


@jit(error_model="numpy", inline="always")
def _gravity_inputs(pos, mass, iwork, m, G, work, s, cx, cy, cz, length, weight):
    """Coordinates in the frame (centre, length), alpha = 1, beta = G m / weight into work."""
    _gather(pos, iwork, m, work, s, cx, cy, cz, length)
    for c in range(m):
        work[3 * s + c] = 1.0
        work[4 * s + c] = G * mass[iwork[c]] / weight


@jit(error_model="numpy")
def gravity(pos, mass, active, test, n, G, eps2, box, single, acc, workspace):
    """acc += gravity of the active non-test particles on every active particle (large N);
    ``single``: pair sums in float32 (the workspace's memory seen as float32)."""
    work = workspace.floats
    iwork = workspace.ints
    threads = workspace.threads
    src = 0
    for i in range(n):
        if active[i] and not test[i]:
            src += 1
    a = 0
    m = src
    for i in range(n):
        if active[i]:
            if test[i]:
                iwork[m] = i
                m += 1
            else:
                iwork[a] = i
                a += 1
    # m active particles, the src sources first
    if m == 0:
        return
    if single:
        # a = (G m_max / L^2) sum (m_j / m_max) d' / r'^3 with d' = d / L: every float32
        # quantity is of order one, whatever the units (SI distances overflow r^3 otherwise)
        cx, cy, cz, length = _frame(pos, iwork, m)
        gm_max = 0.0
        for c in range(src):
            gm_max = max(gm_max, G * mass[iwork[c]])
        weight = _power_of_two_above(gm_max)
        w32 = work.view(np.float32)
        s = stride(m, 16)
        _gravity_inputs(pos, mass, iwork, m, G, w32, s, cx, cy, cz, length, weight)
        _field32(w32, m, src, eps2 / (length * length), box / length, threads)
        _scatter(acc, iwork, m, w32, s, weight / (length * length))
    else:
        s = stride(m, 8)
        _gravity_inputs(pos, mass, iwork, m, G, work, s, 0.0, 0.0, 0.0, 1.0, 1.0)
        _field(work, m, src, eps2, box, threads)
        _scatter(acc, iwork, m, work, s, 1.0)


@jit(error_model="numpy")
def coulomb(pos, mass, charge, active, n, k_e, eps2, box, acc, workspace):
    """acc += Coulomb accelerations among the active charged particles (large N)."""
    work = workspace.floats
    iwork = workspace.ints
    threads = workspace.threads
    m = 0
    for i in range(n):
        if active[i] and charge[i] != 0.0:
            iwork[m] = i
            m += 1
    if m == 0:
        return
    s = stride(m, 8)
    _gather(pos, iwork, m, work, s, 0.0, 0.0, 0.0, 1.0)
    for c in range(m):
        i = iwork[c]
        work[3 * s + c] = -k_e * charge[i] / mass[i]
        work[4 * s + c] = charge[i]
    _field(work, m, m, eps2, box, threads)
    _scatter(acc, iwork, m, work, s, 1.0)
