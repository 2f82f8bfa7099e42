"""The built-in bots compiled: they decide inside the game's compiled call, for learning.

The Python bots in ``spacewar.bots`` (with ``spacewar.bots.geometry``) are the readable
reference; this module computes the same decisions from the game's arrays (``core``'s layout,
leading match axis) with no Python per frame, so that the opponents a learner trains against
can play thousands of matches per call (``spacewar.learning.step_learning``)::

    memory = new_memory(M)                 # (M, 2, MEMORY) float64, zeros = a fresh bot
    bot_rng = new_streams(M, seed)         # (M, 2) uint64, the random bot's own streams
    code = decide(KINDS["chaser"], m, seat, pos, vel, charge, active, ship_gauges,
                  ship_counters, torp_life, match_state, rules, memory, bot_rng)
    decide_all(kind, seat, ..., memory, bot_rng, codes)    # every match, codes[:, seat]
    reset_memory(m, seat, memory)          # a match restarted: the bot's reset()

**What a bot sees.** ``Game.observe`` gives a Python bot the raw arrays' own float64 values
(``core.write_observation``): positions, velocities, heading and turn rate, fuel, counters,
``star_mu = rules[R_STAR]`` (the *effective* mu: the heavy / light / none switch applied),
``star_capture = rules[R_CAPTURE]``, the round and round frame, the torpedoes present (own
slots first, in slot order, each with its frames to live) and ``obs.rules``, the game's
``Rules``. The compiled bots read exactly these from the arrays: the rules they use are the
rules vector's turn rate, angular acceleration and switch, thrust, launch offset, muzzle
speed, torpedo life, hit box and diamond, the star's capture radius, whether torpedoes feel
the star (``R_TORP_STAR``, the newtonian mode) and the electric mode.

**Memory** (``MEMORY`` floats per seat): ``[ESCAPING]`` the chaser's and sniper's star-escape
flag; the sniper's and dodger's enemy-thrust estimate ``[THRUST_X, THRUST_Y]`` and the enemy
seen last frame ``[HAS_LAST, LAST_ROUND, LAST_ROUND_FRAME, LAST_X, LAST_Y, LAST_VX, LAST_VY]``
(``Sniper.track``). Zeros are a fresh bot, as after ``reset()``.

**Same numbers, same decisions.** Every formula is the reference's, in the reference's order
of operations, so that a decision is the same bit for bit where the reference's arithmetic
can be reproduced:

* ``math.hypot`` in Python 3.8+ is not the C library's ``hypot``: it is CPython's own
  correctly-rounded-in-practice algorithm (``vector_norm`` in ``Modules/mathmodule.c``:
  scaling by a power of two, exact squares, a compensated sum and one differential
  correction of the square root). It differs from the C ``hypot`` (what numba's
  ``math.hypot`` and numpy's ``np.hypot`` call) in the last bit about 4 times in 10^5.
  :func:`py_hypot` re-implements CPython's algorithm; ``np.hypot`` in the reference
  (``lead_intercept``, the dodger's star pull) stays ``math.hypot`` here.
* numpy's ``a @ b`` of two 2-vectors goes to OpenBLAS's ``ddot``, whose kernel is chosen
  by CPU: on some (SkylakeX kernels) it computes ``fma(a1, b1, a0 b0)``, which a quarter of
  the time differs from ``a0 b0 + a1 b1`` in the last bit; on others (its Haswell kernel on
  an AMD EPYC) it computes the plain sum. ``engine.cache.numpy_dot_kind`` measures which at
  import, and :func:`dot_blas` is compiled to match (the fused form with LLVM's
  ``llvm.fma.f64``, correctly rounded everywhere); the game's compiled-code directory is
  named by the kind. On a machine with a third rounding, the plain sum is used and this
  mirror is off by one rounding there.
  Sums written with ``(a * b).sum(axis=1)`` or ``x * x + y * y`` stay plain.
* ``np.cos`` / ``np.sin`` of float64 agree with ``math.cos`` / ``math.sin`` (the C library)
  on this machine (checked on 2e5 angles); Python's ``%`` on floats and numpy's remainder
  agree with numba's ``%`` (all take the sign of the divisor); ``x ** 2`` of a Python float
  is ``pow(x, 2)``, taken here as ``x * x`` (the same value unless the C library's pow
  misrounds a square, not seen).
* The Kepler prediction calls the engine's compiled ``engine.analytic.kepler_step``, the very
  kernel ``geometry.predict_path`` reaches through ``engine.analytic.kepler``, time by time
  from the same start; its results are identical.
* ``argmin`` / ``argmax`` take the first of equal values, as numpy's; the dodger's
  ``sort`` of two escape directions is stable.

What is left: a ``NaN`` reaching a comparison (numpy's ``maximum`` keeps it where Python's
``max(0.0, nan)`` drops it); a Kepler point that is not finite (the reference then predicts
the whole path straight; here only the points computed are checked, see :func:`enemy_point`;
never seen); and the random bot, whose draws come from ``bot_rng`` (splitmix64,
``core.next_u64``), not numpy's PCG64: it has the reference's probabilities, not its exact
sequence. The agreement test (``tests/spacewar/test_compiled_bots.py``) measured 100% of
frames for the chaser, sniper and dodger.

**Cost.** idle, random and chaser allocate nothing (chaser: about 0.7-1 us a decision on one
thread here). The sniper and dodger need the enemy's predicted path, one Kepler solve
(about 1.7 us) per frame of a torpedo's life: its points are computed lazily and the scans
(lead, first hit, pending hit) skip the frames where a speed bound proves nothing can happen
(:func:`lead_intercept`), which leaves the decisions exactly the reference's and cuts the cost
about eightfold (to about 7-10 us a decision). :func:`decide` allocates one small scratch array
per call for them (``new_scratch``), :func:`decide_all` one per chunk of matches.
"""
import math
from fractions import Fraction

import numpy as np
from numba import prange
from numba.core import types
from numba.extending import intrinsic

from engine import space
from engine.cache import jit_disabled, numpy_dot_kind
from engine.analytic import kepler_step

from . import core
from .builtin_bots import NAMES

jit = core.jit

#: the compiled bots by name, as ``decide``'s ``kind`` (``spacewar.builtin_bots``' order)
KINDS = {name: k for k, name in enumerate(NAMES)}
IDLE, RANDOM, CHASER, SNIPER, DODGER = (KINDS[name] for name in
                                        ("idle", "random", "chaser", "sniper", "dodger"))

# memory per seat (see the module docstring)
(ESCAPING, THRUST_X, THRUST_Y, HAS_LAST, LAST_ROUND, LAST_ROUND_FRAME, LAST_X, LAST_Y, LAST_VX,
 LAST_VY, MEMORY) = range(11)

TWO_PI = 2.0 * math.pi
_NO_TIME = -1.0  # "None" for a time (all real times here are >= 1 frame)

# -- the reference bots' parameters (their constructors' defaults; a test holds them equal) --
RANDOM_PARAMS = {"thrust": 0.5, "fire": 0.2, "hyperspace": 0.002}
CHASER_PARAMS = {"q_min": 0.06, "fire_range": 0.24, "standoff": 0.1, "gain": 0.01,
                 "approach_speed": 1.6e-3, "retreat_speed": 8e-4, "nav_tolerance": 5e-4,
                 "burn_frames": 12, "aim_margin": 0.8, "fire_cone": math.radians(6.0),
                 "ram_distance": 0.04, "ram_horizon": 50, "max_speed": 1.6e-3,
                 "fuel_reserve": 250.0}
SNIPER_PARAMS = {"q_min": 0.08, "aim_shrink": 0.6, "shot_base": 35.0, "shot_per_torpedo": 1.8,
                 "shot_min": 40.0, "min_range": 0.1, "max_range": 0.3, "approach_speed": 1.0e-3,
                 "retreat_speed": 6e-4, "max_speed": 1.4e-3, "max_rel_speed": 1.6e-3,
                 "nav_tolerance": 4e-4, "burn_frames": 12, "fuel_reserve": 250.0, "gain": 0.01,
                 "thrust_smoothing": 0.1, "thrust_weight": 1.0}
DODGER_PARAMS = {"horizon": 80, "danger": 0.024, "clearance": 0.026, "hyper_frames": 4,
                 "thrust_cone": 1.0}

