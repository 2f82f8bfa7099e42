"""JANUS: a bit-wise time-reversible symplectic integrator on a power-of-two lattice.

H. Rein & D. Tamayo, "JANUS: a bit-wise reversible integrator for N-body dynamics", MNRAS 473,
3351 (2018). Positions and velocities live on integer lattices of spacings ``sx`` and ``sv``;
a drift and a kick are exact integer updates

    drift(c h):  x_int += R((c h) v / sx),       v = v_int sv (exact)
    kick(c h):   v_int += R((c h) a(x) / sv),    x = x_int sx (exact)

with a rounding R that is odd, R(-y) == -R(y). Floating-point multiplication is
sign-symmetric ((-s) v == -(s v) bit for bit), so a drift or kick with -h subtracts exactly
what the same update with +h added, and a *symmetric* composition of such updates run with
-h undoes a step with +h bit for bit, whatever rounding the force evaluation commits: the
forces are evaluated at the same lattice positions both ways and give the same bits.

The step is the symmetric composition of drift-kick-drift leapfrogs
``S2(g_0 h) S2(g_1 h) ... S2(g_{s-1} h)`` with g_i = g_{s-1-i}, the adjacent half drifts of
one step merged (``(g_{i-1} + g_i)/2``), the first and last half drifts of consecutive
steps not merged (as in Rein & Tamayo's implementation, so the two give the same numbers).
The coefficients are published facts:

- order 2: one stage, g = 1 (leapfrog);
- order 4: 5 stages, g = (p, p, 1 - 4p, p, p), p = 1 / (4 - 4^(1/3)) (M. Suzuki, "Fractal
  decomposition of exponential operators", Phys. Lett. A 146, 319 (1990); REBOUND's s5odr4);
- order 6: 9 stages, scheme s9odr6a, and order 8: 15 stages, scheme s15odr8, of W. Kahan &
  R.-C. Li, "Composition constants for raising the orders of unconventional schemes for
  ordinary differential equations", Math. Comp. 66, 1089 (1997);

the numbers as tabulated in REBOUND's ``src/integrator_janus.c`` (Rein & Tamayo), which uses
the same four schemes for orders 2 to 8.

Our variant keeps no hidden integer state. The spacings are powers of two, ``sx = 2**-kx``
and ``sv = 2**-kv``, and every lattice value is kept at |i| < 2**53: the float64 number
``i * sx`` is then exact and ``x * 2**kx`` gives ``i`` back, so the simulation's own float
positions and velocities *are* the lattice state. A call converts them to int64 (rounding
any that are off the lattice, with R: a call of zero steps puts a state on the lattice),
steps in integers, and writes the floats back after every update (the forces read the
float positions). The exponents are chosen once, by ``lattice_exponents``, and must then be
kept fixed: changing them between calls re-rounds the state, and the step is then not
undone by a reversed one.

Rounding: ``advance`` rounds to the nearest integer, ties to even (``np.rint``, odd, error
at most half a lattice unit and unbiased). ``advance_truncating`` truncates towards zero,
as REBOUND's C casts do (also odd, but biased towards zero by half a unit on average;
measured over one e = 0.5 Kepler orbit, order 6, 400 steps, 3 bits of headroom: it moved
the end point by 1.7e-11, where halving the lattice spacing twice moved the rounding's by
3e-13; over 1000 orbits (order 8, 200 steps per orbit, default lattice) both are dominated
by the random walk of the rounding errors and came out alike, 2.5e-6 and 1.2e-6). From a
state on the lattice, with the same power-of-two lattices (``scale_pos = 2**-kx``,
``scale_vel = 2**-kv``), the same order and accelerations with the same bits, it computes
exactly what REBOUND's ``janus`` computes, because ``(c h v_int) scale_vel / scale_pos``
and ``(c h) (v_int sv) 2**kx`` differ only by exact power-of-two scalings (the tests hold
the two to bit-for-bit agreement).

What stays exactly reversible: forces that depend on positions only, evaluated
deterministically (the scalar pair loops are; a multi-threaded large-N kernel must sum in a
fixed order). Not exactly reversible: velocity-dependent forces (``vdep``: each kick
evaluates them with the current float velocities, as the engine's other splitting methods
do, so a kick is an explicit Euler step in them, first order, and a kick with -h does not
see the velocities the kick with +h saw) and time-dependent forces (the stage times
``t + c h`` of a reversed step are not bit-identical to the forward ones; the order is
kept). Inactive and pinned particles are never converted or moved: their float positions
are used by the forces as they are, and need not lie on the lattice.

Periodic space (``state.box`` = L > 0, the torus [-L/2, L/2)): positions are wrapped in
integers, ``x_int`` into [-L_int/2, L_int/2) with ``L_int = L / sx``, which is exact (and
reversible: the wrap is a translation by whole periods) only when L / sx is an integer below
2**53; otherwise the call refuses with ``BAD_LATTICE`` before touching the state.
``lattice_exponents(..., box=L)`` picks ``kx`` so that it is: ``L 2**kx`` in [2**52, 2**53).

Status (the ``common`` contract, plus three codes of this module): ``OK`` (-1);
a particle index >= 0 when an update of that particle came out non-finite (a force blew up;
the state is the one at the start of the failing step, ``done`` the index of that step), or
when its position or velocity is not finite at the start of a call (``done`` = 0, state
untouched);
``LATTICE_OVERFLOW`` (-4) when a position or velocity would leave |i| < 2**53 (same state
and ``done``; at the start of a call, a value already outside the lattice range gives it with
``done`` = 0 and the state untouched); ``BAD_LATTICE`` (-5) when the exponents are out of
range (|kx|, |kv|, |kx - kv| must be at most ``MAX_EXPONENT``) or the box is not a whole
number of lattice units; ``BAD_ORDER`` (-6) when ``order`` is not one of ``ORDERS``;
these two are returned with ``done`` = 0 before the state is touched. A blow-up under a
close encounter usually shows as ``LATTICE_OVERFLOW``: a huge velocity leaves the lattice
long before it stops being finite.
"""
import math

