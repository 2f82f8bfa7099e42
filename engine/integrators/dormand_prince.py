"""Adaptive Dormand-Prince 5(4) Runge-Kutta with error control (``rk45``).

Seven stages, first-same-as-last, fifth-order solution, embedded fourth-order error estimate
(Dormand & Prince, J. Comput. Appl. Math. 6 (1980) 19; tableau as in Hairer, Norsett & Wanner,
Solving ODEs I, table II.5.2). The error of a step is

    err = max_i |y5_i - y4_i| / (tol (1 + max(|y_i|, |y_new_i|)))

over every position and velocity component of the active particles (``tol`` is both the
relative and the absolute tolerance). A step with err > 1, or with a non-finite stage, is
rejected and retried with h * max(0.2, 0.9 err^(-1/5)); an accepted one proposes
h * min(5, max(0.2, 0.9 err^(-1/5))) for the next (no growth right after a rejection).
"""
import math

import numpy as np
from ..cache import jit

from ..forces.dispatch import accelerations
from ..state import with_motion
from .common import (OK, STEP_COLLAPSED, TIME_OVERFLOW, active_mask, copy_columns, copy_state,
                     first_nonfinite, first_nonfinite_array, hold_pinned, wrap_positions)

NAME = "rk45"
ORDER = 5

_C = np.array([0.0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1.0, 1.0])
_A = np.array([
    [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [1 / 5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3 / 40, 9 / 40, 0.0, 0.0, 0.0, 0.0, 0.0],
    [44 / 45, -56 / 15, 32 / 9, 0.0, 0.0, 0.0, 0.0],
    [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729, 0.0, 0.0, 0.0],
    [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656, 0.0, 0.0],
    [35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84, 0.0],
])
# fifth-order weights minus fourth-order weights
_E = np.array([71 / 57600, 0.0, -71 / 16695, 71 / 1920, -17253 / 339200, 22 / 525, -1 / 40])

_SAFETY = 0.9
_MIN_FACTOR = 0.2
_MAX_FACTOR = 5.0


@jit(error_model="numpy", inline="always")
def _stage_state(pos, vel, kx, kv, s, h, n, out_pos, out_vel):
    """y + h sum_{j<s} a_sj k_j."""
    for k in range(pos.shape[0]):
        for i in range(n):
            x = pos[k, i]
            v = vel[k, i]
            for j in range(s):
                a = _A[s, j]
                if a != 0.0:
                    x += h * a * kx[j, k, i]
                    v += h * a * kv[j, k, i]
            out_pos[k, i] = x
            out_vel[k, i] = v


@jit(error_model="numpy", inline="always")
def _error(pos, vel, new_pos, new_vel, kx, kv, h, tol, active, n):
    err = 0.0
    for k in range(pos.shape[0]):
        for i in range(n):
            if not active[i]:
                continue
            ex = 0.0
            ev = 0.0
            for j in range(7):
                ex += _E[j] * kx[j, k, i]
                ev += _E[j] * kv[j, k, i]
            sx = tol * (1.0 + max(abs(pos[k, i]), abs(new_pos[k, i])))
            sv = tol * (1.0 + max(abs(vel[k, i]), abs(new_vel[k, i])))
            err = max(err, abs(h * ex) / sx, abs(h * ev) / sv)
    return err


@jit(error_model="numpy")
def advance(t, h, steps, state, model, work, vdep, t_end, tol):
    """``advance_counted`` without the count."""
    return advance_counted(t, h, steps, state, model, work, vdep, t_end, tol,
                           np.zeros(1, dtype=np.int64))


@jit(error_model="numpy")
def advance_counted(t, h, steps, state, model, work, vdep, t_end, tol, counts):
    """``steps`` accepted steps (see the module); ``counts[0]`` gains the force evaluations
    made, rejected attempts included (1 at the start, 6 per attempt)."""
    pos = state.pos
    vel = state.vel
    active = state.active
    n = state.n
    dim = pos.shape[0]
    mask = active_mask(active, state.pinned, n)
    kx = np.empty((7, dim, n))
    kv = np.empty((7, dim, n))
    sx = np.empty((dim, n))
    sv = np.empty((dim, n))
    stage = with_motion(state, sx, sv)
    has_end = not math.isnan(t_end)
    copy_columns(vel, kx[0], n)
    accelerations(t, state, model, kv[0], work)
    counts[0] += 1
    hold_pinned(kv[0], state.pinned, n)
    done = 0
    rejected = False
    while done < steps:
        h_try = h
        last = False
        if has_end:
            remaining = t_end - t
            if remaining == 0.0:
                break
            if abs(h) >= abs(remaining):
                h_try = remaining
                last = True
        if not math.isfinite(t + h_try):
            return t, h, done, TIME_OVERFLOW
        counts[0] += 6
        for s in range(1, 7):
            _stage_state(pos, vel, kx, kv, s, h_try, n, sx, sv)
            copy_columns(sv, kx[s], n)
            accelerations(t + _C[s] * h_try, stage, model, kv[s], work)
            hold_pinned(kv[s], state.pinned, n)
        # stage 7 state is the fifth-order solution (sx, sv)
        status = first_nonfinite(sx, sv, active, n)
        if status < 0:
            status = first_nonfinite_array(kv[6], active, n)
        err = math.inf if status >= 0 else _error(pos, vel, sx, sv, kx, kv, h_try, tol, active, n)
        if err > 1.0:
            factor = _MIN_FACTOR if math.isinf(err) else max(_MIN_FACTOR, _SAFETY * err ** -0.2)
            h = h_try * factor
            rejected = True
            if abs(h) <= 1e-14 * max(1.0, abs(t)):
                if status < 0:
                    status = first_nonfinite_array(kv[0], active, n)
                return t, h, done, status if status >= 0 else STEP_COLLAPSED
            continue
        for k in range(dim):  # the moving particles take the step; the others stay as they are
            for i in range(n):
                if mask[i] != 0.0:
                    pos[k, i] = sx[k, i]
                    vel[k, i] = sv[k, i]
        wrap_positions(pos, mask, n, state.box)
        t = t_end if last else t + h_try
        copy_state(kx[6], kv[6], kx[0], kv[0], n)
        factor = _MAX_FACTOR if err == 0.0 else min(_MAX_FACTOR, max(_MIN_FACTOR, _SAFETY * err ** -0.2))
        if rejected:
            factor = min(factor, 1.0)
        rejected = False
        if not last or abs(h_try * factor) < abs(h):
            h = h_try * factor
        done += 1
        if last:
            break
    return t, h, done, OK
