"""Closed-form solutions used as exact references and as cheap predictors.

Three systems have exact solutions that a game (or a bot predicting the
future) can evaluate at any time without stepping an integrator:

* :func:`ballistic` -- motion under a constant acceleration,
* :func:`kepler` -- two-body motion about a fixed centre, for every conic,
* :func:`harmonic_oscillator` -- the (optionally damped) linear oscillator,

plus :func:`orbital_elements`, a summary of the conic a state lies on.

Layout
------
Each public function validates its input with the engine's shared checks
(``engine._validate``: :class:`TypeError` for text, booleans, complex numbers or
None given as a number, :class:`ValueError` for non-finite or out-of-range
values and bad shapes, both naming the offending argument and its value) and
then calls a numba ``@njit`` core that works
on plain floats and float64 arrays.  The cores are exported so that other
compiled code -- a game's step function, a compiled bot -- can call them
directly.  They do *no* validation: feed them finite values, ``mu > 0`` and a
non-zero ``r0``, or expect non-finite results.  They are compiled with
``error_model="numpy"`` so that a degenerate case (a radial orbit evaluated
exactly at the collision) yields ``inf``/``nan`` instead of raising inside a
compiled game loop.

Compiled cores
--------------
``stumpff(z) -> (c0, c1, c2, c3)``
``universal_anomaly(r0n, sigma0, alpha, tau) -> chi``  (tau = sqrt(mu) t)
``lagrange_coefficients(r0, v0, mu, t) -> (f, g, fdot, gdot)``
``kepler_step(r0, v0, mu, t, r_out, v_out) -> None``  (in place; aliasing ok;
the most accurate route, used by all the others)
``kepler_propagate(r0, v0, mu, t) -> (r, v)``
``kepler_propagate_times(r0, v0, mu, times) -> (R, V)``  (shape (n, dim))
``orbit_invariants(r0, v0, mu) -> (a, e, energy, period, h, p, periapsis)``
``oscillator_transition(omega, zeta, t) -> (a, b, c, d)``
``ballistic_step(p0, v0, g, t, p_out, v_out) -> None``

References
----------
* R. R. Bate, D. D. Mueller, J. E. White, *Fundamentals of Astrodynamics*,
  Dover 1971, ch. 4 (universal variable, f and g functions).
* D. A. Vallado, *Fundamentals of Astrodynamics and Applications*, 4th ed.
  2013, sec. 2.3 and algorithm 8 (KEPLER, initial guesses for chi).
* R. H. Battin, *An Introduction to the Mathematics and Methods of
  Astrodynamics*, rev. ed., AIAA 1999, sec. 4.5 (universal functions U0..U3,
  the form of Kepler's equation used here).
* W. H. Press et al., *Numerical Recipes*, 3rd ed. 2007, sec. 9.4
  (Newton-Raphson safeguarded by bisection).
* Any ODE text for the damped oscillator, e.g. A. P. French,
  *Vibrations and Waves*, 1971, ch. 4.
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
from .cache import jit

from ._validate import finite_array, nonnegative_float, positive_float, vector

__all__ = [
    # public, validating API
    "ballistic",
    "kepler",
    "harmonic_oscillator",
    "orbital_elements",
    "OrbitalElements",
    # compiled cores
    "stumpff",
    "universal_anomaly",
    "lagrange_coefficients",
    "kepler_step",
    "kepler_propagate",
    "kepler_propagate_times",
    "orbit_invariants",
    "oscillator_transition",
    "ballistic_step",
]

_TWO_PI = 2.0 * math.pi

# Below this |z| the closed forms of c2, c3 lose digits to cancellation
# (x - sin x ~ x^3/6), so the Taylor series is used instead.  At |z| = 1 the
# closed form has lost fewer than 3 bits, and 12 series terms reach 1e-20.
_SERIES_Z = 1.0
_SERIES_TERMS = 12

# Relative step size at which Newton iteration on chi is considered converged.
# Newton converges quadratically, so a step this small leaves an error far
# below one ulp.
_CHI_RTOL = 1e-15
_MAX_ITER = 300
# A residual of Kepler's equation below this fraction of the sum of its terms'
# magnitudes is rounding noise.
_RESIDUAL_RTOL = 4.0 * 2.220446049250313e-16


# ---------------------------------------------------------------------------
# Compiled cores.  Compensated arithmetic for alpha = 2/r - v^2/mu first.
# ---------------------------------------------------------------------------
# Near-parabolic states have 2/r and v^2/mu nearly equal, so plain floating
# point leaves alpha (= 1/a) with a relative error of eps * (2/r) / |alpha| --
# 4e-12 at e = 0.99 near periapsis.  That error becomes a period error, and
# the phase drifts by it every orbit.  Computing alpha in double-double
# (error-free transformations: Knuth's TwoSum, Dekker's 1971 split and
# TwoProduct, summed as in Ogita, Rump & Oishi, "Accurate sum and dot
# product", SIAM J. Sci. Comput. 26, 2005) makes it correct
# to a few ulps of alpha itself, so the only loss left is the input's own
# rounding.  No FMA is needed, which keeps this portable under numba.


@jit(error_model="numpy", inline="always")
def _two_sum(a, b):
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


@jit(error_model="numpy", inline="always")
def _two_prod(a, b):
    p = a * b
    c = 134217729.0 * a  # 2^27 + 1: Dekker's splitter for doubles
    ah = c - (c - a)
    al = a - ah
    c = 134217729.0 * b
    bh = c - (c - b)
    bl = b - bh
    return p, ((ah * bh - p) + ah * bl + al * bh) + al * bl


@jit(error_model="numpy")
def _state_scalars(r0, v0, mu):
    """``(|r0|, |v0|^2, r0.v0, alpha)`` with alpha = 2/|r0| - |v0|^2/mu
    accurate to a few ulps (double-double intermediates)."""
    rh = 0.0
    rl = 0.0
    vh = 0.0
    vl = 0.0
    dh = 0.0
    dl = 0.0
    for i in range(r0.shape[0]):
        p, e = _two_prod(r0[i], r0[i])
        rh, t = _two_sum(rh, p)
        rl += t + e
        p, e = _two_prod(v0[i], v0[i])
        vh, t = _two_sum(vh, p)
        vl += t + e
        p, e = _two_prod(r0[i], v0[i])
        dh, t = _two_sum(dh, p)
        dl += t + e
    rh, rl = _two_sum(rh, rl)
    vh, vl = _two_sum(vh, vl)
    # |r| = sqrt(rh + rl) to double-double: one Newton correction.
    sh = math.sqrt(rh)
    p, e = _two_prod(sh, sh)
    sl = ((rh - p) - e + rl) / (2.0 * sh)
    # 2/|r| to double-double.
    qh = 2.0 / sh
    p, e = _two_prod(qh, sh)
    ql = (((2.0 - p) - e) - qh * sl) / sh
    # |v|^2/mu to double-double.
    wh = vh / mu
    p, e = _two_prod(wh, mu)
    wl = (((vh - p) - e) + vl) / mu
    a, err = _two_sum(qh, -wh)
    alpha = a + (err + (ql - wl))
    return sh, vh + vl, dh + dl, alpha


@jit(error_model="numpy")
def stumpff(z):
    """Stumpff functions c0(z), c1(z), c2(z), c3(z).

    ``c_k(z) = sum_j (-z)^j / (2j + k)!``; in closed form for ``z > 0``
    (``x = sqrt(z)``): ``c0 = cos x``, ``c1 = sin x / x``,
    ``c2 = (1 - cos x) / z``, ``c3 = (x - sin x) / x^3``, and the hyperbolic
    counterparts for ``z < 0`` (Bate, Mueller & White 1971, sec. 4.3;
    Vallado 2013, sec. 2.2).

    For ``|z| < 1`` the series is summed, because the closed forms of c2 and
    c3 cancel catastrophically near z = 0.  ``c2`` uses the half-angle form
    ``2 sin^2(x/2) / z``, which never cancels.  For very negative ``z`` the
    hyperbolic values overflow to ``inf``; callers treat that as "too far".
    """
    if abs(z) < _SERIES_Z:
        term2 = 0.5
        term3 = 1.0 / 6.0
        c2 = term2
        c3 = term3
        for k in range(1, _SERIES_TERMS):
            term2 *= -z / ((2 * k + 1) * (2 * k + 2))
            term3 *= -z / ((2 * k + 2) * (2 * k + 3))
            c2 += term2
            c3 += term3
        # |z c2| <= 0.5 and |z c3| <= 0.17 here, so these do not cancel.
        return 1.0 - z * c2, 1.0 - z * c3, c2, c3
    if z > 0.0:
        x = math.sqrt(z)
        s = math.sin(x)
        h = math.sin(0.5 * x)
        # c0 and c1 straight from cos/sin: 1 - z*c3 would cancel near x = pi.
        return math.cos(x), s / x, 2.0 * h * h / z, (x - s) / (z * x)
    x = math.sqrt(-z)
    sh = math.sinh(x)
    hh = math.sinh(0.5 * x)
    return math.cosh(x), sh / x, 2.0 * hh * hh / (-z), (sh - x) / (-z * x)


@jit(error_model="numpy")
def _universal_functions(chi, alpha):
    """Battin's U0..U3 for universal anomaly ``chi`` and ``alpha = 1/a``."""
    chi2 = chi * chi
    c0, c1, c2, c3 = stumpff(alpha * chi2)
    return c0, chi * c1, chi2 * c2, chi2 * chi * c3


