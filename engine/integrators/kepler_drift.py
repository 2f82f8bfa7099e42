"""The Kepler drift of the Wisdom-Holman methods: one body's Kepler orbit over one step, fast.

A Wisdom-Holman step solves a Kepler problem per body per step, so its solver sets the
method's cost. ``engine.analytic.kepler_step`` is built for any time span and every conic
(double-double intermediates, a periapsis route far out on open orbits); a drift spans a
fraction of an orbit from the previous drift's end, which a lighter solver handles to round-off:

- Universal variables with beta = 2 mu / r0 - v0^2 and Stumpff's G-functions
  G_k(X) = X^k c_k(beta X^2) (Danby 1988, Fundamentals of Celestial Mechanics, sec. 6.9;
  Stumpff 1959). Kepler's equation in X is

      F(X) = r0 G1 + eta0 G2 + mu G3 - dt = 0,   F' = r = r0 G0 + eta0 G1 + mu G2,
      F'' = eta0 G0 + zeta0 G1,   eta0 = r0 . v0,  zeta0 = mu - beta r0,

  solved by Halley's iteration from X = dt / r0 (a short arc) or X = dt beta / mu (the mean of
  dX/dt = 1/r over an orbit, for arcs longer than a twentieth of it); elliptic arcs longer
  than a period lose their whole periods first (P = 2 pi mu / beta^(3/2)).
- The Stumpff functions by their series at |z| <= 0.1, reached by quartering z, and then the
  quadruple-argument identities c0(4z) = 2 c0^2 - 1, c1(4z) = c0 c1, c2(4z) = c1^2 / 2,
  c3(4z) = (c2 + c0 c3) / 4 (no trigonometric call; the reduction Rein & Tamayo 2015 use).
- The state from the Lagrange coefficients f = 1 - mu G2 / r0, g = r0 G1 + eta0 G2,
  fdot = -mu G1 / (r0 r), gdot = 1 - mu G2 / r (g in the form that does not cancel).

If the iteration has not met round-off after ``MAX_ITERATIONS``, the drift is taken by
``engine.analytic.kepler_step`` instead, so the fast path never returns a worse answer.
"""
import math

import numpy as np
from numba import njit

from ..analytic import kepler_step

MAX_ITERATIONS = 12
_TWO_PI = 2.0 * math.pi
#: (dt / P)^2 (2 pi)^2 above which an elliptic arc counts as long: dt > P / 20
_LONG_ARC = (_TWO_PI * 0.05) ** 2
_R6, _R12, _R20, _R30, _R42, _R56 = 1 / 6, 1 / 12, 1 / 20, 1 / 30, 1 / 42, 1 / 56
_R72, _R90, _R110, _R132, _R156, _R182, _R210 = (1 / 72, 1 / 90, 1 / 110, 1 / 132, 1 / 156,
                                                  1 / 182, 1 / 210)


@njit(cache=True, error_model="numpy", inline="always")
def stumpff(z):
    """c0(z), c1(z), c2(z), c3(z) by the series at small |z| and quadruple-argument steps."""
    quarterings = 0
    while abs(z) > 0.1:
        z *= 0.25
        quarterings += 1
    # the series' ratios as products by reciprocals: no division in the hot path
    c3 = (1.0 - z * _R20 * (1.0 - z * _R42 * (1.0 - z * _R72 * (1.0 - z * _R110 * (
        1.0 - z * _R156 * (1.0 - z * _R210)))))) * _R6
    c2 = (1.0 - z * _R12 * (1.0 - z * _R30 * (1.0 - z * _R56 * (1.0 - z * _R90 * (
        1.0 - z * _R132 * (1.0 - z * _R182)))))) * 0.5
    c1 = 1.0 - z * c3
    c0 = 1.0 - z * c2
    for _ in range(quarterings):
        c3 = 0.25 * (c2 + c0 * c3)
        c2 = 0.5 * c1 * c1
        c1 = c1 * c0
        c0 = 2.0 * c0 * c0 - 1.0
    return c0, c1, c2, c3


