"""Forward (explicit) Euler, exactly the lecture's pseudo code.

    a_i = f(p_i, v_i) / m;   p_{i+1} = p_i + v_i dt;   v_{i+1} = v_i + a_i dt

First order, not symplectic: the energy of a bound orbit grows step after step.
"""
import numpy as np
from ..cache import jit

from ..forces.dispatch import accelerations
from ..space import wrap_scalar
from .common import OK, active_mask, all_finite, copy_state, first_nonfinite

NAME = "euler"
ORDER = 1
FORCE_EVALUATIONS = 1


@jit(error_model="numpy")
def advance(t, h, steps, state, model, work, vdep, t_end):
    pos = state.pos
    vel = state.vel
    n = state.n
    box = state.box
    mask = active_mask(state.active, state.pinned, n)
    active = state.active
    dim = pos.shape[0]
    acc = np.empty((dim, n))
    save_pos = np.empty((dim, n))
    save_vel = np.empty((dim, n))
    t0 = t
    for step in range(steps):
        copy_state(pos, vel, save_pos, save_vel, n)
        accelerations(t, state, model, acc, work)
        for k in range(dim):
            for i in range(n):
                if mask[i] != 0.0:
                    pos[k, i] = wrap_scalar(pos[k, i] + h * vel[k, i], box)
                    vel[k, i] += h * acc[k, i]
        if not all_finite(pos, vel, n):
            status = first_nonfinite(pos, vel, active, n)
            if status >= 0:
                copy_state(save_pos, save_vel, pos, vel, n)
                return t, h, step, status
        t = t0 + (step + 1) * h
    return t, h, steps, OK