@jit(error_model="numpy")
def _kepler_residual(y, r0n, sig, alpha, target):
    """Residual G of Kepler's equation at chi = y, its derivative r, and the
    rounding-noise level of G (eps times the sum of its terms' magnitudes)."""
    u0, u1, u2, u3 = _universal_functions(y, alpha)
    a1 = r0n * u1
    a2 = sig * u2
    G = a1 + a2 + u3 - target
    r = r0n * u0 + sig * u1 + u2
    noise = _RESIDUAL_RTOL * (abs(a1) + abs(a2) + abs(u3) + target)
    return G, r, noise


@jit(error_model="numpy")
def universal_anomaly(r0n, sigma0, alpha, tau):
    """Solve the universal Kepler equation for the universal anomaly chi.

    Solves ``tau = r0n U1(chi) + sigma0 U2(chi) + U3(chi)`` (Battin 1999,
    eq. 4.84), where ``tau = sqrt(mu) t``, ``sigma0 = (r0 . v0) / sqrt(mu)``,
    ``alpha = 2/r0n - v0^2/mu`` and U_k are Battin's universal functions.
    The right-hand side is monotonic in chi with derivative ``r(chi) =
    r0n U0 + sigma0 U1 + U2 >= 0``, so the root is unique.

    The guess (Vallado 2013, algorithm 8: ``alpha tau`` for ellipses, a
    logarithmic estimate for hyperbolae; plus ``tau / r0n`` for short arcs
    and ``(6 tau)^(1/3)`` near parabolic) is doubled or halved until the root
    is bracketed within a factor of two; for ellipses the bracket is also
    capped by one period, ``chi = 2 pi / sqrt(alpha)``.  Newton's method then
    runs inside the bracket, and whenever its step leaves the bracket or fails
    to halve it fast enough a bisection step is taken instead (Press et al.
    2007, sec. 9.4, "rtsafe").  It stops when the step or the residual reaches
    rounding level.  This always converges, including for nearly parabolic
    and radial orbits; typically 4-8 evaluations, rarely more than ~20.

    For elliptic orbits ``tau`` should already be reduced to within half a
    period (``lagrange_coefficients`` does this).  ``r0n`` may be 0 (start at
    the focus of a radial orbit).
    """
    if tau == 0.0:
        return 0.0
    # Time symmetry: going back by |tau| is going forward with the velocity
    # reversed (sigma0 -> -sigma0, chi -> -chi), so only chi >= 0 is solved.
    d = 1.0 if tau > 0.0 else -1.0
    target = abs(tau)
    sig = d * sigma0

    lo = 0.0
    y = -1.0
    if alpha > 0.0:
        hi = _TWO_PI / math.sqrt(alpha)  # one full period: tau(hi) = 2pi/alpha^1.5
    else:
        hi = np.inf
        if alpha < 0.0:
            sqa = math.sqrt(-1.0 / alpha)
            den = sig + sqa * (1.0 - r0n * alpha)
            if den > 0.0:
                arg = -2.0 * alpha * target / den
                if arg > 1.0:
                    y = sqa * math.log(arg)
                    if r0n > 0.0:
                        # The log form is for long arcs; it overshoots short ones.
                        y = min(y, target / r0n)
    if not (0.0 < y < hi):
        # Short arcs: chi ~ tau / r0.  Long arcs: mean motion (alpha tau) on
        # ellipses, the cubic term (6 tau)^(1/3) on near-parabolic orbits.
        y = np.cbrt(6.0 * target)
        if alpha > 0.0:
            y = max(y, target * alpha)
        if r0n > 0.0:
            y = min(y, target / r0n)
        if not (y < hi):
            y = 0.5 * hi
    if not (y > 0.0):
        # target so small that chi underflows: the state does not move.
        return 0.0

    G, r, noise = _kepler_residual(y, r0n, sig, alpha, target)
    if abs(G) <= noise:
        return d * y
    # Bracket the root within a factor of two by doubling or halving the
    # guess, remembering the endpoint with the smaller residual as the
    # Newton start (a good guess is not thrown away).
    yb, Gb, rb = y, G, r
    if G < 0.0:
        lo = y
        for _ in range(2100):
            y2 = 2.0 * y
            if not (y2 < hi):
                break
            y = y2
            G, r, noise = _kepler_residual(y, r0n, sig, alpha, target)
            if abs(G) < abs(Gb):
                yb, Gb, rb = y, G, r
            if G < 0.0:
                lo = y
            else:  # positive, or nan from overflow far beyond the root
                hi = y
                break
    else:
        hi = y
        for _ in range(2100):
            y2 = 0.5 * y
            if not (y2 > 0.0):
                break
            y = y2
            G, r, noise = _kepler_residual(y, r0n, sig, alpha, target)
            if abs(G) < abs(Gb) or not (abs(Gb) < np.inf):
                yb, Gb, rb = y, G, r
            if G < 0.0:
                lo = y
                break
            hi = y
    y, G, r = yb, Gb, rb
    if G == 0.0:
        return d * y

    dx_old = hi - lo
    dx = dx_old
    for _ in range(_MAX_ITER):
        newton_ok = r > 0.0 and abs(G) < np.inf
        yn = y
        if newton_ok:
            yn = y - G / r
        if (not newton_ok) or (not (lo < yn < hi)) or abs(2.0 * G) > abs(dx_old * r):
            dx_old = dx
            dx = 0.5 * (hi - lo)
            yn = lo + dx
        else:
            dx_old = dx
            dx = yn - y
        if yn == y or abs(dx) <= _CHI_RTOL * abs(yn):
            y = yn
            break
        y = yn
        G, r, noise = _kepler_residual(y, r0n, sig, alpha, target)
        if G < 0.0:
            lo = y
        elif G == 0.0:
            break
        else:
            hi = y
        # Further Newton steps would only chase rounding noise.
        if abs(G) <= noise or hi - lo <= 2.3e-16 * hi:
            break
    return d * y