# numba freezes module globals into the machine code: plain floats, read once here
_P_THRUST, _P_FIRE, _P_HYPER = (RANDOM_PARAMS[k] for k in ("thrust", "fire", "hyperspace"))
(C_QMIN, C_FIRE_RANGE, C_STANDOFF, C_GAIN, C_APPROACH, C_RETREAT, C_NAV_TOL, C_BURN, C_AIM_MARGIN,
 C_FIRE_CONE, C_RAM_DIST, C_RAM_HORIZON, C_MAX_SPEED, C_FUEL_RESERVE) = CHASER_PARAMS.values()
(S_QMIN, S_AIM_SHRINK, S_SHOT_BASE, S_SHOT_PER_TORP, S_SHOT_MIN, S_MIN_RANGE, S_MAX_RANGE,
 S_APPROACH, S_RETREAT, S_MAX_SPEED, S_MAX_REL, S_NAV_TOL, S_BURN, S_FUEL_RESERVE, S_GAIN,
 S_SMOOTH, S_THRUST_WEIGHT) = SNIPER_PARAMS.values()
D_HORIZON, D_DANGER, D_CLEARANCE, D_HYPER_FRAMES, D_THRUST_CONE = DODGER_PARAMS.values()

NUMERIC = {"error_model": "numpy"}  # a zero division gives inf / nan as numpy would, no raise
DOT_FUSED = numpy_dot_kind() == "fused"  # how numpy's 2-vector dot rounds here (dot_blas)


# -- the reference's arithmetic ----------------------------------------------------------------
@intrinsic
def fma(typingctx, x, y, z):
    """``x y + z`` with one rounding (LLVM's ``llvm.fma.f64``)."""
    sig = types.float64(types.float64, types.float64, types.float64)

    def codegen(context, builder, signature, args):
        return builder.fma(args[0], args[1], args[2])
    return sig, codegen


if jit_disabled():  # the bots as plain Python (NUMBA_DISABLE_JIT=1, for tracing)
    def fma(x, y, z):  # noqa: F811 - an intrinsic cannot run in Python
        """``x y + z`` with one rounding: exact rationals, rounded once by int / int."""
        if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(z)):
            return x * y + z
        return float(Fraction(x) * Fraction(y) + Fraction(z))


@jit(inline="always", **NUMERIC)
def dot_blas(ax, ay, bx, by):
    """numpy's ``a @ b`` for 2-vectors as OpenBLAS's ddot computes it on this machine:
    ``fma(a1, b1, a0 b0)`` or ``a0 b0 + a1 b1`` (``DOT_FUSED``, a constant when compiled)."""
    if DOT_FUSED:
        return fma(ay, by, ax * bx)
    return ax * bx + ay * by


@jit(**NUMERIC)
def py_hypot(x, y):
    """Python's ``math.hypot(x, y)`` bit for bit: CPython's ``vector_norm`` for two numbers.

    With ``M = max(|x|, |y|) = m 2^e`` (frexp), the scaled ``x 2^-e`` are squared exactly
    (``hi + lo``, the low part by fma) and summed onto 1.0 with the rounding errors kept
    (``csum``, ``frac1``, ``frac2``); ``h = sqrt(sum)`` is then corrected once by
    ``(sum - h^2) / (2 h)`` (computed the same compensated way) and scaled back. Source:
    CPython 3.10+ ``Modules/mathmodule.c`` (R. Hettinger, after Borges, "An improved
    algorithm for hypot(a, b)", 2019). Subnormal inputs (never in this game) go to C's hypot.
    """
    ax = abs(x)
    ay = abs(y)
    if math.isinf(ax) or math.isinf(ay):
        return math.inf
    if math.isnan(ax) or math.isnan(ay):
        return math.nan
    big = ax if ax > ay else ay
    if big == 0.0:
        return big
    _, e = math.frexp(big)
    if e < -1021:
        return math.hypot(x, y)
    scale = math.ldexp(1.0, -e)
    csum = 1.0
    frac1 = 0.0
    frac2 = 0.0
    for v in (ax, ay):
        v = v * scale
        hi = v * v
        lo = fma(v, v, -hi)
        s = csum + hi  # fast two-sum: |csum| >= |hi|
        frac2 += (csum - s) + hi
        csum = s
        frac1 += lo
    h = math.sqrt(csum - 1.0 + (frac1 + frac2))
    hi = -h * h
    lo = fma(-h, h, -hi)
    s = csum + hi
    frac2 += (csum - s) + hi
    csum = s
    frac1 += lo
    r = csum - 1.0 + (frac1 + frac2)
    h += r / (2.0 * h)
    return h / scale


@jit(inline="always", **NUMERIC)
def wrap(x):
    """``geometry.wrap`` / ``torus_delta``: onto [-0.5, 0.5) (``engine.space``'s one wrap)."""
    return space.wrap_scalar(x, 1.0)


@jit(inline="always", **NUMERIC)
def angle_diff(target, heading):
    """``geometry.angle_diff``: target - heading wrapped to (-pi, pi]."""
    d = (target - heading + math.pi) % TWO_PI - math.pi
    return d if d != -math.pi else math.pi


@jit(inline="always")
def action(turn, thrust, fire, hyper, flip):
    """The action code: turn index (0, 1, 2 for -1, 0, +1) + 3 thrust + 6 fire + 12 hyperspace
    + 24 flip (``spacewar.codes``)."""
    return (turn + 1) + 3 * int(thrust) + 6 * int(fire) + 12 * int(hyper) + 24 * int(flip)


# -- steering -----------------------------------------------------------------------------------
@jit(**NUMERIC)
def steer(heading, omega, target, rules):
    """``geometry.steer``: -1, 0 or +1. Without the angular-momentum switch the heading moves
    ``turn_rate`` a frame: turn unless within half of it (``turn_towards``). With it, aim for
    ``w* = sign(e) min(sqrt(2 alpha |e|), 4 turn_rate)`` and press the key moving w towards w*."""
    err = angle_diff(target, heading)
    if rules[core.R_ANG_MOM] == 0.0:
        if abs(err) <= 0.5 * rules[core.R_TURN]:
            return 0
        return 1 if err > 0 else -1
    alpha = rules[core.R_ANG_ACCEL]
    w_star = math.copysign(min(math.sqrt(2.0 * alpha * abs(err)), 4.0 * rules[core.R_TURN]), err)
    if omega < w_star - 0.5 * alpha:
        return 1
    if omega > w_star + 0.5 * alpha:
        return -1
    return 0


@jit(inline="always", **NUMERIC)
def heading_after(heading, omega, turn, rules):
    """``geometry.heading_after``: the heading once this frame's turn is applied (unwrapped)."""
    if rules[core.R_ANG_MOM] != 0.0:
        limit = 4.0 * rules[core.R_TURN]
        w = min(limit, max(-limit, omega + turn * rules[core.R_ANG_ACCEL]))
        return heading + w
    return heading + turn * rules[core.R_TURN]


# -- the star -----------------------------------------------------------------------------------
@jit(inline="always", **NUMERIC)
def star_accel(x, y, mu, capture):
    """``geometry.star_accel``: -mu p / (|p|^2 + eps^2)^(3/2), eps = capture / 2."""
    if mu <= 0.0:
        return 0.0, 0.0
    eps = 0.5 * capture
    r2 = (x * x + y * y) + eps * eps
    den = r2 * math.sqrt(r2)
    return (-mu * x) / den, (-mu * y) / den


@jit(inline="always")
def ship_motion(m, s, pos, vel):
    """Ship s's position and velocity in match m, as four floats."""
    return pos[m, 0, s], pos[m, 1, s], vel[m, 0, s], vel[m, 1, s]


@jit(inline="always", **NUMERIC)
def periapsis_r(x, y, r, vx, vy, mu):
    """``geometry.periapsis`` with ``r = |p|`` given (``mu > 0``, ``r > 0``): ``h = x v_y - y v_x``,
    ``E = |v|^2/2 - mu/r``, ``e = sqrt(1 + 2 E h^2 / mu^2)``, ``q = h^2 / (mu (1 + e))``; an unbound
    ship moving away never comes closer than r (Bate, Mueller & White 1971, ch. 1-2)."""
    h = x * vy - y * vx
    energy = 0.5 * (vx * vx + vy * vy) - mu / r
    if energy >= 0.0 and x * vx + y * vy > 0.0:
        return r
    e = math.sqrt(max(0.0, 1.0 + 2.0 * energy * h * h / (mu * mu)))
    return h * h / (mu * (1.0 + e))


