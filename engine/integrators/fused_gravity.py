"""The splitting methods fused with open-space gravity, for a few bodies over many steps.

A scene that is exactly one ``NBodyGravity`` term in open space (no periodic box), on fewer active
bodies than the vectorised kernels start at (``pairwise.PARALLEL_MIN``) and with no test
particles, is the planetary-system case: five bodies, millions of steps. There the general
executor of ``splitting`` spends more time on its generality (the force-table call with its
fifteen array arguments, strided (dim, n) indexing, a save and a finiteness pass per step)
than on the physics. This executor runs the same drift/kick sequence on an interleaved
(n, 3) copy of the active bodies and evaluates gravity inline.

It computes exactly what ``splitting.advance`` computes, operation for operation: the same
pair loop (Newton's third law, a_i += G m_j d / r^3, a_j -= G m_i d / r^3), the same
kicks ``v += (d_k h) a`` and drifts ``p += (c_k h) v``, the same reuse of the last evaluation
(verlet, yoshida4), so the results are bit-identical (the tests hold it to that). The one
difference: an inactive body is left untouched here, where the general path's masked drift
adds 0 to it (which turns a coordinate of -0.0 into +0.0).

A blow-up is found without a check per step: a non-finite coordinate never becomes finite
again within a call (inf and NaN absorb every later add and multiply), so the state is checked
once per block of ``BLOCK`` steps against a copy taken at the start of the block; a failed
block is re-run step by step from that copy to stop at the last finite state, as the general
executor does.
"""
import math

import numpy as np
from ..cache import jit

from ..forces import gravity, pairwise
from .common import OK

#: steps between finiteness checks (and state copies); the cost of a failure's re-run
BLOCK = 64


@jit(error_model="numpy", inline="always")
def applies(state, model):
    """Is this call the fused case: one open-space gravity term, few bodies, none of them test
    particles or pinned?"""
    kinds = model.kinds
    if kinds.shape[0] != 1 or kinds[0] != gravity.KIND or model.params[model.param_offsets[0] + 2] != 0.0:
        return False
    n = state.n
    if state.box != 0.0 or n >= pairwise.PARALLEL_MIN or state.pos.shape[0] > 3:
        return False
    for i in range(n):
        if state.active[i] and (state.test[i] or state.pinned[i]):
            return False
    return True


@jit(error_model="numpy", inline="always")
def _gravity(P, gm, m, eps2, A):
    """A = accelerations of the m bodies at positions P (rows), G m_j in gm: the pair loop of
    ``gravity._open_space_3d`` on interleaved rows.

    The first body's pass stores where the others accumulate, instead of zeroing A first
    (0 - x is -x and 0 + x is x, so no bit changes; it saves 5% of a five-body step)."""
    for i in range(m):
        xi = P[i, 0]
        yi = P[i, 1]
        zi = P[i, 2]
        gi = gm[i]
        axi = 0.0
        ayi = 0.0
        azi = 0.0
        for j in range(i + 1, m):
            dx = P[j, 0] - xi
            dy = P[j, 1] - yi
            dz = P[j, 2] - zi
            r2 = dx * dx + dy * dy + dz * dz + eps2
            inv_r3 = 1.0 / (r2 * math.sqrt(r2))
            si = gm[j] * inv_r3
            sj = gi * inv_r3
            axi += si * dx
            ayi += si * dy
            azi += si * dz
            if i == 0:
                A[j, 0] = -(sj * dx)
                A[j, 1] = -(sj * dy)
                A[j, 2] = -(sj * dz)
            else:
                A[j, 0] -= sj * dx
                A[j, 1] -= sj * dy
                A[j, 2] -= sj * dz
        if i == 0:
            A[i, 0] = axi
            A[i, 1] = ayi
            A[i, 2] = azi
        else:
            A[i, 0] += axi
            A[i, 1] += ayi
            A[i, 2] += azi


@jit(error_model="numpy", inline="always")
def _add_scaled(X, Y, m, h):
    """X += h Y over the m rows (a drift with Y = velocities, a kick with Y = accelerations)."""
    for i in range(m):
        X[i, 0] += h * Y[i, 0]
        X[i, 1] += h * Y[i, 1]
        X[i, 2] += h * Y[i, 2]


@jit(error_model="numpy", inline="always")
def _steps(P, V, A, gm, m, eps2, h, count, drifts, kicks, fresh):
    """``count`` steps of the scheme; returns whether A holds the forces of the final P."""
    for _ in range(count):
        for s in range(drifts.shape[0]):
            if drifts[s] != 0.0:
                _add_scaled(P, V, m, drifts[s] * h)
                fresh = False
            if kicks[s] != 0.0:
                if not fresh:
                    _gravity(P, gm, m, eps2, A)
                    fresh = True
                _add_scaled(V, A, m, kicks[s] * h)
    return fresh


@jit(error_model="numpy", inline="always")
def _first_nonfinite_row(P, V, m):
    for i in range(m):
        for k in range(3):
            if not (math.isfinite(P[i, k]) and math.isfinite(V[i, k])):
                return i
    return -1


@jit(error_model="numpy", inline="always")
def _finite(P, V, m):
    s = 0.0
    for i in range(m):
        for k in range(3):
            s += P[i, k] * 0.0 + V[i, k] * 0.0
    return s == 0.0


@jit(error_model="numpy", inline="always")
def _copy(src_a, src_b, src_c, dst_a, dst_b, dst_c, m):
    for i in range(m):
        for k in range(3):
            dst_a[i, k] = src_a[i, k]
            dst_b[i, k] = src_b[i, k]
            dst_c[i, k] = src_c[i, k]


@jit(error_model="numpy")
def advance(t, h, steps, pos, vel, mass, active, n, G, eps2, drifts, kicks):
    """``splitting.advance`` for the case ``applies`` accepts; same returns."""
    dim = pos.shape[0]
    index = np.empty(n, dtype=np.int64)
    m = 0
    for i in range(n):
        if active[i]:
            index[m] = i
            m += 1
    P = np.zeros((m, 3))
    V = np.zeros((m, 3))
    A = np.zeros((m, 3))
    gm = np.empty(m)
    for c in range(m):
        gm[c] = G * mass[index[c]]
        for k in range(dim):
            P[c, k] = pos[k, index[c]]
            V[c, k] = vel[k, index[c]]
    saved_P = np.empty((m, 3))
    saved_V = np.empty((m, 3))
    saved_A = np.empty((m, 3))
    fresh = False
    done = 0
    status = OK
    careful = False  # after a failed block: re-run it one step at a time
    while done < steps:
        count = 1 if careful else min(BLOCK, steps - done)
        _copy(P, V, A, saved_P, saved_V, saved_A, m)
        saved_fresh = fresh
        fresh = _steps(P, V, A, gm, m, eps2, h, count, drifts, kicks, fresh)
        if _finite(P, V, m):
            done += count
            continue
        row = _first_nonfinite_row(P, V, m)
        _copy(saved_P, saved_V, saved_A, P, V, A, m)
        fresh = saved_fresh
        if careful:
            status = index[row]
            break
        careful = True
    for c in range(m):
        for k in range(dim):
            pos[k, index[c]] = P[c, k]
            vel[k, index[c]] = V[c, k]
    return (t if done == 0 else t + done * h), h, done, status
