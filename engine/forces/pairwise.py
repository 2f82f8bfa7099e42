"""Direct-summation pair forces for many particles: SIMD over sources, all cores over targets.

Both gravity and Coulomb have the form

    a_i = alpha_i sum_{j != i} beta_j (p_j - p_i) / (|p_j - p_i|^2 + eps^2)^(3/2)

(gravity: alpha = 1, beta_j = G m_j; Coulomb: alpha_i = -k q_i / m_i, beta_j = q_j). For large
N the active particles are first copied into contiguous coordinate arrays (structure of
arrays), then every target sums over all sources in a branch-free loop that the compiler
vectorises (8 doubles per AVX-512 instruction), targets spread over all cores.

Why not Newton's third law here, as the small-N kernel does? Writing the reaction into the
other body inside the loop stops the vectoriser (it cannot prove the arrays do not overlap):
measured on this project's 2-core machine, the vectorised full sum costs 0.9 ns per pair
visit against 3.8 ns per pair for the scalar symmetric loop, so it wins even doing each pair
twice. Each target's sum is independent of the others, so the result does not depend on
the number of threads. The loops are compiled with the reassociation vector reductions need,
never with 'nnan'/'ninf': a singular pair must still produce NaN and be caught.
"""
import math

import numpy as np
from numba import njit, prange

#: reassociation and contraction for vector reductions; never 'nnan'/'ninf' (NaN must survive)
SIMD_MATH = {"reassoc", "contract", "nsz", "arcp"}

#: from this many particle slots on, the vectorised kernels replace the scalar pair loop
PARALLEL_MIN = 192

#: from this many interacting particles on, the vectorised kernel also uses every core
THREADS_MIN = 1024


def workspace(n):
    """Scratch arrays for the large-N kernels, made once per ``step(n)`` call (in Python, so
    compiled code never allocates per force evaluation): compacted coordinates, weights and
    results (8 n floats) and the index map (n ints)."""
    if n < PARALLEL_MIN:
        return np.empty(0), np.empty(0, dtype=np.int64)
    return np.empty(8 * n), np.empty(n, dtype=np.int64)


@njit(cache=True, error_model="numpy", inline="always")
def _image(d, box):
    if box > 0.0:
        return d - box * math.floor(d / box + 0.5)
    return d


@njit(cache=True, fastmath=SIMD_MATH, error_model="numpy", inline="always")
def _span(x, y, z, beta, eps2, box, xi, yi, zi, j0, j1):
    """sum_{j0 <= j < j1} beta_j (p_j - p_i) / r^3: reads only, so it vectorises."""
    sx = 0.0
    sy = 0.0
    sz = 0.0
    for j in range(j0, j1):
        dx = _image(x[j] - xi, box)
        dy = _image(y[j] - yi, box)
        dz = _image(z[j] - zi, box)
        r2 = dx * dx + dy * dy + dz * dz + eps2
        bj = beta[j] / (r2 * math.sqrt(r2))
        sx += bj * dx
        sy += bj * dy
        sz += bj * dz
    return sx, sy, sz


@njit(cache=True, fastmath=SIMD_MATH, error_model="numpy", inline="always")
def _target(c, x, y, z, alpha, beta, sources, eps2, box, ax, ay, az):
    """a_c = alpha_c sum_{j < sources, j != c} beta_j d / r^3 (particle c is skipped as its
    own source by splitting the range, never by a branch in the loop)."""
    xi = x[c]
    yi = y[c]
    zi = z[c]
    sx, sy, sz = _span(x, y, z, beta, eps2, box, xi, yi, zi, 0, min(c, sources))
    if c + 1 < sources:
        tx, ty, tz = _span(x, y, z, beta, eps2, box, xi, yi, zi, c + 1, sources)
        sx += tx
        sy += ty
        sz += tz
    ax[c] = alpha[c] * sx
    ay[c] = alpha[c] * sy
    az[c] = alpha[c] * sz


# One explicit signature each: a parallel function is compiled into a kernel whose symbol every
# cached caller links against; two specialisations of it (C and A layouts) in one cache were
# seen to let a caller pick the wrong kernel and crash. So there is exactly one.
_ARR = "float64[::1]"
_FIELD_SIGNATURE = f"void({', '.join([_ARR] * 5)}, int64, float64, float64, {', '.join([_ARR] * 3)})"


@njit(_FIELD_SIGNATURE, parallel=True, cache=True, fastmath=SIMD_MATH, error_model="numpy")
def field(x, y, z, alpha, beta, sources, eps2, box, ax, ay, az):
    """Every particle's field from particles [0, sources), targets spread over all cores.

    Particles from ``sources`` on only feel the field (test particles)."""
    for c in prange(x.shape[0]):
        _target(c, x, y, z, alpha, beta, sources, eps2, box, ax, ay, az)


@njit(_FIELD_SIGNATURE, cache=True, fastmath=SIMD_MATH, error_model="numpy")
def field_serial(x, y, z, alpha, beta, sources, eps2, box, ax, ay, az):
    """``field`` on one core: for mid-sized systems, where waking the other threads for each
    evaluation costs more than it saves (and a busy machine can stall a parallel region)."""
    for c in range(x.shape[0]):
        _target(c, x, y, z, alpha, beta, sources, eps2, box, ax, ay, az)


@njit(cache=True, error_model="numpy", inline="always")
def _field(x, y, z, alpha, beta, sources, eps2, box, ax, ay, az):
    if x.shape[0] >= THREADS_MIN:
        field(x, y, z, alpha, beta, sources, eps2, box, ax, ay, az)
    else:
        field_serial(x, y, z, alpha, beta, sources, eps2, box, ax, ay, az)


@njit(cache=True, error_model="numpy", inline="always")
def _gather(pos, iwork, m, work):
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
    b = src
    for i in range(n):
        if active[i]:
            if test[i]:
                iwork[b] = i
                b += 1
            else:
                iwork[a] = i
                a += 1
    m = b  # active particles, sources first
    _gather(pos, iwork, m, work)
    for c in range(m):
        work[3 * m + c] = 1.0
        work[4 * m + c] = G * mass[iwork[c]]
    _field(work[0:m], work[m:2 * m], work[2 * m:3 * m], work[3 * m:4 * m], work[4 * m:5 * m], src,
          eps2, box, work[5 * m:6 * m], work[6 * m:7 * m], work[7 * m:8 * m])
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
    _field(work[0:m], work[m:2 * m], work[2 * m:3 * m], work[3 * m:4 * m], work[4 * m:5 * m], m,
          eps2, box, work[5 * m:6 * m], work[6 * m:7 * m], work[7 * m:8 * m])
    _scatter(acc, iwork, m, work)