@jit(**NUMERIC)
def periapsis(x, y, vx, vy, mu):
    """``geometry.periapsis`` for one velocity: +inf without a star, 0 at the star."""
    if mu <= 0.0:
        return math.inf
    r = py_hypot(x, y)
    if r == 0.0:
        return 0.0
    return periapsis_r(x, y, r, vx, vy, mu)


@jit(**NUMERIC)
def safest_heading(x, y, vx, vy, mu, heading, dv):
    """``geometry.safest_heading`` (n = 32, slack 0.9): of the burn directions ``heading +
    k 2 pi / 32`` (offsets past pi taken negative), the one nearest the heading among those whose
    periapsis after a velocity change ``dv`` is within 0.9 of the best. Two passes (the best q,
    then the choice) instead of arrays."""
    n = 32
    step = TWO_PI / n
    r = py_hypot(x, y)
    qmax = -math.inf
    for k in range(n):
        off = k * step
        if off > math.pi:
            off = off - TWO_PI
        a = heading + off
        if r == 0.0:
            q = 0.0
        else:
            q = periapsis_r(x, y, r, vx + dv * math.cos(a), vy + dv * math.sin(a), mu)
        if q > qmax or (k == 0 and not q <= qmax):
            qmax = q
    best = -1
    best_cost = math.inf
    for k in range(n):
        off = k * step
        if off > math.pi:
            off = off - TWO_PI
        if abs(off) >= best_cost:
            continue
        a = heading + off
        if r == 0.0:
            q = 0.0
        else:
            q = periapsis_r(x, y, r, vx + dv * math.cos(a), vy + dv * math.sin(a), mu)
        if q >= 0.9 * qmax:
            best = k
            best_cost = abs(off)
    if best < 0:
        best = 0  # numpy's argmin of all-inf: the first
    off = best * step
    if off > math.pi:
        off = off - TWO_PI
    return heading + off


@jit(**NUMERIC)
def safe_heading_near(x, y, vx, vy, mu, desired, dv, q_min, heading):
    """``geometry.safe_heading_near`` (n = 36, turn weight 0.5): of the directions ``desired +
    j 2 pi / 36`` in the order j = 0, +1, -1, +2, ..., the one whose burn keeps the periapsis
    >= q_min with the least ``|offset| + 0.5 |turn from heading|``; (angle, True), or the highest
    periapsis and False when none is safe. The offsets only grow along that order and the cost is
    at least the offset, so the scan stops once the offset reaches the best cost (numpy's argmin
    keeps the first of equal costs, so nothing later could win)."""
    if mu <= 0.0:
        return desired, True
    n = 36
    step = TWO_PI / n
    r = py_hypot(x, y)
    best = -1
    best_cost = math.inf
    top = -1
    top_q = -math.inf
    for k in range(n):
        j = (k + 1) // 2 if k % 2 == 1 else -(k // 2)
        off = j * step
        if best >= 0 and abs(off) >= best_cost:
            break
        a = desired + off
        if r == 0.0:
            q = 0.0
        else:
            q = periapsis_r(x, y, r, vx + dv * math.cos(a), vy + dv * math.sin(a), mu)
        if q >= q_min:
            cost = abs(off) + 0.5 * abs((a - heading + math.pi) % TWO_PI - math.pi)
            if cost < best_cost:
                best = k
                best_cost = cost
        if q > top_q or top < 0:
            top = k
            top_q = q
    k = best if best >= 0 else top
    j = (k + 1) // 2 if k % 2 == 1 else -(k // 2)
    return desired + j * step, best >= 0


# -- the bots ---------------------------------------------------------------------------------
def new_memory(matches):
    """Fresh memory for ``matches`` matches: float64 (M, 2, MEMORY), zeros = a fresh bot."""
    return np.zeros((int(matches), 2, MEMORY))


def new_streams(matches, seed=0):
    """The random bot's per-seat splitmix64 states, (M, 2) uint64, from an int seed
    (numpy's SeedSequence, as ``game.seed_state``)."""
    return np.random.SeedSequence(int(seed)).generate_state(2 * int(matches), np.uint64) \
        .reshape(int(matches), 2)


@jit()
def reset_memory(m, seat, memory):
    """Seat ``seat``'s bot of match ``m`` as new (the Python bots' ``reset()``). Its random
    stream ``bot_rng[m, seat]`` is the caller's to set."""
    for k in range(memory.shape[2]):
        memory[m, seat, k] = 0.0


@jit(**NUMERIC)
def random_code(m, seat, bot_rng):
    """``RandomBot``: turn uniform in {-1, 0, 1} (``int(3 u) - 1``), thrust with p = 0.5, fire
    with p = 0.2, hyperspace with p = 0.002, from four draws of the seat's own stream."""
    row = bot_rng[m]
    turn = int(core.uniform(row, seat) * 3.0) - 1
    thrust = core.uniform(row, seat) < _P_THRUST
    fire = core.uniform(row, seat) < _P_FIRE
    hyper = core.uniform(row, seat) < _P_HYPER
    return action(turn, thrust, fire, hyper, False)


@jit(**NUMERIC)
def lead_straight(dx, dy, wx, wy, offset, speed):
    """``geometry.lead_straight``: the smallest t > 0 with ``|d + w t| = offset + speed t``
    (``(w.w - s^2) t^2 + 2 (d.w - offset s) t + (d.d - offset^2) = 0``) and the heading of
    ``d + w t``; ``(_NO_TIME, 0)`` when there is none. The dot products are numpy's (BLAS)."""
    a = dot_blas(wx, wy, wx, wy) - speed * speed
    b = 2.0 * (dot_blas(dx, dy, wx, wy) - offset * speed)
    c = dot_blas(dx, dy, dx, dy) - offset * offset
    t = math.inf
    if abs(a) < 1e-18:
        if b != 0.0:
            t0 = -c / b
            if t0 > 0.0:
                t = t0
    else:
        disc = b * b - 4.0 * a * c
        if disc < 0.0:
            return _NO_TIME, 0.0
        sq = math.sqrt(disc)
        t1 = (-b - sq) / (2.0 * a)
        t2 = (-b + sq) / (2.0 * a)
        if t1 > 0.0:
            t = t1
        if t2 > 0.0 and t2 < t:
            t = t2
    if t == math.inf:
        return _NO_TIME, 0.0
    return t, math.atan2(dy + wy * t, dx + wx * t)


@jit(**NUMERIC)
def chaser_aim(m, me, en, pos, vel, rules, dx, dy):
    """``Chaser._aim``: the straight-line lead if it meets within a torpedo's life, else the
    direction to the enemy (``d`` = nearest image from me to the enemy)."""
    t, lead = lead_straight(dx, dy, vel[m, 0, en] - vel[m, 0, me], vel[m, 1, en] - vel[m, 1, me],
                            rules[core.R_OFFSET], rules[core.R_MUZZLE])
    if t != _NO_TIME and t < rules[core.R_TLIFE]:
        return lead
    return math.atan2(dy, dx)


@jit(**NUMERIC)
def chaser_fire(m, me, en, pos, vel, ship_gauges, ship_counters, rules, turn, aim, have_aim):
    """``Chaser._fire``: the enemy visible within ``fire_range`` and the heading after this
    frame's turn within ``min(fire_cone, atan2(aim_margin hit_box, distance))`` of the aim."""
    if (ship_counters[m, en, core.ALIVE] == 0 or ship_counters[m, en, core.IN_HYPER] == 1
            or ship_counters[m, me, core.TORPS] <= 0 or ship_counters[m, me, core.RELOAD] > 0):
        return False
    dx = wrap(pos[m, 0, en] - pos[m, 0, me])
    dy = wrap(pos[m, 1, en] - pos[m, 1, me])
    dist = py_hypot(dx, dy)
    if dist > C_FIRE_RANGE:
        return False
    if not have_aim:
        aim = chaser_aim(m, me, en, pos, vel, rules, dx, dy)
    cone = min(C_FIRE_CONE, math.atan2(C_AIM_MARGIN * rules[core.R_HITBOX], dist))
    after = heading_after(ship_gauges[m, me, core.HEADING], ship_gauges[m, me, core.OMEGA], turn,
                          rules)
    return abs(angle_diff(aim, after)) < cone


