"""Direct-summation pair forces for many particles: SIMD over sources, all cores over targets.

Both gravity and Coulomb have the form

    a_i = alpha_i sum_{j != i} beta_j (p_j - p_i) / (|p_j - p_i|^2 + eps^2)^(3/2)

(gravity: alpha = 1, beta_j = G m_j; Coulomb: alpha_i = -k q_i / m_i, beta_j = q_j). For large
N the active particles are first copied into contiguous coordinate arrays (structure of
arrays), then every target sums over all sources in a branch-free loop that the compiler
vectorises (8 doubles per AVX-512 instruction), targets spread over all cores.

Why not Newton's third law here, as the small-N kernel does? Writing the reaction into the
other body inside the loop stops the vectoriser (it cannot prove the arrays do not overlap):
measured on this project's 2-core machine (one core, N = 1024), the vectorised full sum costs
0.41 ns per pair visit against 4.5 ns per pair for the scalar symmetric loop, so it wins by
5x even doing each pair twice. Each target's sum is independent of the others, so the result
does not depend on the number of threads. The loops are compiled with the reassociation vector
reductions need, never with 'nnan'/'ninf': a singular pair must still produce NaN and be caught.

Gravity can also run in single precision (``NBodyGravity(precision="float32")``): the same
loop on float32 copies of the coordinates, in a frame centred on the particles and scaled to
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


#: the workspace of small systems, shared: its arrays are empty, so nothing can write them
_NO_WORKSPACE = {flag: Workspace(np.empty(0), np.empty(0, dtype=np.int64), flag)
                 for flag in (False, True)}


def workspace(n, threads=True):
    """Scratch for the large-N kernels, made once per ``step(n)`` call (in Python, so compiled
    code never allocates per force evaluation): compacted coordinates, weights and results
    (8 n floats) and the index map (n ints), as an ``engine.state.Workspace``. Kernels given a
    smaller workspace use the scalar pair loop instead. ``threads=False`` keeps the kernels on
    the calling thread (a batch, whose systems already spread over the cores)."""
    if n < PARALLEL_MIN:
        return _NO_WORKSPACE[bool(threads)]
    return Workspace(np.empty(8 * n), np.empty(n, dtype=np.int64), bool(threads))


@jit(error_model="numpy", inline="always")
def usable(n, work):
    """Does this call take the vectorised path: enough particles, and a workspace for them?"""
    return n >= PARALLEL_MIN and work.floats.shape[0] >= 8 * n and work.ints.shape[0] >= n


@jit(fastmath=SIMD_MATH, error_model="numpy", inline="always")
def _target(c, x, y, z, alpha, beta, sources, eps2, box, zero, half, ax, ay, az):
    """a_c = alpha_c sum_{j < sources, j != c} beta_j d / r^3, in one branch-free pass over
    the sources that reads only, so it vectorises.

    Particle c is dropped as its own source by a select on the index (a vector compare and
    blend), not by splitting the row into two loops around it, which measured 3 times slower
    at N = 1024. A genuinely coincident pair j != c still gives 0 * inf = NaN and is caught.
    ``zero`` and ``half`` come in the arrays' precision, so a float32 call stays in float32.
    """
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
        r2 = dx * dx + dy * dy + dz * dz + eps2
        bj = beta[j] / (r2 * math.sqrt(r2))
        bj = zero if j == c else bj
        sx += bj * dx
        sy += bj * dy
        sz += bj * dz
    ax[c] = alpha[c] * sx
    ay[c] = alpha[c] * sy
    az[c] = alpha[c] * sz


# One explicit signature each: a parallel function is compiled into a kernel whose symbol every
# cached caller links against; two specialisations of it (C and A layouts) in one cache were
# seen to let a caller pick the wrong kernel and crash. So there is exactly one per precision.
def _signature(real):
    arr = f"{real}[::1]"
    return f"void({', '.join([arr] * 5)}, int64, int64, {real}, {real}, {', '.join([arr] * 3)})"


@jit(signature=_signature("float64"), parallel=True, fastmath=SIMD_MATH, error_model="numpy")
def field(x, y, z, alpha, beta, targets, sources, eps2, box, ax, ay, az):
    """The field on particles [0, targets) from particles [0, sources), targets spread over
    all cores. Particles from ``sources`` on only feel the field (test particles)."""
    for c in prange(targets):
        _target(c, x, y, z, alpha, beta, sources, eps2, box, 0.0, 0.5, ax, ay, az)


@jit(signature=_signature("float64"), fastmath=SIMD_MATH, error_model="numpy")
def field_serial(x, y, z, alpha, beta, targets, sources, eps2, box, ax, ay, az):
    """``field`` on one core: for mid-sized systems, where waking the other threads for each
    evaluation costs more than it saves (and a busy machine can stall a parallel region)."""
    for c in range(targets):
        _target(c, x, y, z, alpha, beta, sources, eps2, box, 0.0, 0.5, ax, ay, az)


@jit(signature=_signature("float32"), parallel=True, fastmath=SIMD_MATH32, error_model="numpy")
def field32(x, y, z, alpha, beta, targets, sources, eps2, box, ax, ay, az):
    """``field`` in single precision: 16 lanes per AVX-512 instruction instead of 8."""
    for c in prange(targets):
        _target(c, x, y, z, alpha, beta, sources, eps2, box, np.float32(0.0), np.float32(0.5),
                ax, ay, az)


@jit(signature=_signature("float32"), fastmath=SIMD_MATH32, error_model="numpy")
def field32_serial(x, y, z, alpha, beta, targets, sources, eps2, box, ax, ay, az):
    """``field32`` on one core."""
    for c in range(targets):
        _target(c, x, y, z, alpha, beta, sources, eps2, box, np.float32(0.0), np.float32(0.5),
                ax, ay, az)


@jit(error_model="numpy", inline="always")
def _blocks(work, m):
    """The eight blocks of m in ``work``: x, y, z, alpha, beta (inputs), ax, ay, az (results)."""
    return (work[0:m], work[m:2 * m], work[2 * m:3 * m], work[3 * m:4 * m], work[4 * m:5 * m],
            work[5 * m:6 * m], work[6 * m:7 * m], work[7 * m:8 * m])


@jit(error_model="numpy", inline="always")
def _field(work, m, sources, eps2, box, threads):
    """The field of the m gathered particles in float64 ``work``."""
    x, y, z, alpha, beta, ax, ay, az = _blocks(work, m)
    if threads and m >= THREADS_MIN:
        field(x, y, z, alpha, beta, m, sources, eps2, box, ax, ay, az)
    else:
        field_serial(x, y, z, alpha, beta, m, sources, eps2, box, ax, ay, az)


@jit(error_model="numpy", inline="always")
def _field32(work, m, sources, eps2, box, threads):
    """The field of the m gathered particles in float32 ``work``."""
    x, y, z, alpha, beta, ax, ay, az = _blocks(work, m)
    e = np.float32(eps2)
    b = np.float32(box)
    if threads and m >= THREADS_MIN:
        field32(x, y, z, alpha, beta, m, sources, e, b, ax, ay, az)
    else:
        field32_serial(x, y, z, alpha, beta, m, sources, e, b, ax, ay, az)


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
def _gather(pos, iwork, m, work, cx, cy, cz, length):
    """Copy the m chosen particles' coordinates, as (p - centre) / length, into work's first
    three blocks of m (converted to work's precision)."""
    dim = pos.shape[0]
    for c in range(m):
        i = iwork[c]
        work[c] = (pos[0, i] - cx) / length
        work[m + c] = (pos[1, i] - cy) / length
        work[2 * m + c] = (pos[2, i] - cz) / length if dim == 3 else 0.0


@jit(error_model="numpy", inline="always")
def _scatter(acc, iwork, m, work, scale):
    """acc += scale * the results in work's last three blocks (scale undoes the float32 frame;
    1.0, exactly, in float64)."""
    dim = acc.shape[0]
    for c in range(m):
        i = iwork[c]
        acc[0, i] += scale * work[5 * m + c]
        acc[1, i] += scale * work[6 * m + c]
        if dim == 3:
            acc[2, i] += scale * work[7 * m + c]


@jit(error_model="numpy", inline="always")
def _gravity_inputs(pos, mass, iwork, m, G, work, cx, cy, cz, length, weight):
    """Coordinates in the frame (centre, length), alpha = 1, beta = G m / weight into work."""
    _gather(pos, iwork, m, work, cx, cy, cz, length)
    for c in range(m):
        work[3 * m + c] = 1.0
        work[4 * m + c] = G * mass[iwork[c]] / weight


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
        _gravity_inputs(pos, mass, iwork, m, G, w32, cx, cy, cz, length, weight)
        _field32(w32, m, src, eps2 / (length * length), box / length, threads)
        _scatter(acc, iwork, m, w32, weight / (length * length))
    else:
        _gravity_inputs(pos, mass, iwork, m, G, work, 0.0, 0.0, 0.0, 1.0, 1.0)
        _field(work, m, src, eps2, box, threads)
        _scatter(acc, iwork, m, work, 1.0)


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
    _gather(pos, iwork, m, work, 0.0, 0.0, 0.0, 1.0)
    for c in range(m):
        i = iwork[c]
        work[3 * m + c] = -k_e * charge[i] / mass[i]
        work[4 * m + c] = charge[i]
    _field(work, m, m, eps2, box, threads)
    _scatter(acc, iwork, m, work, 1.0)
