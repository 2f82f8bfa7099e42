"""Pieces every integrator shares: drift, kick, save/restore and the finiteness check.

Every integrator module exposes ``advance(t, h, steps, state, model, work, vdep, t_end)``
(the named tuples of ``engine.state``)
returning ``(t, h_next, done, status)``: the new time, the step to use next (``h`` for fixed-step
methods), the number of steps completed, and ``status`` = -1 on success, the index of the first
non-finite particle when a step blew up (the state is then the last finite one and ``done`` is
the index of the failing step), or -2 when an adaptive step size collapsed, or -3 when an adaptive step would make the
time non-finite (the state is then the last accepted one). ``t_end`` is only
used by adaptive methods (they shorten their last step to land on it; NaN means no target).
"""
import math

import numpy as np
from ..cache import jit

from ..space import period_shift, wrap_scalar

OK = -1
STEP_COLLAPSED = -2
#: an adaptive step would take the time past the largest float (the state is kept)
TIME_OVERFLOW = -3


@jit(error_model="numpy", inline="always")
def drift(pos, vel, mask, n, h, box):
    """p <- p + h v, v masked to 0 for inactive and pinned particles (so they stay exactly
    put); the moving ones are then wrapped onto the periodic space of side ``box`` (none when
    box is 0)."""
    if box > 0.0:
        # wrapped without a branch: a parked particle's shift is multiplied by its mask of 0
        # (and a moving one's by 1.0, exactly space.wrap), so the loop stays vectorised
        for k in range(pos.shape[0]):
            for i in range(n):
                moved = pos[k, i] + (h * mask[i]) * vel[k, i]
                pos[k, i] = moved - period_shift(moved, box, 0.5) * mask[i]
        return
    for k in range(pos.shape[0]):
        for i in range(n):
            pos[k, i] += (h * mask[i]) * vel[k, i]


@jit(error_model="numpy", inline="always")
def wrap_positions(pos, mask, n, box):
    """Every moving particle's position onto the periodic space (a Runge-Kutta step's end)."""
    if box > 0.0:
        for k in range(pos.shape[0]):
            for i in range(n):
                if mask[i] != 0.0:
                    pos[k, i] = wrap_scalar(pos[k, i], box)


@jit(error_model="numpy", inline="always")
def kick(vel, acc, mask, n, h):
    """v <- v + h a, masked to 0 for pinned (and inactive) particles, so a pinned particle's
    velocity stays zero whatever acts on it (h * 1.0 is h: the others' kicks are exact)."""
    for k in range(vel.shape[0]):
        for i in range(n):
            vel[k, i] += (h * mask[i]) * acc[k, i]


@jit(error_model="numpy", inline="always")
def hold_pinned(acc, pinned, n):
    """Zero the accelerations of pinned particles (Runge-Kutta stages: a pinned particle's
    stage velocity must stay zero, so that its stage positions do not move)."""
    for i in range(n):
        if pinned[i]:
            for k in range(acc.shape[0]):
                acc[k, i] = 0.0


@jit(error_model="numpy", inline="always")
def copy_columns(src, dst, n):
    """dst[:, :n] = src[:, :n], as a loop: numba compiles a slice assignment with the error
    message of a shape mismatch, whose string formatting cost seconds of compiling in every
    integrator that had one."""
    for k in range(src.shape[0]):
        for i in range(n):
            dst[k, i] = src[k, i]


@jit(error_model="numpy", inline="always")
def copy_state(src_pos, src_vel, dst_pos, dst_vel, n):
    for k in range(src_pos.shape[0]):
        for i in range(n):
            dst_pos[k, i] = src_pos[k, i]
            dst_vel[k, i] = src_vel[k, i]


@jit(error_model="numpy", inline="always")
def active_mask(active, pinned, n):
    """1.0 for the particles that move (active and not pinned), else 0.0."""
    mask = np.empty(n)
    fill_active_mask(mask, active, pinned, n)
    return mask


@jit(error_model="numpy", inline="always")
def fill_active_mask(mask, active, pinned, n):
    """``active_mask`` into a caller's array."""
    for i in range(n):
        mask[i] = 1.0 if active[i] and not pinned[i] else 0.0


@jit(error_model="numpy", inline="always")
def all_finite(pos, vel, n):
    """True if every position and velocity is finite: x * 0 is 0 for finite x and NaN for
    inf or NaN, and a sum of zeros never overflows, so one cheap vectorisable pass decides."""
    s = 0.0
    for k in range(pos.shape[0]):
        for i in range(n):
            s += pos[k, i] * 0.0 + vel[k, i] * 0.0
    return s == 0.0


@jit(error_model="numpy")
def first_nonfinite(pos, vel, active, n):
    """Index of the first active particle with a non-finite position or velocity, else -1."""
    for i in range(n):
        if not active[i]:
            continue
        for k in range(pos.shape[0]):
            if not (math.isfinite(pos[k, i]) and math.isfinite(vel[k, i])):
                return i
    return -1


@jit(error_model="numpy")
def first_nonfinite_array(a, active, n):
    for i in range(n):
        if not active[i]:
            continue
        for k in range(a.shape[0]):
            if not math.isfinite(a[k, i]):
                return i
    return -1