@jit(**NUMERIC)
def ram_escape(dx, dy, wx, wy, distance, horizon):
    """``geometry.ram_escape``: the unit direction widening a closest approach nearer than
    ``distance`` within ``horizon`` frames (``-c / |c|``, or a normal of w when head-on), else
    (0, 0, False). d: the other body relative to me, w: its velocity relative to me."""
    ww = wx * wx + wy * wy
    if ww < 1e-14:
        return 0.0, 0.0, False
    t = -(dx * wx + dy * wy) / ww
    if t < 0.0 or t > horizon:
        return 0.0, 0.0, False
    cx = dx + t * wx
    cy = dy + t * wy
    cn = py_hypot(cx, cy)
    if cn >= distance:
        return 0.0, 0.0, False
    if cn < 1e-6:
        root = math.sqrt(ww)
        return -wy / root, wx / root, True
    return -cx / cn, -cy / cn, True


@jit(**NUMERIC)
def chaser(m, seat, pos, vel, ship_gauges, ship_counters, rules, memory):
    """``Chaser.act`` (see its docstring): 1. the star (escape burn while the periapsis is low),
    2. pursuit (burn towards the wanted velocity along a safe direction), 3. attack."""
    me = seat
    en = 1 - seat
    if ship_counters[m, me, core.ALIVE] == 0 or ship_counters[m, me, core.IN_HYPER] == 1:
        return core.NOOP
    x, y, vx, vy = ship_motion(m, me, pos, vel)
    heading = ship_gauges[m, me, core.HEADING]
    omega = ship_gauges[m, me, core.OMEGA]
    mu = rules[core.R_STAR]
    dv = rules[core.R_THRUST] * C_BURN
    # 1. the star
    if mu > 0.0:
        q = periapsis(x, y, vx, vy, mu)
        limit = C_QMIN * (1.5 if memory[m, seat, ESCAPING] != 0.0 else 1.0)
        if q < limit:
            memory[m, seat, ESCAPING] = 1.0
            target = safest_heading(x, y, vx, vy, mu, heading, dv)
            turn = steer(heading, omega, target, rules)
            thrust = abs(angle_diff(target, heading)) < 0.8
            fire = chaser_fire(m, me, en, pos, vel, ship_gauges, ship_counters, rules, turn, 0.0,
                               False)
            return action(turn, thrust, fire, False, False)
        memory[m, seat, ESCAPING] = 0.0
    if ship_counters[m, en, core.ALIVE] == 0 or ship_counters[m, en, core.IN_HYPER] == 1:
        return core.NOOP
    # 2. pursuit
    evx = vel[m, 0, en]
    evy = vel[m, 1, en]
    dx = wrap(pos[m, 0, en] - x)
    dy = wrap(pos[m, 1, en] - y)
    dist = py_hypot(dx, dy)
    ux = dx / max(dist, 1e-12)
    uy = dy / max(dist, 1e-12)
    closing = min(max(C_GAIN * (dist - C_STANDOFF), -C_RETREAT), C_APPROACH)
    wantx = evx + closing * ux
    wanty = evy + closing * uy
    speed = py_hypot(wantx, wanty)
    if speed > C_MAX_SPEED:
        f = C_MAX_SPEED / speed
        wantx = wantx * f
        wanty = wanty * f
    corrx = wantx - vx
    corry = wanty - vy
    sx, sy, dodge = ram_escape(dx, dy, -(vx - evx), -(vy - evy), C_RAM_DIST, C_RAM_HORIZON)
    if dodge:
        corrx = sx * C_APPROACH
        corry = sy * C_APPROACH
    aim = chaser_aim(m, me, en, pos, vel, rules, dx, dy)
    if py_hypot(corrx, corry) > C_NAV_TOL and ship_gauges[m, me, core.FUEL] > C_FUEL_RESERVE:
        want = math.atan2(corry, corrx)
        nav, safe = safe_heading_near(x, y, vx, vy, mu, want, dv, C_QMIN * 1.3, heading)
        turn = steer(heading, omega, nav, rules)
        thrust = safe and abs(angle_diff(nav, heading)) < 0.35
        fire = chaser_fire(m, me, en, pos, vel, ship_gauges, ship_counters, rules, turn, aim, True)
        return action(turn, thrust, fire, False, False)
    # 3. attack
    turn = steer(heading, omega, aim, rules)
    fire = chaser_fire(m, me, en, pos, vel, ship_gauges, ship_counters, rules, turn, aim, True)
    return action(turn, False, fire, False, False)


# -- prediction (the sniper's and dodger's) -------------------------------------------------------
# Scratch of a sniper's or dodger's decision, rows of (x, y), with n = torpedo_life - 1:
# [0, n) the enemy's path, [n, 2n) its own, [2n, 3n) a torpedo's, [3n, 4n) which points of the
# enemy's path are computed yet (column 0), [4n, 4n + 4) the enemy path's Kepler start (r0, v0,
# a spare output, then its speed bound and mode), the last 3 the other paths' Kepler vectors.
@jit()
def new_scratch(rules):
    """The scratch of one sniper or dodger decision (see the layout above)."""
    n = max(int(rules[core.R_TLIFE]) - 1, 1)
    return np.empty((4 * n + 7, 2))


@jit(**NUMERIC)
def predict_path(x, y, vx, vy, mu, capture, n, path, at, scratch):
    """``geometry.predict_path`` at times 1 .. n into ``path[at:at + n]``, unwrapped: with a star
    the Kepler conic about the origin (``engine.analytic.kepler_step``, each time from the start)
    started from ``v + a(p) / 2`` (the velocity the game stores is half a frame behind the
    position); else, or when any Kepler point is not finite, the straight ``p + v t``."""
    if mu > 0.0 and (x != 0.0 or y != 0.0):
        ax, ay = star_accel(x, y, mu, capture)
        base = scratch.shape[0] - 3
        r0 = scratch[base]
        v0 = scratch[base + 1]
        v_out = scratch[base + 2]
        r0[0] = x
        r0[1] = y
        v0[0] = vx + 0.5 * ax
        v0[1] = vy + 0.5 * ay
        finite = True
        for k in range(n):
            row = path[at + k]
            kepler_step(r0, v0, mu, k + 1.0, row, v_out)
            if not (math.isfinite(row[0]) and math.isfinite(row[1])):
                finite = False
        if finite:
            return
    for k in range(n):
        t = k + 1.0
        path[at + k, 0] = x + t * vx
        path[at + k, 1] = y + t * vy


@jit(**NUMERIC)
def track(m, seat, pos, vel, ship_counters, match_state, rules, memory):
    """``Sniper.track``: the enemy's own thrust ``a = v' - v - a_star(p)`` between consecutive
    frames of a round, averaged with weight ``thrust_smoothing``; zero whenever the enemy was not
    visible on both; a jump above ``4 thrust`` (a wrap glitch, a collision) is ignored."""
    en = 1 - seat
    mem = memory[m, seat]
    visible = ship_counters[m, en, core.ALIVE] == 1 and ship_counters[m, en, core.IN_HYPER] == 0
    rnd = float(match_state[m, core.ROUNDS_PLAYED])
    frame = float(match_state[m, core.ROUND_FRAME])
    had = mem[HAS_LAST] != 0.0
    prev_round = mem[LAST_ROUND]
    prev_frame = mem[LAST_ROUND_FRAME]
    px = mem[LAST_X]
    py = mem[LAST_Y]
    pvx = mem[LAST_VX]
    pvy = mem[LAST_VY]
    mem[HAS_LAST] = 1.0 if visible else 0.0
    if visible:
        mem[LAST_ROUND] = rnd
        mem[LAST_ROUND_FRAME] = frame
        mem[LAST_X] = pos[m, 0, en]
        mem[LAST_Y] = pos[m, 1, en]
        mem[LAST_VX] = vel[m, 0, en]
        mem[LAST_VY] = vel[m, 1, en]
    if not visible or not had or prev_round != rnd or prev_frame + 1.0 != frame:
        mem[THRUST_X] = 0.0
        mem[THRUST_Y] = 0.0
        return
    gx, gy = star_accel(px, py, rules[core.R_STAR], rules[core.R_CAPTURE])
    ax = (vel[m, 0, en] - pvx) - gx
    ay = (vel[m, 1, en] - pvy) - gy
    if py_hypot(ax, ay) > 4.0 * rules[core.R_THRUST] + 1e-12:
        return
    k = S_SMOOTH
    mem[THRUST_X] = (1.0 - k) * mem[THRUST_X] + k * ax
    mem[THRUST_Y] = (1.0 - k) * mem[THRUST_Y] + k * ay