@jit(error_model="numpy")
def lagrange_coefficients(r0, v0, mu, t):
    """Lagrange f, g, fdot, gdot mapping (r0, v0) to the state at time t.

    ``r = f r0 + g v0`` and ``v = fdot r0 + gdot v0`` with (Battin 1999,
    sec. 4.5; Bate, Mueller & White 1971, sec. 4.4)::

        f    = 1 - U2 / r0
        g    = (r0 U1 + sigma0 U2) / sqrt(mu)
        fdot = -sqrt(mu) U1 / (r r0)
        gdot = 1 - U2 / r
        r    = r0 U0 + sigma0 U1 + U2

    ``g`` is written in the cancellation-free form rather than the textbook
    ``t - U3 / sqrt(mu)``, which loses all digits for short arcs.  For
    elliptic orbits ``t`` is first reduced to within half a period (the
    motion is exactly periodic), so arbitrarily long times keep full
    precision relative to ``t`` itself.

    These coefficients are exact, but far from periapsis on open or
    near-parabolic orbits they are large and ``f r0 + g v0`` cancels;
    :func:`kepler_step` avoids that and is what :func:`kepler` uses.

    ``r0`` and ``v0`` are float arrays of equal length (2 or 3), ``mu > 0``.
    """
    r0n, v02, rv, alpha = _state_scalars(r0, v0, mu)
    sqmu = math.sqrt(mu)
    sigma0 = rv / sqmu

    if alpha > 0.0:
        period = _TWO_PI / (sqmu * alpha * math.sqrt(alpha))
        if abs(t) > 0.5 * period:
            # np.fmod is exact, so the only error left is that of t itself.
            t = np.fmod(t, period)
            if t > 0.5 * period:
                t -= period
            elif t < -0.5 * period:
                t += period
    chi = universal_anomaly(r0n, sigma0, alpha, sqmu * t)
    u0, u1, u2, u3 = _universal_functions(chi, alpha)
    r = r0n * u0 + sigma0 * u1 + u2
    f = 1.0 - u2 / r0n
    g = (r0n * u1 + sigma0 * u2) / sqmu
    fdot = -sqmu * u1 / (r * r0n)
    gdot = 1.0 - u2 / r
    return f, g, fdot, gdot


