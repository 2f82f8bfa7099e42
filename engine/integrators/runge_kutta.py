"""The classic fourth-order Runge-Kutta method on (p, v)' = (v, a(p, v, t)).

    k1 = F(t, y), k2 = F(t + h/2, y + h/2 k1), k3 = F(t + h/2, y + h/2 k2), k4 = F(t + h, y + h k3)
    y_{n+1} = y_n + h (k1 + 2 k2 + 2 k3 + k4) / 6        (Kutta 1901; Hairer, Norsett & Wanner I, II.1)

Four evaluations per step, fourth order, not symplectic: energy drifts slowly, linearly in time.
"""
import numpy as np
from ..cache import jit

from ..forces.dispatch import accelerations
from ..state import with_motion
from .common import (OK, active_mask, all_finite, copy_state, first_nonfinite, hold_pinned,
                     wrap_positions)

NAME = "rk4"
ORDER = 4
FORCE_EVALUATIONS = 4


@jit(error_model="numpy", inline="always")
def _stage(pos, vel, dx, dv, c, n, out_pos, out_vel):
    """out = y + c * (dx, dv)."""
    for k in range(pos.shape[0]):
        for i in range(n):
            out_pos[k, i] = pos[k, i] + c * dx[k, i]
            out_vel[k, i] = vel[k, i] + c * dv[k, i]


@jit(error_model="numpy")
def advance(t, h, steps, state, model, work, vdep, t_end):
    pos = state.pos
    vel = state.vel
    n = state.n
    dim = pos.shape[0]
    mask = active_mask(state.active, state.pinned, n)
    a1 = np.empty((dim, n))
    a2 = np.empty((dim, n))
    a3 = np.empty((dim, n))
    a4 = np.empty((dim, n))
    x2 = np.empty((dim, n))
    v2 = np.empty((dim, n))
    x3 = np.empty((dim, n))
    v3 = np.empty((dim, n))
    x4 = np.empty((dim, n))
    v4 = np.empty((dim, n))
    # the stage states, made once: the loop only writes into their arrays
    s2 = with_motion(state, x2, v2)
    s3 = with_motion(state, x3, v3)
    s4 = with_motion(state, x4, v4)
    t0 = t
    for step in range(steps):
        accelerations(t, state, model, a1, work)
        hold_pinned(a1, state.pinned, n)
        _stage(pos, vel, vel, a1, 0.5 * h, n, x2, v2)
        accelerations(t + 0.5 * h, s2, model, a2, work)
        hold_pinned(a2, state.pinned, n)
        _stage(pos, vel, v2, a2, 0.5 * h, n, x3, v3)
        accelerations(t + 0.5 * h, s3, model, a3, work)
        hold_pinned(a3, state.pinned, n)
        _stage(pos, vel, v3, a3, h, n, x4, v4)
        accelerations(t + h, s4, model, a4, work)
        hold_pinned(a4, state.pinned, n)
        # write the update into x2/v2 first so a blow-up leaves pos/vel untouched
        for k in range(dim):
            for i in range(n):
                if mask[i] != 0.0:
                    x2[k, i] = pos[k, i] + h / 6.0 * (vel[k, i] + 2.0 * v2[k, i] + 2.0 * v3[k, i] + v4[k, i])
                    v2[k, i] = vel[k, i] + h / 6.0 * (a1[k, i] + 2.0 * a2[k, i] + 2.0 * a3[k, i] + a4[k, i])
                else:
                    x2[k, i] = pos[k, i]
                    v2[k, i] = vel[k, i]
        if not all_finite(x2, v2, n):
            status = first_nonfinite(x2, v2, state.active, n)
            if status >= 0:
                return t, h, step, status
        wrap_positions(x2, mask, n, state.box)
        copy_state(x2, v2, pos, vel, n)
        t = t0 + (step + 1) * h
    return t, h, steps, OK