@jit(**NUMERIC)
def enemy_path(m, seat, pos, vel, rules, memory, n, scratch):
    """``Sniper.enemy_path``, made lazy: sets up the enemy's path ``scratch[0:n]`` (the coasting
    conic plus ``thrust_weight a t^2 / 2`` for the estimated mean thrust a), whose points
    :func:`enemy_point` computes when first asked for; each is the reference's to the bit.

    It also bounds the path's speed, so that the scans can skip frames that cannot matter:
    on the conic ``|v|^2 = |v0|^2 + 2 mu (1/r - 1/r0)`` (energy) and ``r >= q`` (periapsis), so
    ``|v| <= sqrt(|v0|^2 + 2 mu (1/q - 1/r0))``, plus ``thrust_weight |a| n`` for the thrust term
    (widened by 1e-6 relative for rounding)."""
    en = 1 - seat
    x = pos[m, 0, en]
    y = pos[m, 1, en]
    vx = vel[m, 0, en]
    vy = vel[m, 1, en]
    mu = rules[core.R_STAR]
    for k in range(n):
        scratch[3 * n + k, 0] = 0.0
    tx = memory[m, seat, THRUST_X]
    ty = memory[m, seat, THRUST_Y]
    extra = S_THRUST_WEIGHT * math.sqrt(tx * tx + ty * ty) * n
    e = 4 * n
    if mu > 0.0 and (x != 0.0 or y != 0.0):
        ax, ay = star_accel(x, y, mu, rules[core.R_CAPTURE])
        scratch[e, 0] = x
        scratch[e, 1] = y
        scratch[e + 1, 0] = vx + 0.5 * ax
        scratch[e + 1, 1] = vy + 0.5 * ay
        v0x = scratch[e + 1, 0]
        v0y = scratch[e + 1, 1]
        r0 = math.sqrt(x * x + y * y)
        q = periapsis_r(x, y, r0, v0x, v0y, mu)
        v2 = v0x * v0x + v0y * v0y
        if q > 1e-9:
            v2 += 2.0 * mu * max(0.0, 1.0 / (q * (1.0 - 1e-6)) - 1.0 / (r0 * (1.0 + 1e-6)))
            bound = math.sqrt(v2)
        else:
            bound = math.inf
        scratch[e + 3, 0] = max(bound, math.sqrt(vx * vx + vy * vy)) * (1.0 + 1e-6) + extra
        scratch[e + 3, 1] = 1.0  # Kepler
    else:
        scratch[e + 3, 0] = math.sqrt(vx * vx + vy * vy) * (1.0 + 1e-6) + extra
        scratch[e + 3, 1] = 0.0  # straight
        straight_enemy(m, seat, pos, vel, memory, n, scratch)


@jit(**NUMERIC)
def straight_enemy(m, seat, pos, vel, memory, n, scratch):
    """The whole enemy path straight, ``p + v t`` plus the thrust term (``predict_path``'s
    fallback, also when a Kepler point is not finite), every point marked computed."""
    en = 1 - seat
    for k in range(n):
        t = k + 1.0
        scratch[k, 0] = pos[m, 0, en] + t * vel[m, 0, en]
        scratch[k, 1] = pos[m, 1, en] + t * vel[m, 1, en]
        add_thrust(m, seat, memory, k, scratch)
        scratch[3 * n + k, 0] = 1.0
    scratch[4 * n + 3, 1] = 0.0


@jit(inline="always", **NUMERIC)
def add_thrust(m, seat, memory, k, scratch):
    """``path + (0.5 thrust_weight) t^2 a`` at point k, as ``Sniper.enemy_path`` (when a != 0)."""
    tx = memory[m, seat, THRUST_X]
    ty = memory[m, seat, THRUST_Y]
    if S_THRUST_WEIGHT > 0.0 and (tx != 0.0 or ty != 0.0):
        t = k + 1.0
        w = (0.5 * S_THRUST_WEIGHT) * (t * t)
        scratch[k, 0] = scratch[k, 0] + w * tx
        scratch[k, 1] = scratch[k, 1] + w * ty


@jit(**NUMERIC)
def enemy_point(k, m, seat, pos, vel, rules, memory, n, scratch):
    """Point k (time k + 1) of the enemy's path, computed on first use by the engine's
    ``kepler_step`` from the start set by :func:`enemy_path`. A point that is not finite turns
    the whole path straight, as ``predict_path`` does (the reference checks every point; this
    only those it computes: the one place where the two could part, never seen)."""
    if scratch[3 * n + k, 0] == 0.0:
        e = 4 * n
        row = scratch[k]
        kepler_step(scratch[e], scratch[e + 1], rules[core.R_STAR], k + 1.0, row, scratch[e + 2])
        if not (math.isfinite(row[0]) and math.isfinite(row[1])):
            straight_enemy(m, seat, pos, vel, memory, n, scratch)
        else:
            add_thrust(m, seat, memory, k, scratch)
            scratch[3 * n + k, 0] = 1.0
    return scratch[k, 0], scratch[k, 1]


@jit(**NUMERIC)
def lead_f(i, m, seat, pos, vel, rules, memory, n, scratch, shift_x, shift_y):
    """``lead_intercept``'s ``f(t) = |D(t)| - offset - speed t`` and ``D(t) = wrap(E(t) - shift -
    p - v t)`` at point i (t = i + 1), p and v the shooter's (np.hypot: the C library's)."""
    t = i + 1.0
    ex, ey = enemy_point(i, m, seat, pos, vel, rules, memory, n, scratch)
    dx = wrap((ex - shift_x) - (pos[m, 0, seat] + t * vel[m, 0, seat]))
    dy = wrap((ey - shift_y) - (pos[m, 1, seat] + t * vel[m, 1, seat]))
    return math.hypot(dx, dy) - (rules[core.R_OFFSET] + rules[core.R_MUZZLE] * t), dx, dy


@jit(**NUMERIC)
def lead_intercept(m, seat, pos, vel, rules, memory, n, scratch, shift_x, shift_y):
    """``geometry.lead_intercept`` against the enemy path minus ``shift``: the first sampled t
    where ``f(t) = |D(t)| - offset - speed t <= 0`` (see :func:`lead_f`), refined by linear
    interpolation with the point before; returns (t, heading of D(t)) or (_NO_TIME, 0).

    f falls by at most ``V + |v| + speed`` a frame (V the enemy path's speed bound, |v| the
    shooter's drift; |D| is a torus distance, 1-Lipschitz), so after a point with f > 0 the
    next ``ceil(f / (V + |v| + speed))`` - 1 frames have f > 0 too and are not computed; the
    first root, and the point before it, are the reference's."""
    rate = (scratch[4 * n + 3, 0] + math.sqrt(vel[m, 0, seat] ** 2 + vel[m, 1, seat] ** 2)
            + rules[core.R_MUZZLE]) * (1.0 + 1e-6)
    i = 0
    while i < n:
        f, dx, dy = lead_f(i, m, seat, pos, vel, rules, memory, n, scratch, shift_x, shift_y)
        if f <= 0.0:
            if i == 0:
                return 1.0, math.atan2(dy, dx)
            fp, dpx, dpy = lead_f(i - 1, m, seat, pos, vel, rules, memory, n, scratch, shift_x,
                                  shift_y)
            t = i + 1.0
            frac = fp / (fp - f)
            tt = (t - 1.0) + frac * (t - (t - 1.0))
            return tt, math.atan2(dpy + frac * (dy - dpy), dpx + frac * (dx - dpx))
        i += max(1, skip_frames(f - 1e-12, rate))
    return _NO_TIME, 0.0


@jit(inline="always", **NUMERIC)
def skip_frames(margin, rate):
    """Frames to the next one at which a quantity now ``margin`` above its threshold, falling
    at most ``rate`` a frame, can reach it: ``ceil(margin / rate)`` (1 if unbounded)."""
    if not (rate < math.inf) or not (margin > 0.0) or rate <= 0.0:
        return 1
    steps = margin / rate
    if steps > 1e6:
        return 1000000
    return int(math.ceil(steps))


@jit(**NUMERIC)
def launch_state(x, y, vx, vy, heading, rules):
    """``geometry.launch_state``: a torpedo fired on ``heading`` starts at ``p + offset u`` with
    ``v + muzzle u`` (u the heading's unit vector; unwrapped, as the reference)."""
    c = math.cos(heading)
    s = math.sin(heading)
    return (x + rules[core.R_OFFSET] * c, y + rules[core.R_OFFSET] * s,
            vx + rules[core.R_MUZZLE] * c, vy + rules[core.R_MUZZLE] * s)


@jit(inline="always", **NUMERIC)
def diamond(rx, ry, box, dia):
    """The game's hit test on a nearest-image relative position (``geometry.diamond_hits``)."""
    ax = abs(rx)
    ay = abs(ry)
    return ax < box and ay < box and ax + ay < dia


