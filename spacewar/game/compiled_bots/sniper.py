"""``spacewar.bots.sniper.Sniper`` compiled: the enemy's path predicted (Kepler about the star,
its thrust estimated), the torpedo's path, the first hit, a shot when it lands."""
import math

import numpy as np

from engine.analytic import kepler_step

from spacewar.game import core
from spacewar.game.compiled_bots.numerics import NUMERIC, dot_blas, py_hypot
from spacewar.game.compiled_bots.geometry import (NO_TIME, action, angle_diff, heading_after,
                                                  periapsis, periapsis_r, safe_heading_near,
                                                  safest_heading, ship_motion, star_accel, steer,
                                                  wrap)
from spacewar.game.compiled_bots.memory import (ESCAPING, HAS_LAST, LAST_ROUND, LAST_ROUND_FRAME,
                                                LAST_VX, LAST_VY, LAST_X, LAST_Y, THRUST_X, THRUST_Y)

jit = core.jit

SNIPER_PARAMS = {"q_min": 0.08, "aim_shrink": 0.6, "shot_base": 35.0, "shot_per_torpedo": 1.8,
                 "shot_min": 40.0, "min_range": 0.1, "max_range": 0.3, "approach_speed": 1.0e-3,
                 "retreat_speed": 6e-4, "max_speed": 1.4e-3, "max_rel_speed": 1.6e-3,
                 "nav_tolerance": 4e-4, "burn_frames": 12, "fuel_reserve": 250.0, "gain": 0.01,
                 "thrust_smoothing": 0.1, "thrust_weight": 1.0}
(S_QMIN, S_AIM_SHRINK, S_SHOT_BASE, S_SHOT_PER_TORP, S_SHOT_MIN, S_MIN_RANGE, S_MAX_RANGE,
 S_APPROACH, S_RETREAT, S_MAX_SPEED, S_MAX_REL, S_NAV_TOL, S_BURN, S_FUEL_RESERVE, S_GAIN,
 S_SMOOTH, S_THRUST_WEIGHT) = SNIPER_PARAMS.values()


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
    interpolation with the point before; returns (t, heading of D(t)) or (NO_TIME, 0).

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
    return NO_TIME, 0.0


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
    or NO_TIME (a later hit is no shot for the sniper anyway). A straight torpedo is compared
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
    return NO_TIME


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
    if t == NO_TIME or t > longest:
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
    if t == NO_TIME or not (rules[core.R_TORP_STAR] != 0.0 and mu > 0.0):
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
        if t2 == NO_TIME:
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
    in_shot = t != NO_TIME and t <= shot_time(m, me, ship_counters, rules)
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
    if t != NO_TIME:
        target = sol
    else:
        target = math.atan2(wrap(pos[m, 1, en] - y), wrap(pos[m, 0, en] - x))
    turn = steer(heading, omega, target, rules)
    fire = fire_ok(m, seat, pos, vel, active, ship_gauges, ship_counters, torp_life, rules, memory,
                   turn, True, n, scratch)
    return action(turn, False, fire, False, False)