import numpy as np
from ..cache import jit

from ..forces import gravity
from ..forces.dispatch import accelerations_inline
from . import fused_gravity
from .common import OK, fill_active_mask

NAME = "janus"
ORDERS = (2, 4, 6, 8)

#: a position or velocity would leave the lattice range |i| < 2**53 (the state is kept)
LATTICE_OVERFLOW = -4
#: exponents out of range, or a periodic box that is not a whole number of lattice units
BAD_LATTICE = -5
#: an order other than 2, 4, 6, 8
BAD_ORDER = -6

#: every lattice value i satisfies |i| < LIMIT, so that i * 2**-k is an exact float64
LIMIT = 2 ** 53
#: bits of headroom ``lattice_exponents`` leaves above the largest |x| and |v| it sees
HEADROOM_BITS = 10
#: largest |kx|, |kv|, |kx - kv| accepted (2**k stays a finite, normal float64)
MAX_EXPONENT = 1000

#: first half (with the middle one) of each scheme's g_i; the rest mirror them
SCHEMES = {
    2: (1.0,),
    # Suzuki (1990): p, p, 1 - 4p; the decimal values of REBOUND's table (s5odr4)
    4: (0.41449077179437573714, 0.41449077179437573714, -0.65796308717750294857),
    # Kahan & Li (1997), s9odr6a
    6: (0.39216144400731413928, 0.33259913678935943860, -0.70624617255763935981,
        0.082213596293550800230, 0.79854399093482996340),
    # Kahan & Li (1997), s15odr8
    8: (0.74167036435061295345, -0.40910082580003159400, 0.19075471029623837995,
        -0.57386247111608226666, 0.29906418130365592384, 0.33462491824529818378,
        0.31529309239676659663, -0.79688793935291635402),
}


def stage_coefficients(order):
    """The full symmetric list g_0 ... g_{s-1} of a scheme (s = 1, 5, 9, 15 stages)."""
    half = SCHEMES[order]
    return half + half[-2::-1]