@jit(**NUMERIC)
def torpedo_path(p0x, p0y, v0x, v0y, rules, mu, n, scratch):
    """``geometry.torpedo_path`` at 1 .. n into ``scratch[2n:3n]`` when torpedoes feel the star
    (a Kepler conic); False when they fly straight (``p0 + v0 t``, computed where needed)."""
    if mu > 0.0 and rules[core.R_TORP_STAR] != 0.0:
        predict_path(p0x, p0y, v0x, v0y, mu, rules[core.R_CAPTURE], n, scratch, 2 * n, scratch)
        return True
    return False


@jit(**NUMERIC)
def first_hit(m, seat, pos, vel, rules, memory, n, scratch, p0x, p0y, v0x, v0y, shrink, t_max):
    """``geometry.first_hit`` up to ``t_max``: the first t in 1 .. min(n, t_max) at which the
    torpedo launched from (p0, v0) meets the enemy path by the diamond test scaled by ``shrink``,
    or _NO_TIME (a later hit is no shot for the sniper anyway). A straight torpedo is compared
    only at frames where the torus distance max(|dx|, |dy|) can have fallen below the box (it
    falls at most ``V + |v0|`` a frame, see :func:`lead_intercept`)."""
    box = shrink * rules[core.R_HITBOX]
    dia = shrink * rules[core.R_DIAMOND]
    mu = rules[core.R_STAR]
    curved = torpedo_path(p0x, p0y, v0x, v0y, rules, mu, n, scratch)
    rate = (scratch[4 * n + 3, 0] + math.sqrt(v0x * v0x + v0y * v0y)) * (1.0 + 1e-6)
    k = 0
    while k < n and k + 1.0 <= t_max:
        t = k + 1.0
        if curved:
            tx = scratch[2 * n + k, 0]
            ty = scratch[2 * n + k, 1]
        else:
            tx = p0x + t * v0x
            ty = p0y + t * v0y
        ex, ey = enemy_point(k, m, seat, pos, vel, rules, memory, n, scratch)
        rx = wrap(ex - tx)
        ry = wrap(ey - ty)
        if diamond(rx, ry, box, dia):
            return t
        k += 1 if curved else max(1, skip_frames(max(abs(rx), abs(ry)) - box - 1e-12, rate))
    return _NO_TIME


@jit(**NUMERIC)
def shot_time(m, me, ship_counters, rules):
    """``Sniper.shot_time``: ``clip(base + per_torpedo torpedoes, min(shot_min, life), life)``,
    life = torpedo_life - 1."""
    life = float(int(rules[core.R_TLIFE]) - 1)
    x = S_SHOT_BASE + S_SHOT_PER_TORP * ship_counters[m, me, core.TORPS]
    return min(max(x, min(S_SHOT_MIN, life)), life)


@jit(**NUMERIC)
def pending_hit(m, seat, pos, vel, active, torp_life, rules, memory, n, scratch):
    """``Sniper.pending_hit``: one of my torpedoes in flight, flying straight, meets the enemy
    path by the (full) diamond test before it bursts (frames skipped as in :func:`first_hit`)."""
    ntorp = torp_life.shape[1] // 2
    box = rules[core.R_HITBOX]
    dia = rules[core.R_DIAMOND]
    for j in range(ntorp):
        b = 2 + seat * ntorp + j
        if not active[m, b]:
            continue
        ttl = float(torp_life[m, seat * ntorp + j])
        px = pos[m, 0, b]
        py = pos[m, 1, b]
        tvx = vel[m, 0, b]
        tvy = vel[m, 1, b]
        rate = (scratch[4 * n + 3, 0] + math.sqrt(tvx * tvx + tvy * tvy)) * (1.0 + 1e-6)
        k = 0
        while k < n and k + 1.0 < ttl:
            t = k + 1.0
            ex, ey = enemy_point(k, m, seat, pos, vel, rules, memory, n, scratch)
            rx = wrap(ex - (px + t * tvx))
            ry = wrap(ey - (py + t * tvy))
            if diamond(rx, ry, box, dia):
                return True
            k += max(1, skip_frames(max(abs(rx), abs(ry)) - box - 1e-12, rate))
    return False


@jit(**NUMERIC)
def fire_ok(m, seat, pos, vel, active, ship_gauges, ship_counters, torp_life, rules, memory,
            turn, have_path, n, scratch):
    """``Sniper.fire_ok``: a predicted hit (hit box shrunk by ``aim_shrink``) within
    ``shot_time`` on the heading after this frame's turn, the enemy not falling into the star
    before (``doomed_before``) and none of my torpedoes already on its way to hit."""
    me = seat
    en = 1 - seat
    if (ship_counters[m, me, core.TORPS] <= 0 or ship_counters[m, me, core.RELOAD] > 0
            or ship_counters[m, en, core.ALIVE] == 0 or ship_counters[m, en, core.IN_HYPER] == 1
            or not have_path):
        return False
    mu = rules[core.R_STAR]
    h = heading_after(ship_gauges[m, me, core.HEADING], ship_gauges[m, me, core.OMEGA], turn, rules)
    p0x, p0y, v0x, v0y = launch_state(pos[m, 0, me], pos[m, 1, me], vel[m, 0, me], vel[m, 1, me],
                                      h, rules)
    longest = shot_time(m, me, ship_counters, rules)
    t = first_hit(m, seat, pos, vel, rules, memory, n, scratch, p0x, p0y, v0x, v0y, S_AIM_SHRINK,
                  longest)
    if t == _NO_TIME or t > longest:
        return False
    if mu > 0.0:  # doomed_before: the coasting enemy within 1.2 capture radii within t frames
        k_end = max(1, min(int(math.ceil(t)), n))
        lim = 1.2 * rules[core.R_CAPTURE]
        lim2 = lim * lim
        for k in range(k_end):
            ex, ey = enemy_point(k, m, seat, pos, vel, rules, memory, n, scratch)
            if ex * ex + ey * ey < lim2:
                return False
    return not pending_hit(m, seat, pos, vel, active, torp_life, rules, memory, n, scratch)


@jit(**NUMERIC)
def solve(m, seat, pos, vel, rules, memory, n, scratch):
    """``Sniper.solve``: the lead against the enemy path; where torpedoes feel the star the aim
    point is shifted twice by a Kepler torpedo's miss at the meeting frame. (t, heading)."""
    me = seat
    x, y, vx, vy = ship_motion(m, me, pos, vel)
    mu = rules[core.R_STAR]
    t, h = lead_intercept(m, seat, pos, vel, rules, memory, n, scratch, 0.0, 0.0)
    if t == _NO_TIME or not (rules[core.R_TORP_STAR] != 0.0 and mu > 0.0):
        return t, h
    shx = 0.0
    shy = 0.0
    for _ in range(2):
        p0x, p0y, v0x, v0y = launch_state(x, y, vx, vy, h, rules)
        k = max(min(int(round(t)) - 1, n - 1), 0)
        tk = k + 1.0
        # the reference's torpedo_path at the one time tk
        predict_at(p0x, p0y, v0x, v0y, mu, rules[core.R_CAPTURE], tk, scratch, 2 * n)
        shx = shx + (scratch[2 * n, 0] - (p0x + tk * v0x))
        shy = shy + (scratch[2 * n, 1] - (p0y + tk * v0y))
        t2, h2 = lead_intercept(m, seat, pos, vel, rules, memory, n, scratch, shx, shy)
        if t2 == _NO_TIME:
            return t, h
        t = t2
        h = h2
    return t, h


@jit(**NUMERIC)
def predict_at(x, y, vx, vy, mu, capture, t, path, row):
    """``geometry.predict_path`` at the single time ``t`` into ``path[row]``."""
    if mu > 0.0 and (x != 0.0 or y != 0.0):
        ax, ay = star_accel(x, y, mu, capture)
        base = path.shape[0] - 3
        r0 = path[base]
        v0 = path[base + 1]
        r0[0] = x
        r0[1] = y
        v0[0] = vx + 0.5 * ax
        v0[1] = vy + 0.5 * ay
        out = path[row]
        kepler_step(r0, v0, mu, t, out, path[base + 2])
        if math.isfinite(out[0]) and math.isfinite(out[1]):
            return
    path[row, 0] = x + t * vx
    path[row, 1] = y + t * vy


