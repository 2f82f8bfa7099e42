"""The classic fourth-order Runge-Kutta method on (p, v)' = (v, a(p, v, t)).

    k1 = F(t, y), k2 = F(t + h/2, y + h/2 k1), k3 = F(t + h/2, y + h/2 k2), k4 = F(t + h, y + h k3)
    y_{n+1} = y_n + h (k1 + 2 k2 + 2 k3 + k4) / 6        (Kutta 1901; Hairer, Norsett & Wanner I, II.1)

Four evaluations per step, fourth order, not symplectic: energy drifts slowly, linearly in time.
"""
import numpy as np
from numba import njit

from ..forces.dispatch import accelerations
from .common import OK, all_finite, first_nonfinite

NAME = "rk4"
ORDER = 4
FORCE_EVALUATIONS = 4


@njit(cache=True, error_model="numpy", inline="always")
def _stage(pos, vel, dx, dv, c, n, out_pos, out_vel):
    """out = y + c * (dx, dv)."""
    for k in range(pos.shape[0]):
        for i in range(n):
            out_pos[k, i] = pos[k, i] + c * dx[k, i]
            out_vel[k, i] = vel[k, i] + c * dv[k, i]


@njit(cache=True, error_model="numpy")
def advance(t, h, steps, pos, vel, mass, charge, radius, active, test, n, kinds, fp, foff, ip,
            ioff, work, iwork, vdep, t_end):
    dim = pos.shape[0]
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
    t0 = t
    for step in range(steps):
        accelerations(t, pos, vel, mass, charge, radius, active, test, n, kinds, fp, foff, ip, ioff,
                          a1, work, iwork)
        _stage(pos, vel, vel, a1, 0.5 * h, n, x2, v2)
        accelerations(t + 0.5 * h, x2, v2, mass, charge, radius, active, test, n, kinds, fp, foff, ip, ioff,
                          a2, work, iwork)
        _stage(pos, vel, v2, a2, 0.5 * h, n, x3, v3)
        accelerations(t + 0.5 * h, x3, v3, mass, charge, radius, active, test, n, kinds, fp, foff, ip, ioff,
                          a3, work, iwork)
        _stage(pos, vel, v3, a3, h, n, x4, v4)
        accelerations(t + h, x4, v4, mass, charge, radius, active, test, n, kinds, fp, foff, ip, ioff,
                          a4, work, iwork)
        # write the update into x2/v2 first so a blow-up leaves pos/vel untouched
        for k in range(dim):
            for i in range(n):
                if active[i]:
                    x2[k, i] = pos[k, i] + h / 6.0 * (vel[k, i] + 2.0 * v2[k, i] + 2.0 * v3[k, i] + v4[k, i])
                    v2[k, i] = vel[k, i] + h / 6.0 * (a1[k, i] + 2.0 * a2[k, i] + 2.0 * a3[k, i] + a4[k, i])
                else:
                    x2[k, i] = pos[k, i]
                    v2[k, i] = vel[k, i]
        if not all_finite(x2, v2, n):
            bad = first_nonfinite(x2, v2, active, n)
            if bad >= 0:
                return t, h, step, bad
        pos[:, :n] = x2
        vel[:, :n] = v2
        t = t0 + (step + 1) * h
    return t, h, steps, OK
