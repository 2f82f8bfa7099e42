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
- The Stumpff functions by their series at |z| <= 0.1 (four terms below |z| = 2e-3, six
  above), reached by quartering z, and then the
  quadruple-argument identities c0(4z) = 2 c0^2 - 1, c1(4z) = c0 c1, c2(4z) = c1^2 / 2,
  c3(4z) = (c2 + c0 c3) / 4 (no trigonometric call; the reduction Rein & Tamayo 2015 use).
- The state from the Lagrange coefficients f = 1 - mu G2 / r0, g = r0 G1 + eta0 G2,
  fdot = -mu G1 / (r0 r), gdot = 1 - mu G2 / r (g in the form that does not cancel).

If the iteration has not met round-off after ``MAX_ITERATIONS``, the drift is taken by
``engine.analytic.kepler_step`` instead, so the fast path never returns a worse answer.

``drift_columns`` moves all of a step's bodies at once, their iterations in lockstep (see
there).
"""
import functools
import math

import numpy as np
from numba import types
from numba.extending import intrinsic

from ..address_calls import F8_1D, F8_2D, call_at, check_call, entry_address
from ..cache import jit

from ..analytic import kepler_step

MAX_ITERATIONS = 12
_TWO_PI = 2.0 * math.pi
#: (dt / P)^2 (2 pi)^2 above which an elliptic arc counts as long: dt > P / 20
_LONG_ARC = (_TWO_PI * 0.05) ** 2
_R6, _R12, _R20, _R30, _R42, _R56 = 1 / 6, 1 / 12, 1 / 20, 1 / 30, 1 / 42, 1 / 56
#: |z| below which four terms of the series suffice: the first left out, z^4 / 10! of c2 and
#: 6 z^4 / 11! of c3, is below 1e-17 of them
_SHORT_SERIES = 2e-3
_R72, _R90, _R110, _R132, _R156, _R182, _R210 = (1 / 72, 1 / 90, 1 / 110, 1 / 132, 1 / 156,
                                                  1 / 182, 1 / 210)


@jit(error_model="numpy", inline="always")
def stumpff(z):
    """c0(z), c1(z), c2(z), c3(z) by the series at small |z| and quadruple-argument steps;
    below |z| = 2e-3 (a planet's step of under a thirtieth of its orbit) four terms of each
    series, which took the outer solar system's step from 281 to 270 ns."""
    if abs(z) < _SHORT_SERIES:
        # a short arc (each drift of a planet's step): four terms of each series leave out
        # less than 1e-17 of c2 and c3
        c3 = (1.0 - z * _R20 * (1.0 - z * _R42 * (1.0 - z * _R72))) * _R6
        c2 = (1.0 - z * _R12 * (1.0 - z * _R30 * (1.0 - z * _R56))) * 0.5
        return 1.0 - z * c2, 1.0 - z * c3, c2, c3
    quarterings = 0
    # an infinite z (an orbit blown up to overflow) would be quartered for ever: it leaves the
    # loop as it is, and the solver's checks then find the state not finite
    while 0.1 < abs(z) < math.inf:
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


@jit(error_model="numpy", inline="always")
def _column(jp, jv, j):
    """Column j's position and velocity as six scalars (z = vz = 0 in two dimensions), and
    r0 = |r|, v^2 and eta0 = r . v."""
    dim = jp.shape[0]
    x = jp[0, j]
    y = jp[1, j]
    z = jp[2, j] if dim == 3 else 0.0
    vx = jv[0, j]
    vy = jv[1, j]
    vz = jv[2, j] if dim == 3 else 0.0
    r0 = math.sqrt(x * x + y * y + z * z)
    return x, y, z, vx, vy, vz, r0, vx * vx + vy * vy + vz * vz, x * vx + y * vy + z * vz


@jit(error_model="numpy", inline="always")
def _third_order_start(dt, inv, eta0, v2, mu):
    """X = integral of dt / r, from the Taylor series of 1/r to third order in dt (r' = eta0 /
    r0, r'' = (v0^2 - r'^2) / r0 - mu / r0^2; ``inv`` = 1 / r0)."""
    rd = eta0 * inv
    rdd = (v2 - rd * rd) * inv - mu * inv * inv
    return dt * inv * (1.0 + dt * inv * (-0.5 * rd + dt * (2.0 * rd * rd * inv - rdd) * _R6))


@jit(error_model="numpy", inline="always")
def _start_of_x(dt, r0, eta0, v2, beta, mu):
    """``(X, dt)``: where Halley's iteration for X starts, and the time it solves for."""
    if beta > 0.0 and dt * dt * beta * beta * beta > _LONG_ARC * mu * mu:
        # an elliptic arc of more than a twentieth of the period: its whole periods dropped,
        # then the mean of dX/dt = 1/r over an orbit
        period = _TWO_PI * mu / (beta * math.sqrt(beta))
        if abs(dt) > period:
            dt = np.fmod(dt, period)  # exact
        return dt * beta / mu, dt
    # on a short arc one Halley correction from the third-order start reaches round-off; on
    # a long open one, the first-order term alone
    inv = 1.0 / r0
    if dt * dt * (v2 + mu * inv) * inv * inv < 0.25:
        return _third_order_start(dt, inv, eta0, v2, mu), dt
    return dt * inv, dt


@jit(error_model="numpy", _nrt=False, fastmath=False)
def drift_column(jp, jv, j, mu, dt, r, v):
    """Column ``j`` of positions ``jp`` and velocities ``jv`` (dim, count) moved along its
    Kepler orbit about mu for time dt, in place. ``r``, ``v`` are dim-long scratch for the
    fallback. ``drift_columns``' fallback for a column its lockstep solve left: called, not
    inlined, so that this rare path stays out of the lockstep code."""
    dim = jp.shape[0]
    x, y, z, vx, vy, vz, r0, v2, eta0 = _column(jp, jv, j)
    beta = 2.0 * mu / r0 - v2
    zeta0 = mu - beta * r0
    X, dt = _start_of_x(dt, r0, eta0, v2, beta, mu)
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


# -- every column at once -------------------------------------------------------------------------
# One drift is a chain of dependent operations (a square root, a reciprocal, the start of X, two
# polynomials, Halley's correction, the Lagrange coefficients): about 100 ns of latency for a few
# dozen floating-point operations. The columns of a step are independent, so ``drift_columns``
# takes them in lockstep, one stage of the solve at a time over all columns (each Halley
# iteration over the columns still pending), so that the processor overlaps them: the cost per
# column comes near the operations' throughput, not their latency (the 5 drifts of an
# outer-solar-system step: 0.51-0.76 us one at a time, 0.30-0.41 us in lockstep, measured side
# by side). Each column starts and iterates as in ``drift_column``; multiply-adds are
# contracted (each rounds once, and the chains are shorter). A column whose iteration fails is
# left to ``drift_column`` and its reference-solver fallback.

#: rows of ``drift_columns``' scratch (``SCRATCH_ROWS`` by max(count, 3))
_RV_R, _RV_V, _R0, _ETA0, _MU, _BETA, _ZETA0, _X, _DT, _G1, _G2, _RN, _OK, _INV = range(14)
SCRATCH_ROWS = 14
#: rows of the scratch that hold each column's |r| and 1 / |r| (see ``drift_columns``' ``known``)
R0_ROW, INV_R0_ROW = _R0, _INV


@jit(error_model="numpy", inline="always")
def _start(jp, jv, j, mu, dt, kw, known):
    """Column j's invariants and the start of X into ``kw``, as ``drift_column`` starts
    (``_start_of_x``; whole periods of a long elliptic arc dropped from ``kw[_DT]``);
    ``known``: r0 and 1 / r0 are in ``kw[_R0]`` and ``kw[_INV]`` already."""
    if known:  # r0 left unused here, so its square root is not computed
        _, _, _, _, _, _, _, v2, eta0 = _column(jp, jv, j)
        r0 = kw[_R0, j]
        inv = kw[_INV, j]
    else:
        _, _, _, _, _, _, r0, v2, eta0 = _column(jp, jv, j)
        inv = 1.0 / r0
    beta = 2.0 * mu * inv - v2
    X, dt = _start_of_x(dt, r0, eta0, v2, beta, mu)
    kw[_R0, j] = r0
    kw[_INV, j] = inv
    kw[_ETA0, j] = eta0
    kw[_MU, j] = mu
    kw[_BETA, j] = beta
    kw[_ZETA0, j] = mu - beta * r0
    kw[_X, j] = X
    kw[_DT, j] = dt


@jit(error_model="numpy", inline="always")
def _halley_all(kw, first, count):
    """Halley's iteration for X of every pending column (``kw[_OK]`` 1), the columns in
    lockstep, as ``drift_column`` iterates: a column whose correction was at most 1e-7 of X
    (X then exact to round-off) gets its G's moved to the corrected X by their Taylor series
    and ``kw[_OK]`` 2 (0 if r is not positive there); columns still pending after
    ``MAX_ITERATIONS``, or whose X is not finite, get 0."""
    for _ in range(MAX_ITERATIONS):
        pending = 0
        for j in range(first, count):
            if kw[_OK, j] != 1.0:
                continue
            r0 = kw[_R0, j]
            eta0 = kw[_ETA0, j]
            mu = kw[_MU, j]
            beta = kw[_BETA, j]
            X = kw[_X, j]
            c0, c1, c2, c3 = stumpff(beta * X * X)
            G0 = c0
            G1 = X * c1
            G2 = X * X * c2
            G3 = X * X * X * c3
            rn = r0 * G0 + eta0 * G1 + mu * G2
            F = r0 * G1 + eta0 * G2 + mu * G3 - kw[_DT, j]
            F2 = eta0 * G0 + kw[_ZETA0, j] * G1
            step = F * rn / (rn * rn - 0.5 * F * F2)
            X -= step
            if abs(step) <= 1e-7 * abs(X) or F == 0.0:
                half = 0.5 * step * step
                G1n = G1 - step * G0 - half * beta * G1
                G2n = G2 - step * G1 + half * G0
                G0n = G0 + step * beta * G1 - half * beta * G0
                rn = r0 * G0n + eta0 * G1n + mu * G2n
                kw[_G1, j] = G1n
                kw[_G2, j] = G2n
                kw[_RN, j] = rn
                kw[_OK, j] = 2.0 if rn > 0.0 else 0.0
            elif math.isfinite(X):
                kw[_X, j] = X
                pending += 1
            else:
                kw[_OK, j] = 0.0
        if pending == 0:
            return
    for j in range(first, count):
        if kw[_OK, j] == 1.0:
            kw[_OK, j] = 0.0


@jit(error_model="numpy", inline="always")
def _apply_all(jp, jv, kw, first, count):
    """x' = f x + g v, v' = fd x + gd v for every column solved (``kw[_OK]`` 2), from the
    Lagrange coefficients f = 1 - mu G2 / r0, g = r0 G1 + eta0 G2, fd = -mu G1 / (r0 r),
    gd = 1 - mu G2 / r."""
    dim = jp.shape[0]
    for j in range(first, count):
        r0 = kw[_R0, j]
        mu = kw[_MU, j]
        G1 = kw[_G1, j]
        G2 = kw[_G2, j]
        rn = kw[_RN, j]
        ok = kw[_OK, j] == 2.0
        inv_r0 = kw[_INV, j]
        inv_rn = 1.0 / rn
        f = 1.0 - mu * G2 * inv_r0
        g = r0 * G1 + kw[_ETA0, j] * G2
        fd = -mu * G1 * inv_r0 * inv_rn
        gd = 1.0 - mu * G2 * inv_rn
        for k in range(dim):
            x = jp[k, j]
            v = jv[k, j]
            jp[k, j] = f * x + g * v if ok else x
            jv[k, j] = fd * x + gd * v if ok else v


def drift_columns(jp, jv, first, count, mu, dt, kw, known=False):
    """Columns ``first`` to ``count`` of ``jp``, ``jv`` (dim, count) moved along their Kepler
    orbits about ``mu[j]`` for time dt, in place (mu[j] = 0: a straight line): the same
    result as ``drift_column`` on each, to round-off, the columns solved in lockstep (see
    above). ``kw`` is scratch of ``SCRATCH_ROWS`` rows and at
    least max(count, 3) columns.

    ``known``: rows ``R0_ROW`` and ``INV_R0_ROW`` of ``kw`` already hold |r| and 1 / |r| of
    these very positions (the interaction that came just before computed them for its Kepler
    terms), so the drift takes them from there: a square root and a division less a column,
    on the chain every step waits for (outer solar system: 270 -> 258 ns a step).

    For Python callers (the tests): ``drift_columns_at``, which the integrators call, with the
    fallback's address, the very code the integrators run."""
    if known:
        drift_columns_at(jp, jv, first, count, mu, dt, kw, fallback_address(), True)
    else:  # omitted: the integrators' own compiled version
        drift_columns_at(jp, jv, first, count, mu, dt, kw, fallback_address())


# -- the fallback called through its address ------------------------------------------------------
# A compiled function carries the machine code of every compiled function it calls (numba links
# the callee into the caller, and optimises and translates the whole again for each caller up
# the chain): the fallback's ``engine.analytic.kepler_step`` is large, and was compiled again in
# each of the half-dozen Wisdom-Holman functions above a drift. Called through its address
# (``fallback_address``, made in Python and passed down as an int64), it is compiled once.


#: the types ``drift_column`` is compiled for when called through its address
FALLBACK_ARGUMENTS = (F8_2D, F8_2D, types.int64, types.float64, types.float64, F8_1D, F8_1D)


@functools.lru_cache(maxsize=None)
def fallback_address():
    """The address of the fallback (``drift_column``) for ``drift_columns_at``: compiled on the
    first call in a process, or loaded from the compiled-code cache."""
    return entry_address(drift_column, types.none(*FALLBACK_ARGUMENTS))


@intrinsic
def _call_drift_column(typingctx, address, jp, jv, j, mu, dt, r, v):
    """``drift_column(jp, jv, j, mu, dt, r, v)`` through its address."""
    given = (jp, jv, j, mu, dt, r, v)
    check_call(given, FALLBACK_ARGUMENTS, "the drift's fallback")

    def codegen(context, builder, signature, args):
        call_at(context, builder, args[0], types.none, FALLBACK_ARGUMENTS, given, args[1:])
        return context.get_dummy_value()
    return types.none(address, *given), codegen


@jit(error_model="numpy", _nrt=False, fastmath={"contract"}, no_cfunc_wrapper=True)
def drift_columns_at(jp, jv, first, count, mu, dt, kw, fallback, known=False):
    """``drift_columns`` with its fallback called through ``fallback`` (``fallback_address()``),
    so that the fallback's code is compiled once, not in every caller. The integrators
    compile it with ``known`` a constant, False or True (numba's ``Omitted`` argument): its
    test taken out of each column's start, 0.2-2% of a step (a lone orbit to three planets
    with SABA, measured in one process against ``known`` passed at run time)."""
    dim = jp.shape[0]
    kepler = 0
    for j in range(first, count):
        if mu[j] > 0.0:
            _start(jp, jv, j, mu[j], dt, kw, known)
            kw[_OK, j] = 1.0
            kepler += 1
        else:  # a straight line; the lockstep loops skip it (its rows are not read for it)
            kw[_OK, j] = 0.0
            for k in range(dim):
                jp[k, j] += dt * jv[k, j]
    if kepler > 0:
        _halley_all(kw, first, count)
        _apply_all(jp, jv, kw, first, count)
        for j in range(first, count):
            if mu[j] > 0.0 and kw[_OK, j] != 2.0:
                _call_drift_column(fallback, jp, jv, j, mu[j], dt, kw[_RV_R, :dim],
                                   kw[_RV_V, :dim])