@jit(**NUMERIC)
def navigation(m, seat, pos, vel, ship_gauges, in_shot):
    """``Sniper.navigation``: the velocity change wanted relative to the enemy (close in when out
    of shot, open when too close, damp a fast sideways pass, never past ``max_speed``), or
    (0, 0, False) to stay on this orbit (small change, or fuel at the reserve)."""
    me = seat
    en = 1 - seat
    if ship_gauges[m, me, core.FUEL] <= S_FUEL_RESERVE:
        return 0.0, 0.0, False
    vx = vel[m, 0, me]
    vy = vel[m, 1, me]
    dx = wrap(pos[m, 0, en] - pos[m, 0, me])
    dy = wrap(pos[m, 1, en] - pos[m, 1, me])
    dist = py_hypot(dx, dy)
    ux = dx / max(dist, 1e-12)
    uy = dy / max(dist, 1e-12)
    rx = vx - vel[m, 0, en]
    ry = vy - vel[m, 1, en]
    closing_now = dot_blas(rx, ry, ux, uy)
    acx = rx - closing_now * ux
    acy = ry - closing_now * uy
    if not in_shot and dist > S_MIN_RANGE:
        closing = min(S_APPROACH, S_GAIN * max(dist - 0.5 * S_MAX_RANGE, 0.0))
    elif dist < S_MIN_RANGE:
        closing = -S_RETREAT
    else:
        closing = closing_now
    cx = (closing - closing_now) * ux
    cy = (closing - closing_now) * uy
    side = py_hypot(acx, acy)
    if side > S_MAX_REL:
        f = 1.0 - S_MAX_REL / side
        cx = cx - acx * f
        cy = cy - acy * f
    nx = vx + cx
    ny = vy + cy
    speed = py_hypot(nx, ny)
    if speed > S_MAX_SPEED and speed > py_hypot(vx, vy):
        f = 1.0 - S_MAX_SPEED / speed
        cx = cx - nx * f
        cy = cy - ny * f
    if py_hypot(cx, cy) <= S_NAV_TOL:
        return 0.0, 0.0, False
    return cx, cy, True


@jit(**NUMERIC)
def sniper_decide(m, seat, pos, vel, active, ship_gauges, ship_counters, torp_life, rules,
                  memory, n, scratch):
    """``Sniper.decide`` for a live ship out of hyperspace: escape the star (firing if a shot
    lines up), wait while the enemy is unseen, else engage (navigate or aim, and fire)."""
    me = seat
    en = 1 - seat
    x, y, vx, vy = ship_motion(m, me, pos, vel)
    heading = ship_gauges[m, me, core.HEADING]
    omega = ship_gauges[m, me, core.OMEGA]
    mu = rules[core.R_STAR]
    visible = ship_counters[m, en, core.ALIVE] == 1 and ship_counters[m, en, core.IN_HYPER] == 0
    if visible:
        enemy_path(m, seat, pos, vel, rules, memory, n, scratch)
    # safety
    if mu <= 0.0:
        memory[m, seat, ESCAPING] = 0.0
    else:
        q = periapsis(x, y, vx, vy, mu)
        if q >= S_QMIN * (1.5 if memory[m, seat, ESCAPING] != 0.0 else 1.0):
            memory[m, seat, ESCAPING] = 0.0
        else:
            memory[m, seat, ESCAPING] = 1.0
            target = safest_heading(x, y, vx, vy, mu, heading, rules[core.R_THRUST] * S_BURN)
            turn = steer(heading, omega, target, rules)
            thrust = abs(angle_diff(target, heading)) < 0.8
            fire = fire_ok(m, seat, pos, vel, active, ship_gauges, ship_counters, torp_life, rules,
                           memory, turn, visible, n, scratch)
            return action(turn, thrust, fire, False, False)
    if not visible:
        return core.NOOP
    # engage
    t, sol = solve(m, seat, pos, vel, rules, memory, n, scratch)
    in_shot = t != _NO_TIME and t <= shot_time(m, me, ship_counters, rules)
    cx, cy, navigate = navigation(m, seat, pos, vel, ship_gauges, in_shot)
    if navigate:
        want = math.atan2(cy, cx)
        nav, safe = safe_heading_near(x, y, vx, vy, mu, want, rules[core.R_THRUST] * S_BURN,
                                      S_QMIN * 1.3, heading)
        turn = steer(heading, omega, nav, rules)
        thrust = safe and abs(angle_diff(nav, heading)) < 0.35
        fire = fire_ok(m, seat, pos, vel, active, ship_gauges, ship_counters, torp_life, rules,
                       memory, turn, True, n, scratch)
        return action(turn, thrust, fire, False, False)
    if t != _NO_TIME:
        target = sol
    else:
        target = math.atan2(wrap(pos[m, 1, en] - y), wrap(pos[m, 0, en] - x))
    turn = steer(heading, omega, target, rules)
    fire = fire_ok(m, seat, pos, vel, active, ship_gauges, ship_counters, torp_life, rules, memory,
                   turn, True, n, scratch)
    return action(turn, False, fire, False, False)


# -- the dodger -----------------------------------------------------------------------------------
@jit(**NUMERIC)
def threat(m, seat, pos, vel, active, torp_life, rules, n_life, scratch):
    """``Dodger.threat``: of the enemy torpedoes with more than a frame to live, those passing
    near by straight relative motion (miss below ``2 danger + (g + thrust) t_c^2 / 2``) are
    followed against my coasting Kepler path (``scratch[n_life:]``) at integer frames; one whose
    closest approach is below ``danger`` is a threat, the earliest (first in slot order on a tie)
    is returned: ``(slot, t_c, c_x, c_y, t_hit)`` (``slot`` -1: no threat, t_hit _NO_TIME: the
    diamond test misses)."""
    me = seat
    en = 1 - seat
    ntorp = torp_life.shape[1] // 2
    x, y, vx, vy = ship_motion(m, me, pos, vel)
    mu = rules[core.R_STAR]
    gx, gy = star_accel(x, y, mu, rules[core.R_CAPTURE])
    g = math.hypot(gx, gy)  # np.hypot: the C library's
    # cheap first pass; the largest ttl of the near ones sets the horizon of the fine pass
    max_ttl = -1
    for j in range(ntorp):
        b = 2 + en * ntorp + j
        ttl = torp_life[m, en * ntorp + j]
        if not active[m, b] or ttl <= 1:
            continue
        if _near(pos[m, 0, b], pos[m, 1, b], vel[m, 0, b], vel[m, 1, b], x, y, vx, vy, ttl, g,
                 rules):
            max_ttl = max(max_ttl, ttl)
    if max_ttl < 0:
        return -1, 0.0, 0.0, 0.0, _NO_TIME
    n = max(1, min(D_HORIZON, max_ttl - 1))
    predict_path(x, y, vx, vy, mu, rules[core.R_CAPTURE], n, scratch, n_life, scratch)
    best_slot = -1
    best_k = n
    dd = D_DANGER * D_DANGER
    for j in range(ntorp):
        b = 2 + en * ntorp + j
        ttl = torp_life[m, en * ntorp + j]
        if not active[m, b] or ttl <= 1:
            continue
        px = pos[m, 0, b]
        py = pos[m, 1, b]
        tvx = vel[m, 0, b]
        tvy = vel[m, 1, b]
        if not _near(px, py, tvx, tvy, x, y, vx, vy, ttl, g, rules):
            continue
        kmin = 0
        dmin = math.inf
        for k in range(n):
            t = k + 1.0
            if not t < ttl:
                break  # the rest are inf, never below a finite minimum
            rx = wrap((px + t * tvx) - scratch[n_life + k, 0])
            ry = wrap((py + t * tvy) - scratch[n_life + k, 1])
            d2 = rx * rx + ry * ry
            if d2 < dmin:
                dmin = d2
                kmin = k
        if dmin < dd and kmin < best_k:
            best_k = kmin
            best_slot = j
    if best_slot < 0:
        return -1, 0.0, 0.0, 0.0, _NO_TIME
    b = 2 + en * ntorp + best_slot
    ttl = torp_life[m, en * ntorp + best_slot]
    px = pos[m, 0, b]
    py = pos[m, 1, b]
    tvx = vel[m, 0, b]
    tvy = vel[m, 1, b]
    t_hit = _NO_TIME
    box = rules[core.R_HITBOX]
    dia = rules[core.R_DIAMOND]
    cx = 0.0
    cy = 0.0
    for k in range(n):
        t = k + 1.0
        rx = wrap((px + t * tvx) - scratch[n_life + k, 0])
        ry = wrap((py + t * tvy) - scratch[n_life + k, 1])
        if k == best_k:
            cx = rx
            cy = ry
        if t_hit == _NO_TIME and t < ttl and diamond(rx, ry, box, dia):
            t_hit = t
    return best_slot, best_k + 1.0, cx, cy, t_hit


