"""``spacewar.bots.dodger.Dodger`` compiled: the sniper's play, and out of the way of a torpedo
that would hit (a burn across its path, or hyperspace when none is enough)."""
import math

from spacewar.game import core
from spacewar.game.compiled_bots.numerics import NUMERIC, dot_blas, py_hypot
from spacewar.game.compiled_bots.geometry import (NO_TIME, action, angle_diff, periapsis,
                                                  ship_motion, star_accel, steer, wrap)
from spacewar.game.compiled_bots.sniper import (S_BURN, S_QMIN, diamond, enemy_path, fire_ok,
                                                predict_path)

jit = core.jit

DODGER_PARAMS = {"horizon": 80, "danger": 0.024, "clearance": 0.026, "hyper_frames": 4,
                 "thrust_cone": 1.0}
D_HORIZON, D_DANGER, D_CLEARANCE, D_HYPER_FRAMES, D_THRUST_CONE = DODGER_PARAMS.values()


# -- the dodger -----------------------------------------------------------------------------------
@jit(**NUMERIC)
def threat(m, seat, pos, vel, active, torp_life, rules, n_life, scratch):
    """``Dodger.threat``: of the enemy torpedoes with more than a frame to live, those passing
    near by straight relative motion (miss below ``2 danger + (g + thrust) t_c^2 / 2``) are
    followed against my coasting Kepler path (``scratch[n_life:]``) at integer frames; one whose
    closest approach is below ``danger`` is a threat, the earliest (first in slot order on a tie)
    is returned: ``(slot, t_c, c_x, c_y, t_hit)`` (``slot`` -1: no threat, t_hit NO_TIME: the
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
        return -1, 0.0, 0.0, 0.0, NO_TIME
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
        return -1, 0.0, 0.0, 0.0, NO_TIME
    b = 2 + en * ntorp + best_slot
    ttl = torp_life[m, en * ntorp + best_slot]
    px = pos[m, 0, b]
    py = pos[m, 1, b]
    tvx = vel[m, 0, b]
    tvy = vel[m, 1, b]
    t_hit = NO_TIME
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
        if t_hit == NO_TIME and t < ttl and diamond(rx, ry, box, dia):
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
    t_arrive = t_c if t_hit == NO_TIME else t_hit
    late = max(0.0, t_arrive - t_turn)
    reach = 0.5 * rules[core.R_THRUST] * (late * late)
    need = D_CLEARANCE - abs(cn)
    if (t_hit != NO_TIME and t_hit <= D_HYPER_FRAMES and reach < need
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