def _table():
    g = np.zeros((len(ORDERS), 15))
    stages = np.zeros(len(ORDERS), dtype=np.int64)
    for row, order in enumerate(ORDERS):
        full = stage_coefficients(order)
        g[row, :len(full)] = full
        stages[row] = len(full)
    return g, stages


_GAMMA, _STAGES = _table()

#: force evaluations per step, by order (one per stage; the composition reuses none)
FORCE_EVALUATIONS = {order: len(stage_coefficients(order)) for order in ORDERS}


# -- the lattice ---------------------------------------------------------------------------------

def _moving(active, pinned, n):
    if active is None:
        return np.ones(n, dtype=bool)
    m = np.asarray(active[:n], dtype=bool)
    if pinned is not None:
        m = m & ~np.asarray(pinned[:n], dtype=bool)
    return m


def lattice_exponents(pos, vel, n, box=0.0, active=None, pinned=None, headroom=HEADROOM_BITS):
    """``(kx, kv)``: lattice spacings ``2**-kx`` and ``2**-kv`` for this state.

    Headroom rule: with ``X`` the largest |coordinate| and ``V`` the largest |velocity
    component| of the moving particles (active and not pinned, when ``active``/``pinned``
    are given; all ``n`` otherwise), ``kx`` is the largest integer with
    ``X 2**kx < 2**(53 - headroom)``, so that positions may grow by a factor ``2**headroom``
    (1024 by default) before the lattice overflows, and likewise ``kv`` for V. The resolution
    is then about ``2**(headroom - 52)``, 2.3e-13 by default, of the largest value.

    In a periodic space (``box`` = L > 0) positions never exceed L/2, so ``kx`` is instead
    the one that makes ``L 2**kx`` an integer in [2**52, 2**53): the box is then a whole
    number of lattice units, as ``advance`` requires.

    A state with no nonzero position uses X = 1; one with no nonzero velocity (a start from
    rest, such as the Pythagorean problem) uses V = X (speeds of a system size per unit
    time, times the headroom). Non-finite values raise ValueError.
    """
    moving = _moving(active, pinned, n)
    x = np.asarray(pos)[:, :n][:, moving]
    v = np.asarray(vel)[:, :n][:, moving]
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(v))):
        raise ValueError("lattice_exponents: non-finite position or velocity")
    if box > 0.0:
        if not math.isfinite(box):
            raise ValueError("lattice_exponents: the box must be finite")
        kx = 53 - math.frexp(box)[1]
        xmax = 0.5 * box
    else:
        xmax = float(np.max(np.abs(x))) if x.size else 0.0
        if xmax == 0.0:
            xmax = 1.0
        kx = (53 - headroom) - math.frexp(xmax)[1]
    vmax = float(np.max(np.abs(v))) if v.size else 0.0
    if vmax == 0.0:
        vmax = xmax
    kv = (53 - headroom) - math.frexp(vmax)[1]
    if max(abs(kx), abs(kv), abs(kx - kv)) > MAX_EXPONENT:
        raise ValueError(f"lattice_exponents: scales out of range (kx={kx}, kv={kv})")
    return kx, kv


def on_lattice(pos, vel, n, kx, kv, active=None, pinned=None):
    """Are the moving particles' positions and velocities exactly lattice values i 2**-k with
    |i| < 2**53? (The state ``advance`` leaves behind always is.)"""
    moving = _moving(active, pinned, n)
    for a, k in ((pos, kx), (vel, kv)):
        y = np.asarray(a)[:, :n][:, moving] * math.ldexp(1.0, k)
        if not (np.all(np.isfinite(y)) and np.all(np.abs(y) < LIMIT) and np.all(y == np.rint(y))):
            return False
    return True


# -- the compiled stepper ------------------------------------------------------------------------

@jit(error_model="numpy", inline="always")
def _round(y, truncate):
    """The odd rounding R: to nearest, ties to even, or towards zero."""
    if truncate:
        return math.trunc(y)
    return np.rint(y)