# A state farther than this many periapsis distances from the focus is
# propagated from periapsis instead of from itself (see kepler_step).  Nearer
# in, the hyperbolic anomaly |H0| < 1.4 (parabolic anomaly tan(nu/2) < 1), so
# the direct universal form loses at most a factor e^(2|H0|) ~ 16; ellipses
# this far out have e > 1/3, so the periapsis direction is well defined.
_FAR_FROM_PERIAPSIS = 2.0


@jit(error_model="numpy")
def kepler_step(r0, v0, mu, t, r_out, v_out):
    """Advance a Kepler state by ``t`` and write it to ``r_out``, ``v_out``.

    Same physics as :func:`kepler`; no validation.  ``r_out``/``v_out`` may be
    the very arrays ``r0``/``v0`` (in-place update for a game loop).

    States near periapsis (``|r0| <= 2 q``) use the Lagrange coefficients of
    :func:`lagrange_coefficients`.  Farther out that form is ill-conditioned
    on open and near-parabolic orbits: U1..U3 grow like ``e^|dH|`` (or
    ``chi^3``) and the terms of both Kepler's equation and ``r = f r0 + g v0``
    cancel to a tiny fraction of their size -- a hyperbolic flyby started
    1e4 |a| out would lose ~8 digits.  Such states are re-expressed about
    periapsis, where ``sigma = 0`` and nothing cancels.  With ``p = h^2/mu``,
    ``e = sqrt(1 - alpha p)``, ``q = p / (1 + e)``, ``P = e_vec / |e_vec|``,
    ``Q = h x P / |h|`` (Bate, Mueller & White 1971, ch. 2 and 4; Battin
    1999, sec. 4.5)::

        chi_p: the state's universal anomaly measured from periapsis,
               E0 / sqrt(alpha), H0 / sqrt(-alpha) or sigma0 (parabola), from
               U0(chi_p) = (1 - alpha r0) / e,  U1(chi_p) = sigma0 / e
        sqrt(mu) t_p = q U1(chi_p) + U3(chi_p)      (time since periapsis)
        sqrt(mu) (t_p + t) = q U1(chi) + U3(chi),   r = q U0 + U2
        r_vec = (q - U2) P + (h U1 / sqrt(mu)) Q
        v_vec = -(sqrt(mu) U1 / r) P + (h U0 / r) Q

    (For a parabola ``e = 1``.)  Both terms of ``t_p`` carry the sign of
    ``chi_p``, so nothing cancels, and errors stay at the level set by the
    rounding of the input itself.  A radial orbit (``h = 0``, ``q = 0``)
    reaches the focus at ``t_p = 0`` and is continued as a bounce.
    """
    n = r0.shape[0]
    if t == 0.0:
        # Exactly the input (the periapsis route below would round it).
        for i in range(n):
            r_out[i] = r0[i]
            v_out[i] = v0[i]
        return
    r0n, v02, rv, alpha = _state_scalars(r0, v0, mu)
    if n == 3:
        hx = r0[1] * v0[2] - r0[2] * v0[1]
        hy = r0[2] * v0[0] - r0[0] * v0[2]
        hz = r0[0] * v0[1] - r0[1] * v0[0]
    else:
        hx = 0.0
        hy = 0.0
        hz = r0[0] * v0[1] - r0[1] * v0[0]
    h2 = hx * hx + hy * hy + hz * hz
    # e^2 = 1 - alpha p: exact enough wherever it is used (e > 1/3 below).
    e = math.sqrt(max(0.0, 1.0 - alpha * h2 / mu))
    q = h2 / (mu * (1.0 + e))
    if r0n > _FAR_FROM_PERIAPSIS * q:
        h = math.sqrt(h2)
        sqmu = math.sqrt(mu)
        sigma0 = rv / sqmu
        if alpha > 0.0:
            sa = math.sqrt(alpha)
            chip = math.atan2(sa * sigma0, 1.0 - alpha * r0n) / sa
        elif alpha < 0.0:
            sa = math.sqrt(-alpha)
            y = sa * sigma0 / e
            chip = math.asinh(y) / sa if y != 0.0 else sigma0 / e
        else:
            chip = sigma0
        _, u1p, _, u3p = _universal_functions(chip, alpha)
        tau = q * u1p + u3p  # sqrt(mu) * time since periapsis
        if alpha > 0.0:
            period = _TWO_PI / (sqmu * alpha * math.sqrt(alpha))
            if abs(t) > 0.5 * period:
                t = np.fmod(t, period)  # exact
            tau += sqmu * t
            half = 0.5 * sqmu * period
            if tau > half:
                tau -= 2.0 * half
            elif tau < -half:
                tau += 2.0 * half
        else:
            tau += sqmu * t
        chi = universal_anomaly(q, 0.0, alpha, tau)
        u0, u1, u2, u3 = _universal_functions(chi, alpha)
        r = q * u0 + u2
        xp = q - u2
        yq = h * u1 / sqmu
        vp = -sqmu * u1 / r
        vq = h * u0 / r
        k = v02 - mu / r0n
        ex = k * r0[0] - rv * v0[0]  # mu * e_vec; only its direction is used
        ey = k * r0[1] - rv * v0[1]
        ez = k * r0[2] - rv * v0[2] if n == 3 else 0.0
        en = math.sqrt(ex * ex + ey * ey + ez * ez)
        px = ex / en
        py = ey / en
        pz = ez / en
        if h > 0.0:
            qx = (hy * pz - hz * py) / h
            qy = (hz * px - hx * pz) / h
            qz = (hx * py - hy * px) / h
        else:
            # Radial: no Q direction, and yq = vq = 0 anyway.
            qx = 0.0
            qy = 0.0
            qz = 0.0
        # All reads of r0/v0 are done, so writing aliased outputs is safe.
        r_out[0] = xp * px + yq * qx
        r_out[1] = xp * py + yq * qy
        v_out[0] = vp * px + vq * qx
        v_out[1] = vp * py + vq * qy
        if n == 3:
            r_out[2] = xp * pz + yq * qz
            v_out[2] = vp * pz + vq * qz
        return
    f, g, fdot, gdot = lagrange_coefficients(r0, v0, mu, t)
    for i in range(n):
        # Read both components before writing, so aliasing is safe.
        ri = r0[i]
        vi = v0[i]
        r_out[i] = f * ri + g * vi
        v_out[i] = fdot * ri + gdot * vi


