"""``spacewar.bots.chaser.Chaser`` compiled: aim ahead of the enemy, fire in range, keep out of
the star, dodge a ram."""
import math

from spacewar.game import core
from spacewar.game.compiled_bots.numerics import NUMERIC, dot_blas, py_hypot
from spacewar.game.compiled_bots.geometry import (NO_TIME, action, angle_diff, heading_after,
                                                  periapsis, safe_heading_near, safest_heading,
                                                  ship_motion, steer, wrap)
from spacewar.game.compiled_bots.memory import ESCAPING

jit = core.jit

CHASER_PARAMS = {"q_min": 0.06, "fire_range": 0.24, "standoff": 0.1, "gain": 0.01,
                 "approach_speed": 1.6e-3, "retreat_speed": 8e-4, "nav_tolerance": 5e-4,
                 "burn_frames": 12, "aim_margin": 0.8, "fire_cone": math.radians(6.0),
                 "ram_distance": 0.04, "ram_horizon": 50, "max_speed": 1.6e-3,
                 "fuel_reserve": 250.0}
(C_QMIN, C_FIRE_RANGE, C_STANDOFF, C_GAIN, C_APPROACH, C_RETREAT, C_NAV_TOL, C_BURN, C_AIM_MARGIN,
 C_FIRE_CONE, C_RAM_DIST, C_RAM_HORIZON, C_MAX_SPEED, C_FUEL_RESERVE) = CHASER_PARAMS.values()


@jit(**NUMERIC)
def lead_straight(dx, dy, wx, wy, offset, speed):
    """``geometry.lead_straight``: the smallest t > 0 with ``|d + w t| = offset + speed t``
    (``(w.w - s^2) t^2 + 2 (d.w - offset s) t + (d.d - offset^2) = 0``) and the heading of
    ``d + w t``; ``(NO_TIME, 0)`` when there is none. The dot products are numpy's (BLAS)."""
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
            return NO_TIME, 0.0
        sq = math.sqrt(disc)
        t1 = (-b - sq) / (2.0 * a)
        t2 = (-b + sq) / (2.0 * a)
        if t1 > 0.0:
            t = t1
        if t2 > 0.0 and t2 < t:
            t = t2
    if t == math.inf:
        return NO_TIME, 0.0
    return t, math.atan2(dy + wy * t, dx + wx * t)


@jit(**NUMERIC)
def chaser_aim(m, me, en, pos, vel, rules, dx, dy):
    """``Chaser._aim``: the straight-line lead if it meets within a torpedo's life, else the
    direction to the enemy (``d`` = nearest image from me to the enemy)."""
    t, lead = lead_straight(dx, dy, vel[m, 0, en] - vel[m, 0, me], vel[m, 1, en] - vel[m, 1, me],
                            rules[core.R_OFFSET], rules[core.R_MUZZLE])
    if t != NO_TIME and t < rules[core.R_TLIFE]:
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