@jit(**NUMERIC)
def _near(px, py, tvx, tvy, x, y, vx, vy, ttl, g, rules):
    """The dodger's cheap pass for one torpedo: closest approach of straight relative motion,
    ``t_c = clip(-d.w / max(w.w, 1e-18), 0, min(ttl, horizon))``, against a margin for the star's
    pull and the ship's own burns."""
    dx = wrap(px - x)
    dy = wrap(py - y)
    wx = tvx - vx
    wy = tvy - vy
    ww = max(wx * wx + wy * wy, 1e-18)
    tc = min(max(-(dx * wx + dy * wy) / ww, 0.0), float(min(ttl, D_HORIZON)))
    mx = dx + tc * wx
    my = dy + tc * wy
    margin = 2.0 * D_DANGER + 0.5 * (g + rules[core.R_THRUST]) * tc * tc
    return mx * mx + my * my < margin * margin


@jit(**NUMERIC)
def dodge(m, seat, pos, vel, charge, active, ship_gauges, ship_counters, torp_life, rules, memory,
          n, scratch, slot, t_c, cx, cy, t_hit):
    """``Dodger.dodge`` (see its docstring): burn along the normal of the torpedo's relative
    velocity that widens the miss (the one needing less turning when dead on, the safe one about
    the star), hyperspace when a hit within ``hyper_frames`` cannot be cleared; flip the charge
    against an opposite torpedo in the electric mode; fire if a shot lines up."""
    me = seat
    en = 1 - seat
    ntorp = torp_life.shape[1] // 2
    b = 2 + en * ntorp + slot
    heading = ship_gauges[m, me, core.HEADING]
    omega = ship_gauges[m, me, core.OMEGA]
    vx = vel[m, 0, me]
    vy = vel[m, 1, me]
    mu = rules[core.R_STAR]
    wx = vel[m, 0, b] - vx
    wy = vel[m, 1, b] - vy
    wn = py_hypot(wx, wy)
    if wn < 1e-12:
        nx = 1.0
        ny = 0.0
    else:
        nx = -wy / wn
        ny = wx / wn
    cn = dot_blas(cx, cy, nx, ny)
    if cn > 0.0:
        s0x, s0y, s1x, s1y = -nx, -ny, nx, ny
    else:
        s0x, s0y, s1x, s1y = nx, ny, -nx, -ny
    if abs(cn) < 0.2 * rules[core.R_HITBOX]:  # dead on: less turning first (a stable sort)
        if abs(angle_diff(math.atan2(s1y, s1x), heading)) < abs(angle_diff(math.atan2(s0y, s0x),
                                                                           heading)):
            s0x, s0y, s1x, s1y = s1x, s1y, s0x, s0y
    if mu > 0.0:
        dv = rules[core.R_THRUST] * S_BURN
        x = pos[m, 0, me]
        y = pos[m, 1, me]
        safe0 = periapsis(x, y, vx + dv * s0x, vy + dv * s0y, mu) >= S_QMIN
        safe1 = periapsis(x, y, vx + dv * s1x, vy + dv * s1y, mu) >= S_QMIN
        if not safe0 and safe1:
            s0x, s0y = s1x, s1y
    target = math.atan2(s0y, s0x)
    off = abs(angle_diff(target, heading))
    t_turn = max(0.0, off - D_THRUST_CONE) / rules[core.R_TURN]
    t_arrive = t_c if t_hit == _NO_TIME else t_hit
    late = max(0.0, t_arrive - t_turn)
    reach = 0.5 * rules[core.R_THRUST] * (late * late)
    need = D_CLEARANCE - abs(cn)
    if (t_hit != _NO_TIME and t_hit <= D_HYPER_FRAMES and reach < need
            and ship_counters[m, me, core.HYPER_LEFT] > 0
            and ship_counters[m, me, core.HYPER_RECHARGE] == 0):
        return action(0, False, False, True, False)
    turn = steer(heading, omega, target, rules)
    thrust = off < D_THRUST_CONE and ship_gauges[m, me, core.FUEL] > 0.0
    visible = ship_counters[m, en, core.ALIVE] == 1 and ship_counters[m, en, core.IN_HYPER] == 0
    fire = False
    if visible:
        enemy_path(m, seat, pos, vel, rules, memory, n, scratch)
        fire = fire_ok(m, seat, pos, vel, active, ship_gauges, ship_counters, torp_life, rules,
                       memory, turn, True, n, scratch)
    flip = rules[core.R_ELECTRIC] != 0.0 and charge[m, b] * charge[m, me] < 0.0
    return action(turn, thrust, fire, False, flip)


# -- the entry points -----------------------------------------------------------------------------
@jit(_nrt=False, inline="always", **NUMERIC)  # allocates nothing; inlined (core's note)
def decide_with(kind, m, seat, pos, vel, charge, active, ship_gauges, ship_counters, torp_life,
                match_state, rules, memory, bot_rng, scratch):
    """:func:`decide` with the sniper's and dodger's scratch given (``new_scratch``)."""
    if kind == RANDOM:
        return random_code(m, seat, bot_rng)
    if kind == CHASER:
        return chaser(m, seat, pos, vel, ship_gauges, ship_counters, rules, memory)
    if kind == SNIPER or kind == DODGER:
        track(m, seat, pos, vel, ship_counters, match_state, rules, memory)
        if ship_counters[m, seat, core.ALIVE] == 0 or ship_counters[m, seat, core.IN_HYPER] == 1:
            return core.NOOP
        n = max(int(rules[core.R_TLIFE]) - 1, 1)
        if kind == DODGER:
            slot, t_c, cx, cy, t_hit = threat(m, seat, pos, vel, active, torp_life, rules, n,
                                              scratch)
            if slot >= 0:
                return dodge(m, seat, pos, vel, charge, active, ship_gauges, ship_counters,
                             torp_life, rules, memory, n, scratch, slot, t_c, cx, cy, t_hit)
        return sniper_decide(m, seat, pos, vel, active, ship_gauges, ship_counters, torp_life,
                             rules, memory, n, scratch)
    return core.NOOP


@jit(**NUMERIC)
def decide(kind, m, seat, pos, vel, charge, active, ship_gauges, ship_counters, torp_life,
           match_state, rules, memory, bot_rng):
    """The action code of bot ``kind`` (``KINDS``) in seat ``seat`` of match ``m`` this frame,
    from the state before the frame is stepped; updates its ``memory[m, seat]`` (and draws from
    ``bot_rng[m, seat]`` for the random bot). idle, random and chaser allocate nothing; the
    sniper and dodger allocate their scratch (``new_scratch``) per call."""
    if kind == SNIPER or kind == DODGER:
        scratch = new_scratch(rules)
        return decide_with(kind, m, seat, pos, vel, charge, active, ship_gauges, ship_counters,
                           torp_life, match_state, rules, memory, bot_rng, scratch)
    if kind == RANDOM:
        return random_code(m, seat, bot_rng)
    if kind == CHASER:
        return chaser(m, seat, pos, vel, ship_gauges, ship_counters, rules, memory)
    return core.NOOP


CHUNK = 64  # matches per scratch in decide_all


@jit(parallel=True, **NUMERIC)
def decide_all(kind, seat, pos, vel, charge, active, ship_gauges, ship_counters, torp_life,
               match_state, rules, memory, bot_rng, codes):
    """:func:`decide` for every match, into ``codes[:, seat]`` (M, 2) int64; matches spread over
    the threads in chunks of ``CHUNK``, each chunk with one scratch. Each match touches only its
    own rows, so the result does not depend on the thread count."""
    matches = pos.shape[0]
    chunks = (matches + CHUNK - 1) // CHUNK
    for c in prange(chunks):
        scratch = new_scratch(rules)
        for m in range(c * CHUNK, min(matches, (c + 1) * CHUNK)):
            codes[m, seat] = decide_with(kind, m, seat, pos, vel, charge, active, ship_gauges,
                                         ship_counters, torp_life, match_state, rules, memory,
                                         bot_rng, scratch)


__all__ = ["KINDS", "MEMORY", "new_memory", "new_streams", "reset_memory", "decide",
           "decide_all", "decide_with", "new_scratch", "py_hypot", "dot_blas"]