@njit(cache=True, error_model="numpy", inline="always")
def drift_column(jp, jv, j, mu, dt, r, v):
    """Column ``j`` of positions ``jp`` and velocities ``jv`` (dim, count) moved along its
    Kepler orbit about mu for time dt, in place. ``r``, ``v`` are dim-long scratch for the
    fallback."""
    dim = jp.shape[0]
    x = jp[0, j]
    y = jp[1, j]
    z = jp[2, j] if dim == 3 else 0.0
    vx = jv[0, j]
    vy = jv[1, j]
    vz = jv[2, j] if dim == 3 else 0.0
    r0 = math.sqrt(x * x + y * y + z * z)
    v2 = vx * vx + vy * vy + vz * vz
    eta0 = x * vx + y * vy + z * vz
    beta = 2.0 * mu / r0 - v2
    zeta0 = mu - beta * r0
    if beta > 0.0 and dt * dt * beta * beta * beta > _LONG_ARC * mu * mu:
        # an elliptic arc of more than a twentieth of the period: its whole periods dropped,
        # then the mean of dX/dt = 1/r over an orbit
        period = _TWO_PI * mu / (beta * math.sqrt(beta))
        if abs(dt) > period:
            dt = np.fmod(dt, period)  # exact
        X = dt * beta / mu
    else:
        # X = integral of dt / r, from the Taylor series of 1/r to third order in dt
        # (r' = eta0 / r0, r'' = (v0^2 - r'^2) / r0 - mu / r0^2): on a short arc one Halley
        # correction then reaches round-off; on a long open one, the first-order term alone
        inv = 1.0 / r0
        rd = eta0 * inv
        rdd = (v2 - rd * rd) * inv - mu * inv * inv
        if dt * dt * (v2 + mu * inv) * inv * inv < 0.25:
            X = dt * inv * (1.0 + dt * inv * (-0.5 * rd + dt * (2.0 * rd * rd * inv - rdd) * _R6))
        else:
            X = dt * inv
    converged = False
    G0 = G1 = G2 = G3 = rn = 0.0
    for _ in range(MAX_ITERATIONS):
        c0, c1, c2, c3 = stumpff(beta * X * X)
        G1 = X * c1
        G2 = X * X * c2
        G3 = X * X * X * c3
        G0 = c0
        rn = r0 * G0 + eta0 * G1 + mu * G2
        F = r0 * G1 + eta0 * G2 + mu * G3 - dt
        F2 = eta0 * G0 + zeta0 * G1
        step = F / (rn - 0.5 * F * F2 / rn)
        X -= step
        if abs(step) <= 2e-16 * abs(X) or F == 0.0:
            # the G's of the X before this last correction of a few ulps are used as they
            # are: their change would be below their own rounding
            converged = True
            break
        if abs(step) <= 1e-7 * abs(X):
            # Halley's iteration is cubic: this correction leaves X exact to round-off. The
            # G's move with it by their Taylor series to second order in the step
            # (dG0/dX = -beta G1, dG1/dX = G0, dG2/dX = G1); the third-order terms are below
            # 1e-21 of the G's, so no second evaluation of the Stumpff functions is needed
            half = 0.5 * step * step
            G0, G1, G2 = (G0 + step * beta * G1 - half * beta * G0,
                          G1 - step * G0 - half * beta * G1,
                          G2 - step * G1 + half * G0)
            rn = r0 * G0 + eta0 * G1 + mu * G2
            converged = True
            break
    if not converged or not (rn > 0.0) or not math.isfinite(X):
        for k in range(dim):
            r[k] = jp[k, j]
            v[k] = jv[k, j]
        kepler_step(r, v, mu, dt, r, v)
        for k in range(dim):
            jp[k, j] = r[k]
            jv[k, j] = v[k]
        return
    f = 1.0 - mu * G2 / r0
    g = r0 * G1 + eta0 * G2
    fd = -mu * G1 / (r0 * rn)
    gd = 1.0 - mu * G2 / rn
    jp[0, j] = f * x + g * vx
    jp[1, j] = f * y + g * vy
    jv[0, j] = fd * x + gd * vx
    jv[1, j] = fd * y + gd * vy
    if dim == 3:
        jp[2, j] = f * z + g * vz
        jv[2, j] = fd * z + gd * vz