@jit(error_model="numpy", inline="always")
def _first_bad(acc, mask, n):
    """The first moving particle with a non-finite acceleration, else -1."""
    for i in range(n):
        if mask[i] != 0.0:
            for k in range(acc.shape[0]):
                if not math.isfinite(acc[k, i]):
                    return i
    return -1


@jit(error_model="numpy", inline="always")
def _wrap(q, L):
    """q onto [-L/2, L/2) in lattice units: q - L floor((2q + L) / 2L), in integers."""
    return q - L * ((2 * q + L) // (2 * L))


@jit(error_model="numpy", inline="always")
def _drift(xi, vi, pos, mask, n, s, ratio, sx, L, truncate):
    """x_int += R((s v_int) 2**(kx - kv)) for the moving particles, floats written back (a
    parked particle's v_int is 0 and its float position is left as it is). No branch in the
    loop: a value that would leave the lattice is replaced by 0 and remembered, and the
    caller, told so, puts back the state of the step's start. Returns OK, LATTICE_OVERFLOW
    or the index of the first particle whose increment is not finite."""
    ok = True
    for k in range(xi.shape[0]):
        for i in range(n):
            y = (s * float(vi[k, i])) * ratio
            fits = abs(y) < LIMIT
            ok &= fits
            q = xi[k, i] + np.int64(_round(y if fits else 0.0, truncate))
            if L > 0:
                q = _wrap(q, L)
            else:
                ok &= abs(q) < LIMIT
            xi[k, i] = q
            pos[k, i] = float(q) * sx if mask[i] != 0.0 else pos[k, i]
    if ok:
        return OK
    for i in range(n):
        for k in range(xi.shape[0]):
            if mask[i] != 0.0 and not math.isfinite((s * float(vi[k, i])) * ratio):
                return i
    return LATTICE_OVERFLOW


@jit(error_model="numpy", inline="always")
def _kick(vi, vel, acc, mask, n, s, iv, sv, truncate):
    """v_int += R((s a) 2**kv) for the moving particles, floats written back; the returns of
    ``_drift``."""
    ok = True
    for k in range(vi.shape[0]):
        for i in range(n):
            moving = mask[i] != 0.0
            y = (s * acc[k, i]) * iv if moving else 0.0
            fits = abs(y) < LIMIT
            ok &= fits
            q = vi[k, i] + np.int64(_round(y if fits else 0.0, truncate))
            ok &= abs(q) < LIMIT
            vi[k, i] = q
            vel[k, i] = float(q) * sv if moving else vel[k, i]
    if ok:
        return OK
    bad = _first_bad(acc, mask, n)
    return bad if bad >= 0 else LATTICE_OVERFLOW


@jit(error_model="numpy", inline="always")
def _write(xi, vi, pos, vel, mask, n, sx, sv):
    for k in range(xi.shape[0]):
        for i in range(n):
            if mask[i] != 0.0:
                pos[k, i] = float(xi[k, i]) * sx
                vel[k, i] = float(vi[k, i]) * sv


@jit(error_model="numpy", inline="always")
def _drift_flat(X, V, P, count, s, ratio, sx, truncate):
    """``_drift`` on the flat interleaved coordinates of the fused path (every one moves),
    without a branch in the loop: a value that would leave the lattice is replaced by 0 and
    remembered, and the caller, told so, puts back the state of the step's start. Returns
    OK, LATTICE_OVERFLOW, or the row (particle) of the first non-finite increment."""
    ok = True
    for c in range(count):
        y = (s * float(V[c])) * ratio
        fits = abs(y) < LIMIT
        ok &= fits
        q = X[c] + np.int64(_round(y if fits else 0.0, truncate))
        ok &= abs(q) < LIMIT
        X[c] = q
        P[c] = float(q) * sx
    if ok:
        return OK
    for c in range(count):
        if not math.isfinite((s * float(V[c])) * ratio):
            return c // 3
    return LATTICE_OVERFLOW


@jit(error_model="numpy", inline="always")
def _kick_flat(V, A, count, s, iv, truncate):
    """``_kick`` on the flat interleaved coordinates (the float velocities are written at
    the end of the call); same returns as ``_drift_flat``."""
    ok = True
    for c in range(count):
        y = (s * A[c]) * iv
        fits = abs(y) < LIMIT
        ok &= fits
        q = V[c] + np.int64(_round(y if fits else 0.0, truncate))
        ok &= abs(q) < LIMIT
        V[c] = q
    if ok:
        return OK
    for c in range(count):
        if not math.isfinite(A[c]):
            return c // 3
    return LATTICE_OVERFLOW


@jit(error_model="numpy", _nrt=False)
def _steps_general(t, h, steps, state, model, work, xi, vi, save_x, save_v, acc, mask, gamma,
                   drifts, cum, ratio, sx, iv, sv, L, truncate):
    """The steps through the force table, on the (dim, n) integer copies xi, vi, in the
    caller's scratch (compiled without reference counting, as the force kernels are: the
    count updates of a dozen arrays would cost more than a small system's physics)."""
    pos = state.pos
    vel = state.vel
    n = state.n
    dim = pos.shape[0]
    stages = cum.shape[0]
    t0 = t
    for step in range(steps):
        for k in range(dim):
            for i in range(n):
                save_x[k, i] = xi[k, i]
                save_v[k, i] = vi[k, i]
        status = OK
        for j in range(stages):
            status = _drift(xi, vi, pos, mask, n, drifts[j] * h, ratio, sx, L, truncate)
            if status != OK:
                break
            accelerations_inline(t + cum[j] * h, state, model, acc, work)
            status = _kick(vi, vel, acc, mask, n, gamma[j] * h, iv, sv, truncate)
            if status != OK:
                break
        if status == OK:
            status = _drift(xi, vi, pos, mask, n, drifts[stages] * h, ratio, sx, L, truncate)
        if status != OK:
            _write(save_x, save_v, pos, vel, mask, n, sx, sv)
            return t, h, step, status
        t = t0 + (step + 1) * h
    return t, h, steps, OK


@jit(error_model="numpy", _nrt=False)
def _fused_loop(h, steps, X, V, save_X, save_V, P, A, P_flat, A_flat, gm, m, eps2, gamma,
                drifts, ratio, sx, iv, truncate):
    """The hot loop of ``_steps_fused`` (without reference counting); returns (done, status)
    with the status's particle as a row of the interleaved arrays."""
    count = 3 * m
    stages = gamma.shape[0]
    for step in range(steps):
        for c in range(count):
            save_X[c] = X[c]
            save_V[c] = V[c]
        status = OK
        for j in range(stages):
            status = _drift_flat(X, V, P_flat, count, drifts[j] * h, ratio, sx, truncate)
            if status != OK:
                break
            fused_gravity._gravity(P, gm, m, eps2, A)
            status = _kick_flat(V, A_flat, count, gamma[j] * h, iv, truncate)
            if status != OK:
                break
        if status == OK:
            status = _drift_flat(X, V, P_flat, count, drifts[stages] * h, ratio, sx, truncate)
        if status != OK:
            for c in range(count):
                X[c] = save_X[c]
                V[c] = save_V[c]
            return step, status
    return steps, OK


@jit(error_model="numpy")
def _steps_fused(t, h, steps, state, model, xi, vi, gamma, drifts, ratio, sx, iv, sv,
                 truncate):
    """The steps for the scenes ``fused_gravity.applies`` accepts (one open-space gravity
    term, a few bodies, none pinned or test): the same integer updates on interleaved (m, 3)
    copies of the active bodies, with ``fused_gravity``'s inlined pair loop, which gives
    the bits of the force table's (so both paths give the same bits; a test holds them)."""
    pos = state.pos
    vel = state.vel
    n = state.n
    dim = pos.shape[0]
    f0 = model.param_offsets[0]
    G = model.params[f0]
    eps2 = model.params[f0 + 1]
    index = np.empty(n, dtype=np.int64)
    m = 0
    for i in range(n):
        if state.active[i]:
            index[m] = i
            m += 1
    count = 3 * m
    X = np.zeros(count, dtype=np.int64)
    V = np.zeros(count, dtype=np.int64)
    save_X = np.empty(count, dtype=np.int64)
    save_V = np.empty(count, dtype=np.int64)
    P = np.zeros((m, 3))
    A = np.zeros((m, 3))
    P_flat = P.reshape(count)
    A_flat = A.reshape(count)
    gm = np.empty(m)
    for c in range(m):
        gm[c] = G * state.mass[index[c]]
        for k in range(dim):
            X[3 * c + k] = xi[k, index[c]]
            V[3 * c + k] = vi[k, index[c]]
            P[c, k] = pos[k, index[c]]
    done, status = _fused_loop(h, steps, X, V, save_X, save_V, P, A, P_flat, A_flat, gm, m,
                               eps2, gamma, drifts, ratio, sx, iv, truncate)
    if status >= 0:
        status = index[status]
    for c in range(m):
        for k in range(dim):
            pos[k, index[c]] = float(X[3 * c + k]) * sx
            vel[k, index[c]] = float(V[3 * c + k]) * sv
    return (t if done == 0 else t + done * h), h, done, status


@jit(error_model="numpy", inline="always")
def _prepare(state, order, kx, kv, truncate):
    """Check the order and the lattice and put the state on it (exact for a state already on
    it; nothing written when a check fails). Returns ``(status, xi, vi, mask, gamma, drifts,
    cum, ratio, sx, iv, sv, L)``: status OK, or the reason not to step (the rest then unused)."""
    pos = state.pos
    vel = state.vel
    n = state.n
    dim = pos.shape[0]
    row = -1
    for r in range(len(ORDERS)):
        if ORDERS[r] == order:
            row = r
    status = OK
    if row < 0:
        status = BAD_ORDER
        row = 0
    elif abs(kx) > MAX_EXPONENT or abs(kv) > MAX_EXPONENT or abs(kx - kv) > MAX_EXPONENT:
        status = BAD_LATTICE
        kx = kv = 0
    ix = math.ldexp(1.0, kx)
    sx = math.ldexp(1.0, -kx)
    iv = math.ldexp(1.0, kv)
    sv = math.ldexp(1.0, -kv)
    ratio = math.ldexp(1.0, kx - kv)
    L = np.int64(0)
    if status == OK and state.box > 0.0:
        lf = state.box * ix
        if not (lf < LIMIT and lf == math.floor(lf)):
            status = BAD_LATTICE
        else:
            L = np.int64(lf)

    stages = _STAGES[row]
    gamma = _GAMMA[row, :stages].copy()
    # drift coefficients g_0/2, (g_{i-1} + g_i)/2, ..., g_{s-1}/2 (REBOUND's sums, halved
    # exactly), and the times the positions reach before each kick
    drifts = np.empty(stages + 1)
    drifts[0] = 0.5 * gamma[0]
    for i in range(1, stages):
        drifts[i] = 0.5 * (gamma[i - 1] + gamma[i])
    drifts[stages] = 0.5 * gamma[stages - 1]
    cum = np.empty(stages)
    c = 0.0
    for i in range(stages):
        c += drifts[i]
        cum[i] = c

    mask = np.empty(n)
    fill_active_mask(mask, state.active, state.pinned, n)
    xi = np.zeros((dim, n), dtype=np.int64)
    vi = np.zeros((dim, n), dtype=np.int64)
    if status != OK:
        return status, xi, vi, mask, gamma, drifts, cum, ratio, sx, iv, sv, L
    # floats -> lattice (exact for a state already on it); refuse before writing anything
    for i in range(n):
        if mask[i] == 0.0:
            continue
        for k in range(dim):
            y = pos[k, i] * ix
            w = vel[k, i] * iv
            if not (math.isfinite(y) and math.isfinite(w)):
                return i, xi, vi, mask, gamma, drifts, cum, ratio, sx, iv, sv, L
            y = _round(y, truncate)
            w = _round(w, truncate)
            if not (abs(y) < LIMIT and abs(w) < LIMIT):
                return LATTICE_OVERFLOW, xi, vi, mask, gamma, drifts, cum, ratio, sx, iv, sv, L
            xi[k, i] = _wrap(np.int64(y), L) if L > 0 else np.int64(y)
            vi[k, i] = np.int64(w)
    _write(xi, vi, pos, vel, mask, n, sx, sv)
    return OK, xi, vi, mask, gamma, drifts, cum, ratio, sx, iv, sv, L


@jit(error_model="numpy", inline="always")
def _general(t, h, steps, state, model, work, xi, vi, mask, gamma, drifts, cum, ratio, sx, iv,
             sv, L, truncate):
    """``_steps_general`` with its scratch."""
    dim, n = xi.shape[0], state.n
    return _steps_general(t, h, steps, state, model, work, xi, vi,
                          np.empty((dim, n), dtype=np.int64), np.empty((dim, n), dtype=np.int64),
                          np.empty((dim, n)), mask, gamma, drifts, cum, ratio, sx, iv, sv, L,
                          truncate)


@jit(error_model="numpy")
def run_lattice(t, h, steps, state, model, work, order, kx, kv, truncate, fuse):
    """Validate, put the state on the lattice, and step by the fused path when ``fuse`` and
    the scene allows it, else by the general one."""
    status, xi, vi, mask, gamma, drifts, cum, ratio, sx, iv, sv, L = _prepare(
        state, order, kx, kv, truncate)
    if status != OK or steps <= 0:
        return t, h, 0, status
    if fuse and fused_gravity.applies(state, model):
        return _steps_fused(t, h, steps, state, model, xi, vi, gamma, drifts, ratio, sx, iv,
                            sv, truncate)
    return _general(t, h, steps, state, model, work, xi, vi, mask, gamma, drifts, cum, ratio,
                    sx, iv, sv, L, truncate)


@jit(error_model="numpy")
def run_lattice_general(t, h, steps, state, model, work, order, kx, kv, truncate):
    """``run_lattice`` by the general path alone: what a scene the fused path cannot take runs
    (chosen in Python by ``advance``), so that it never compiles the fused path."""
    status, xi, vi, mask, gamma, drifts, cum, ratio, sx, iv, sv, L = _prepare(
        state, order, kx, kv, truncate)
    if status != OK or steps <= 0:
        return t, h, 0, status
    return _general(t, h, steps, state, model, work, xi, vi, mask, gamma, drifts, cum, ratio,
                    sx, iv, sv, L, truncate)


def _fusable(model):
    """Can the fused path take this scene (one gravity term; ``fused_gravity.applies`` then
    decides the rest in compiled code)?"""
    return model.kinds.shape[0] == 1 and model.kinds[0] == gravity.KIND


def advance(t, h, steps, state, model, work, vdep, t_end, order, kx, kv):
    """``steps`` JANUS steps of order ``order`` on the lattice ``(2**-kx, 2**-kv)``, rounding to
    nearest; returns ``(t, h, done, status)`` (see the module's doc). ``t_end`` is ignored
    (fixed step); ``vdep`` changes nothing here (each kick evaluates the forces afresh, with
    the current velocities)."""
    if _fusable(model):
        return run_lattice(t, h, steps, state, model, work, order, kx, kv, False, True)
    return run_lattice_general(t, h, steps, state, model, work, order, kx, kv, False)


def advance_truncating(t, h, steps, state, model, work, vdep, t_end, order, kx, kv):
    """``advance`` with the rounding of REBOUND's JANUS (towards zero), for comparisons."""
    if _fusable(model):
        return run_lattice(t, h, steps, state, model, work, order, kx, kv, True, True)
    return run_lattice_general(t, h, steps, state, model, work, order, kx, kv, True)


__all__ = ["NAME", "ORDERS", "SCHEMES", "FORCE_EVALUATIONS", "LATTICE_OVERFLOW", "BAD_LATTICE",
           "BAD_ORDER", "HEADROOM_BITS", "LIMIT", "MAX_EXPONENT", "advance",
           "advance_truncating", "lattice_exponents", "on_lattice", "run_lattice",
           "run_lattice_general",
           "stage_coefficients"]
