"""Torus, steering and orbit helpers the compiled bots share, as ``spacewar.bots.geometry``
is for the Python bots: wrap and angle differences, an action code from its parts, turning
toward a heading, the star's pull, a periapsis and the burn that raises it most."""
import math

from engine import space

from spacewar.game import core
from spacewar.game.compiled_bots.numerics import NUMERIC, py_hypot

jit = core.jit

TWO_PI = 2.0 * math.pi
NO_TIME = -1.0  # "None" for a time (all real times here are >= 1 frame)


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