@jit(error_model="numpy")
def kepler_propagate(r0, v0, mu, t):
    """Compiled ``kepler`` for a scalar time: returns new arrays ``(r, v)``."""
    r = np.empty(r0.shape[0])
    v = np.empty(r0.shape[0])
    kepler_step(r0, v0, mu, t, r, v)
    return r, v


@jit(error_model="numpy")
def kepler_propagate_times(r0, v0, mu, times):
    """Compiled ``kepler`` for many times: arrays ``(R, V)`` of shape (n, dim).

    Every row is propagated from the initial state (not chained), so errors
    do not accumulate along the array.
    """
    nt = times.shape[0]
    dim = r0.shape[0]
    R = np.empty((nt, dim))
    V = np.empty((nt, dim))
    for k in range(nt):
        kepler_step(r0, v0, mu, times[k], R[k], V[k])
    return R, V


@jit(error_model="numpy")
def orbit_invariants(r0, v0, mu):
    """Conic invariants ``(a, e, energy, period, h, p, periapsis)``.

    ``energy = v^2/2 - mu/r = -mu alpha / 2`` with ``alpha = 1/a`` computed
    in compensated arithmetic (see ``_state_scalars``), ``a = 1/alpha``
    (``inf`` for a parabola, negative for a hyperbola), ``h = |r x v|``,
    semi-latus rectum ``p = h^2/mu``, eccentricity from the
    Laplace-Runge-Lenz vector ``e = |(v^2 - mu/r) r - (r.v) v| / mu``,
    periapsis distance ``q = p / (1 + e)``, and ``period = 2 pi /
    (sqrt(mu) alpha^1.5) = 2 pi sqrt(a^3/mu)`` for bound orbits (``inf``
    otherwise) -- the same period ``kepler`` reduces time with.  Bate,
    Mueller & White 1971, ch. 1 and 2.
    """
    n = r0.shape[0]
    rn, vv, rv, alpha = _state_scalars(r0, v0, mu)
    energy = -0.5 * mu * alpha
    if n == 3:
        hx = r0[1] * v0[2] - r0[2] * v0[1]
        hy = r0[2] * v0[0] - r0[0] * v0[2]
        hz = r0[0] * v0[1] - r0[1] * v0[0]
        h = math.sqrt(hx * hx + hy * hy + hz * hz)
    else:
        h = abs(r0[0] * v0[1] - r0[1] * v0[0])
    k = vv - mu / rn
    e2 = 0.0
    for i in range(n):
        ei = (k * r0[i] - rv * v0[i]) / mu
        e2 += ei * ei
    e = math.sqrt(e2)
    p = h * h / mu
    if alpha != 0.0:
        a = 1.0 / alpha
    else:
        a = np.inf
    if alpha > 0.0:
        period = _TWO_PI / (math.sqrt(mu) * alpha * math.sqrt(alpha))
    else:
        period = np.inf
    return a, e, energy, period, h, p, p / (1.0 + e)


