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
5x even doing each pair twice. Each target's sum is independent of the others, so the result does not depend on
the number of threads. The loops are compiled with the reassociation vector reductions need,
never with 'nnan'/'ninf': a singular pair must still produce NaN and be caught.
"""
import math

import numpy as np
from numba import njit, prange

#: reassociation and contraction for vector reductions; never 'nnan'/'ninf' (NaN must survive)
SIMD_MATH = {"reassoc", "contract", "nsz", "arcp"}

#: from this many particle slots on, the vectorised kernels replace the scalar pair loop
#: (measured on leapfrog steps: 16 bodies 0.32 us vectorised against 0.57 us scalar at 15;
#: 8 bodies 0.25 us against 0.21 us)
PARALLEL_MIN = 12

#: from this many interacting particles on, the vectorised kernel also uses every core (a
#: parallel region costs 3 to 4 us to start: measured break-even between 128 and 256 bodies)
THREADS_MIN = 192


def workspace(n):
    """Scratch arrays for the large-N kernels, made once per ``step(n)`` call (in Python, so
    compiled code never allocates per force evaluation): compacted coordinates, weights and
    results (8 n floats) and the index map (n ints). Kernels given a smaller workspace
    (Spacewar passes none) use the scalar pair loop instead."""
    if n < PARALLEL_MIN:
        return np.empty(0), np.empty(0, dtype=np.int64)
    return np.empty(8 * n), np.empty(n, dtype=np.int64)


@njit(cache=True, error_model="numpy", inline="always")
def usable(n, work):
    """Does this call take the vectorised path: enough particles, and a workspace for them?"""
    return n >= PARALLEL_MIN and work.shape[0] >= 8 * n


@njit(cache=True, error_model="numpy", inline="always")
def _image(d, box):
    if box > 0.0:
        return d - box * math.floor(d / box + 0.5)
    return d


@njit(cache=True, fastmath=SIMD_MATH, error_model="numpy", inline="always")
def _target(c, x, y, z, alpha, beta, sources, eps2, box, ax, ay, az):
    """a_c = alpha_c sum_{j < sources, j != c} beta_j d / r^3, in one branch-free pass over
    the sources that reads only, so it vectorises.

    Particle c is dropped as its own source by a select on the index (a vector compare and
    blend), not by splitting the range in two: two shorter loops each end in a scalar
    remainder of up to 31 pairs (8 lanes, 4 interleaved), which measured 2 to 3 times slower
    at N = 1024. A genuinely coincident pair j != c still gives 0 * inf = NaN and is caught.
    """
    xi = x[c]
    yi = y[c]
    zi = z[c]
    sx = 0.0
    sy = 0.0
    sz = 0.0
    for j in range(sources):
        dx = _image(x[j] - xi, box)
        dy = _image(y[j] - yi, box)
        dz = _image(z[j] - zi, box)
        r2 = dx * dx + dy * dy + dz * dz + eps2
        bj = beta[j] / (r2 * math.sqrt(r2))
        bj = 0.0 if j == c else bj
        sx += bj * dx
        sy += bj * dy
        sz += bj * dz
    ax[c] = alpha[c] * sx
    ay[c] = alpha[c] * sy
    az[c] = alpha[c] * sz


# One explicit signature each: a parallel function is compiled into a kernel whose symbol every
# cached caller links against; two specialisations of it (C and A layouts) in one cache were
# seen to let a caller pick the wrong kernel and crash. So there is exactly one.
_ARR = "float64[::1]"
_FIELD_SIGNATURE = f"void({', '.join([_ARR] * 5)}, int64, int64, float64, float64, {', '.join([_ARR] * 3)})"


@njit(_FIELD_SIGNATURE, parallel=True, cache=True, fastmath=SIMD_MATH, error_model="numpy")
def field(x, y, z, alpha, beta, targets, sources, eps2, box, ax, ay, az):
    """The field on particles [0, targets) from particles [0, sources), targets spread over
    all cores. Particles from ``sources`` on only feel the field (test particles)."""
    for c in prange(targets):
        _target(c, x, y, z, alpha, beta, sources, eps2, box, ax, ay, az)


@njit(_FIELD_SIGNATURE, cache=True, fastmath=SIMD_MATH, error_model="numpy")
def field_serial(x, y, z, alpha, beta, targets, sources, eps2, box, ax, ay, az):
    """``field`` on one core: for mid-sized systems, where waking the other threads for each
    evaluation costs more than it saves (and a busy machine can stall a parallel region)."""
    for c in range(targets):
        _target(c, x, y, z, alpha, beta, sources, eps2, box, ax, ay, az)


@njit(cache=True, error_model="numpy", inline="always")
def _field(work, m, sources, eps2, box):
    """The field of the gathered particles: coordinates, alpha and beta in ``work``'s first
    five blocks of m, results into the last three."""
    x = work[0:m]
    y = work[m:2 * m]
    z = work[2 * m:3 * m]
    alpha = work[3 * m:4 * m]
    beta = work[4 * m:5 * m]
    ax = work[5 * m:6 * m]
    ay = work[6 * m:7 * m]
    az = work[7 * m:8 * m]
    if m >= THREADS_MIN:
        field(x, y, z, alpha, beta, m, sources, eps2, box, ax, ay, az)
    else:
        field_serial(x, y, z, alpha, beta, m, sources, eps2, box, ax, ay, az)


@njit(cache=True, error_model="numpy", inline="always")
def _gather(pos, iwork, m, work):
    """Copy the m chosen particles' coordinates into work's first three blocks of m."""
    dim = pos.shape[0]
    for c in range(m):
        i = iwork[c]
        work[c] = pos[0, i]
        work[m + c] = pos[1, i]
        work[2 * m + c] = pos[2, i] if dim == 3 else 0.0


@njit(cache=True, error_model="numpy", inline="always")
def _scatter(acc, iwork, m, work):
    dim = acc.shape[0]
    for c in range(m):
        i = iwork[c]
        acc[0, i] += work[5 * m + c]
        acc[1, i] += work[6 * m + c]
        if dim == 3:
            acc[2, i] += work[7 * m + c]


@njit(cache=True, error_model="numpy")
def gravity(pos, mass, active, test, n, G, eps2, box, acc, work, iwork):
    """acc += gravity of the active non-test particles on every active particle (large N)."""
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
    _gather(pos, iwork, m, work)
    for c in range(m):
        work[3 * m + c] = 1.0
        work[4 * m + c] = G * mass[iwork[c]]
    _field(work, m, src, eps2, box)
    _scatter(acc, iwork, m, work)


@njit(cache=True, error_model="numpy")
def coulomb(pos, mass, charge, active, n, k_e, eps2, box, acc, work, iwork):
    """acc += Coulomb accelerations among the active charged particles (large N)."""
    m = 0
    for i in range(n):
        if active[i] and charge[i] != 0.0:
            iwork[m] = i
            m += 1
    _gather(pos, iwork, m, work)
    for c in range(m):
        i = iwork[c]
        work[3 * m + c] = -k_e * charge[i] / mass[i]
        work[4 * m + c] = charge[i]
    _field(work, m, m, eps2, box)
    _scatter(acc, iwork, m, work)