@jit(error_model="numpy")
def oscillator_transition(omega, zeta, t):
    """State-transition coefficients of ``x'' + 2 zeta omega x' + omega^2 x = 0``.

    Returns ``(a, b, c, d)`` with ``x(t) = a x0 + b v0`` and
    ``v(t) = c x0 + d v0``.  One formula covers every regime (French 1971,
    ch. 4, written in Stumpff functions)::

        x = E (x0 C + (v0 + zeta omega x0) S)
        v = E (v0 C - (omega^2 x0 + zeta omega v0) S)
        E = exp(-zeta omega t),  q = omega^2 (1 - zeta^2) t^2,
        C = c0(q) = cos(omega_d t)       or cosh(gamma t),
        S = t c1(q) = sin(omega_d t)/omega_d or sinh(gamma t)/gamma

    with ``omega_d = omega sqrt(1 - zeta^2)`` and ``gamma = omega
    sqrt(zeta^2 - 1)``.  The Stumpff form is continuous through critical
    damping (``C -> 1``, ``S -> t``) without 0/0.  For strongly overdamped
    motion (``gamma |t| > 1``) the exponentials are combined first,
    ``E C = (e^{s1 t} + e^{s2 t}) / 2``, ``E S = (e^{s1 t} - e^{s2 t}) /
    (2 gamma)`` with roots ``s1 = -omega / (zeta + sqrt(zeta^2 - 1))``,
    ``s2 = -omega (zeta + sqrt(zeta^2 - 1))``, because ``exp(-zeta omega t)``
    underflows while ``cosh(gamma t)`` overflows.
    """
    zw = zeta * omega
    if zeta > 1.0:
        root = math.sqrt((zeta - 1.0) * (zeta + 1.0))
        gamma = omega * root
        if gamma * abs(t) > 1.0:
            s1 = -omega / (zeta + root)  # slow root, written without cancellation
            s2 = -omega * (zeta + root)
            e1 = math.exp(s1 * t)
            e2 = math.exp(s2 * t)
            EC = 0.5 * (e1 + e2)
            ES = 0.5 * (e1 - e2) / gamma
            return EC + zw * ES, ES, -omega * omega * ES, EC - zw * ES
    # (1 - zeta)(1 + zeta) keeps its digits near critical damping.
    q = omega * omega * (1.0 - zeta) * (1.0 + zeta) * t * t
    c0, c1, c2, c3 = stumpff(q)
    E = math.exp(-zw * t)
    EC = E * c0
    ES = E * t * c1
    return EC + zw * ES, ES, -omega * omega * ES, EC - zw * ES


@jit(error_model="numpy")
def ballistic_step(p0, v0, g, t, p_out, v_out):
    """Compiled ``ballistic`` for one time; ``p_out``/``v_out`` may alias inputs."""
    half_tt = 0.5 * t * t
    for i in range(p0.shape[0]):
        pi = p0[i]
        vi = v0[i]
        gi = g[i]
        p_out[i] = pi + vi * t + gi * half_tt
        v_out[i] = vi + gi * t


# ---------------------------------------------------------------------------
# Validation helpers
# ---------------------------------------------------------------------------


def _times(name, value):
    """Returns ``(array, is_scalar)``; ``array`` is 0-d or 1-D float64."""
    arr = finite_array(name, value, "a time or a 1-D array of times")
    if arr.ndim > 1:
        raise ValueError(f"{name} must be a scalar or a 1-D array of times, got {value!r}")
    # (np.ascontiguousarray would promote a 0-d array to 1-D.)
    return np.require(arr, requirements="C"), arr.ndim == 0


def _kepler_inputs(r0, v0, mu):
    r0a = vector("r0", r0)
    v0a = vector("v0", v0)
    if v0a.shape != r0a.shape:
        raise ValueError(f"v0 must have the same length as r0 ({r0a.shape[0]}), got {v0!r}")
    mu_f = positive_float("mu", mu)
    if not np.any(r0a != 0.0):
        raise ValueError(f"r0 must have non-zero length, got {r0!r}")
    return r0a, v0a, mu_f


# ---------------------------------------------------------------------------
# Public API
# ---------------------------------------------------------------------------


def ballistic(p0, v0, g, t):
    """Motion under constant acceleration.

    ``p = p0 + v0 t + g t^2 / 2``, ``v = v0 + g t`` (uniformly accelerated
    motion; Galileo, any mechanics text).

    ``p0``, ``v0``, ``g`` are scalars or arrays of any dimension that
    broadcast together (e.g. one ``(dim,)`` gravity for an ``(n, dim)`` batch
    of particles).  ``t`` is a scalar, giving arrays of the broadcast shape,
    or a 1-D array of times, giving arrays with a leading time axis
    ``(len(t),) + shape`` -- handy for drawing a predicted path.

    Raises TypeError for text, booleans or complex numbers, and ValueError
    for non-finite input, shapes that do not broadcast, or ``t`` with more
    than one axis; both name the argument and show its value.
    """
    p0a = finite_array("p0", p0)
    v0a = finite_array("v0", v0)
    ga = finite_array("g", g)
    ta, _ = _times("t", t)
    try:
        shape = np.broadcast_shapes(p0a.shape, v0a.shape, ga.shape)
    except ValueError as exc:
        raise ValueError(
            f"p0, v0 and g must have compatible shapes, got p0 {p0a.shape}, "
            f"v0 {v0a.shape}, g {ga.shape}"
        ) from exc
    tt = ta.reshape(ta.shape + (1,) * len(shape))
    p = p0a + v0a * tt + 0.5 * ga * (tt * tt)
    v = v0a + ga * tt
    out_shape = ta.shape + shape
    p = np.broadcast_to(p, out_shape).copy()
    v = np.broadcast_to(v, out_shape).copy()
    if out_shape == ():
        return float(p), float(v)
    return p, v


def kepler(r0, v0, mu, t):
    """Two-body motion about a fixed centre, for any conic section.

    Solves ``r'' = -mu r / |r|^3`` exactly for the relative position ``r0``
    and velocity ``v0`` (vectors of length 2 or 3) after time ``t``, which may
    be negative (backwards) or a 1-D array of times.

    Method: universal variables (Bate, Mueller & White 1971, ch. 4; Battin
    1999, sec. 4.5; Vallado 2013, algorithm 8).  With
    ``alpha = 2/|r0| - |v0|^2/mu`` and ``sigma0 = r0.v0 / sqrt(mu)`` the
    universal Kepler equation::

        sqrt(mu) t = |r0| U1(chi) + sigma0 U2(chi) + U3(chi)

    is solved for chi by bracketed Newton iteration (see
    :func:`universal_anomaly`), and the state follows from the Lagrange
    coefficients (see :func:`lagrange_coefficients`).  Elliptic, circular,
    parabolic and hyperbolic orbits use the same formulas; elliptic times are
    first reduced modulo the period, so millions of orbits stay accurate.
    Two refinements keep the error at the level the rounding of the input
    itself implies: ``alpha`` is computed in compensated (double-double)
    arithmetic, which matters near e = 1, and a state farther than twice the
    periapsis distance is propagated from periapsis, which matters for
    distant hyperbolic and near-parabolic arcs (see :func:`kepler_step`).

    Radial orbits (``r0`` parallel to ``v0``) are supported; they are
    continued through the collision as the regularised elastic bounce, and
    exactly at the collision instant the velocity is infinite.

    Returns ``(r, v)`` as arrays of shape ``(dim,)``, or ``(len(t), dim)``
    for an array of times.  The compiled core is :func:`kepler_propagate`
    (and :func:`kepler_step` for in-place updates).

    Raises TypeError for text, booleans or complex numbers, and ValueError
    for: non-finite entries; ``r0``/``v0`` not of length 2 or 3 or of
    different lengths; ``mu <= 0``; ``r0`` of zero length; ``t`` with more
    than one axis.  Both name the argument and show its value.
    """
    r0a, v0a, mu_f = _kepler_inputs(r0, v0, mu)
    ta, scalar = _times("t", t)
    if scalar:
        return kepler_propagate(r0a, v0a, mu_f, float(ta))
    return kepler_propagate_times(r0a, v0a, mu_f, ta)


def harmonic_oscillator(x0, v0, omega, t, zeta=0.0):
    """Linear oscillator ``x'' + 2 zeta omega x' + omega^2 x = 0``.

    Undamped (``zeta = 0``), under-damped (``0 < zeta < 1``), critically
    damped (``zeta = 1``) and over-damped (``zeta > 1``) motion from the
    closed-form solution in :func:`oscillator_transition`; e.g. undamped
    ``x = x0 cos(omega t) + v0/omega sin(omega t)``, critical
    ``x = e^{-omega t} (x0 + (v0 + omega x0) t)``.

    ``x0`` and ``v0`` are scalars or arrays that broadcast together (each
    component oscillates independently with the same ``omega``, ``zeta``);
    ``t`` is a scalar or a 1-D array of times (leading time axis in the
    output).  Returns ``(x, v)``.

    Raises TypeError for text, booleans or complex numbers, and ValueError
    for non-finite input, ``omega <= 0``, ``zeta < 0`` or incompatible
    shapes; both name the argument and show its value.
    """
    x0a = finite_array("x0", x0)
    v0a = finite_array("v0", v0)
    omega_f = positive_float("omega", omega)
    zeta_f = nonnegative_float("zeta", zeta)
    ta, scalar = _times("t", t)
    try:
        shape = np.broadcast_shapes(x0a.shape, v0a.shape)
    except ValueError as exc:
        raise ValueError(
            f"x0 and v0 must have compatible shapes, got x0 {x0a.shape}, v0 {v0a.shape}"
        ) from exc
    flat_t = ta.reshape(-1)
    nt = flat_t.shape[0]
    coeffs = np.empty((nt, 4))
    for k in range(nt):
        coeffs[k] = oscillator_transition(omega_f, zeta_f, float(flat_t[k]))
    expand = (slice(None),) + (None,) * len(shape)
    a, b, c, d = (coeffs[:, j][expand] for j in range(4))
    x = np.broadcast_to(a * x0a + b * v0a, (nt,) + shape).copy()
    v = np.broadcast_to(c * x0a + d * v0a, (nt,) + shape).copy()
    if not scalar:
        return x, v
    if shape == ():
        return float(x[0]), float(v[0])
    return x[0], v[0]


OrbitalElements = namedtuple(
    "OrbitalElements",
    ["a", "e", "energy", "period", "h", "p", "periapsis", "e_vec", "h_vec"],
)
OrbitalElements.__doc__ = """Invariants of a two-body orbit (see :func:`orbital_elements`).

a         semi-major axis (negative for hyperbolae, inf for a parabola)
e         eccentricity
energy    specific orbital energy v^2/2 - mu/r
period    orbital period, inf for unbound orbits
h         magnitude of the specific angular momentum |r x v|
p         semi-latus rectum h^2/mu
periapsis periapsis distance p / (1 + e)
e_vec     eccentricity vector (same length as the input, points to periapsis)
h_vec     angular momentum vector r x v as a 3-vector (z only, for 2-D input)
"""


def orbital_elements(r0, v0, mu):
    """Summary of the conic through the state ``(r0, v0)`` about ``mu``.

    Returns :class:`OrbitalElements` ``(a, e, energy, period, h, p,
    periapsis, e_vec, h_vec)``; formulas in :func:`orbit_invariants`
    (Bate, Mueller & White 1971, ch. 1-2).  Validates like :func:`kepler`.
    """
    r0a, v0a, mu_f = _kepler_inputs(r0, v0, mu)
    a, e, energy, period, h, p, q = orbit_invariants(r0a, v0a, mu_f)
    r3 = np.zeros(3)
    v3 = np.zeros(3)
    r3[: r0a.shape[0]] = r0a
    v3[: v0a.shape[0]] = v0a
    h_vec = np.cross(r3, v3)
    rn = float(np.linalg.norm(r0a))
    e_vec = ((v0a @ v0a - mu_f / rn) * r0a - (r0a @ v0a) * v0a) / mu_f
    return OrbitalElements(
        float(a), float(e), float(energy), float(period), float(h), float(p), float(q), e_vec, h_vec
    )
