"""Geometry and prediction for bots: the helpers the built-in bots use, public for yours.

    from spacewar.bots.geometry import torus_delta, angle_diff, turn_towards

Conventions (checked by ``tests/spacewar/test_bot_author.py``; see ``spacewar.rules``):

* The arena is the unit torus: x and y in [-0.5, 0.5), y up; the star sits at the origin.
  Leaving one edge brings a body back at the opposite one, so between two points there are
  many straight paths (one per image); distances, hits and aiming use the shortest,
  the *nearest image*: ``d = wrap(b - a)``.
* One time unit is one frame. Each frame the game applies ``v += thrust + a_star(p)`` then
  ``p += v`` (symplectic Euler, kick then drift), with
  ``a_star(p) = -mu p / (|p|^2 + eps^2)^(3/2)``, ``eps = star_capture / 2``.
* A heading is an angle in radians from the +x axis, anticlockwise positive, kept in
  (-pi, pi]; a ship points (and thrusts, and fires) along ``(cos heading, sin heading)``.
  ``Action(turn=+1)`` turns anticlockwise: the heading grows by ``rules.turn_rate`` a frame.

What is here:

* torus helpers: :func:`wrap`, :func:`torus_delta`, :func:`torus_distance`; angles:
  :func:`angle_diff`, :func:`bearing`;
* steering: :func:`turn_towards` (fixed turn rate), :func:`steer` (also the angular-momentum
  sense switch, where the keys change the angular velocity), :func:`heading_after`;
* the star: :func:`star_accel`, :func:`periapsis` (closest distance to the star the coasting
  path will reach, from the conic's invariants), :func:`safest_heading` and
  :func:`safe_heading_near` (pick a thrust direction that keeps the periapsis high);
* prediction: :func:`predict_path` (a coasting ship's positions at given frames, by
  ``engine.analytic.kepler`` about the star, or a straight line without a star),
  :func:`torpedo_path`, :func:`launch_state`, :func:`lead_intercept` (the firing heading that
  meets a predicted path), :func:`lead_straight` (the same for straight-line motion, in closed
  form), :func:`diamond_hits` and :func:`first_hit` (would a torpedo on this heading hit, by
  the game's diamond test), :func:`ram_escape`; :func:`warm_up` loads the compiled kernels.

Importing this module needs NumPy alone: a bot that uses these helpers starts as fast as one
that does not (a confined bot's process is ready in a few tenths of a second). Only the
prediction along a conic (:func:`predict_path` with a star, and what calls it) loads the
engine's compiled Kepler solver, on its first call or at :func:`warm_up` (about a second in a
fresh process, within a bot's start-up budget when its constructor calls ``warm_up``).
"""
import math

import numpy as np

__all__ = [
    "SIDE", "TWO_PI", "wrap", "torus_delta", "torus_distance", "angle_diff", "bearing",
    "turn_towards", "steer", "heading_after", "star_accel", "periapsis", "safest_heading",
    "safe_heading_near", "warm_up", "predict_path", "torpedo_path", "lead_intercept",
    "lead_straight", "diamond_hits", "first_hit", "launch_state", "ram_escape",
]

#: side of the game's torus (positions in [-0.5, 0.5))
SIDE = 1.0

TWO_PI = 2.0 * math.pi


# -- torus and angles -------------------------------------------------------------------
def wrap(x):
    """``x`` (a float or an array of coordinates) mapped onto the torus range [-0.5, 0.5):
    ``wrap(x) = x - floor(x + 1/2)`` (``engine.space.wrap`` with the game's side of 1).

    ``wrap(0.7) == -0.3``; applied to a difference it gives the nearest image. The same
    operations as ``engine.space.wrap(x, 1.0)``, bit for bit (a test holds them to it),
    written here so that a bot's helpers do not load the engine's compiled code."""
    return x - SIDE * np.floor(x * (1.0 / SIDE) + 0.5)


def torus_delta(a, b):
    """The shortest vector from point ``a`` to point ``b`` on the unit torus, a (2,) array
    (or (..., 2) for arrays of points): ``wrap(b - a)`` per coordinate, the nearest image
    (``engine.space.nearest_image``). Each component is in [-0.5, 0.5).

    Aim, distances and hits all use it: from (0.45, 0) the point (-0.45, 0) is 0.1 away
    to the right, ``torus_delta((0.45, 0), (-0.45, 0)) == (0.1, 0)``, not 0.9 to the left."""
    return wrap(np.asarray(b, dtype=float) - np.asarray(a, dtype=float))


def torus_distance(a, b):
    """The distance from ``a`` to ``b`` by the nearest image: ``|torus_delta(a, b)|``, at most
    ``sqrt(2) / 2`` (a float)."""
    d = torus_delta(a, b)
    return math.hypot(float(d[0]), float(d[1]))


def bearing(a, b):
    """The heading (radians from +x, anticlockwise, in (-pi, pi]) that points from ``a`` to
    ``b`` by the nearest image: ``atan2(d_y, d_x)`` with ``d = torus_delta(a, b)``."""
    d = torus_delta(a, b)
    return math.atan2(float(d[1]), float(d[0]))


def angle_diff(target, heading):
    """The signed turn from ``heading`` to ``target`` (radians): ``target - heading`` wrapped
    to (-pi, pi], ``((target - heading + pi) mod 2 pi) - pi`` with -pi taken as +pi.

    Positive means the target is anticlockwise of the heading (turn +1 reaches it soonest),
    negative clockwise (turn -1): ``angle_diff(0.1, -0.1) == 0.2``,
    ``angle_diff(-3.1, 3.1)`` is about +0.083 (across the +-pi seam), never about -6.2."""
    d = (target - heading + math.pi) % TWO_PI - math.pi
    return d if d != -math.pi else math.pi


def turn_towards(heading, target, rules, deadband=None):
    """-1, 0 or +1: the turn that brings ``heading`` towards ``target`` fastest.

    The sign of :func:`angle_diff` (``target``, ``heading``), or 0 when its size is within
    ``deadband`` (default half of ``rules.turn_rate``, the heading's step in a frame, so the
    ship does not wobble one step either side of the target). Under the angular-momentum
    switch use :func:`steer`."""
    d = angle_diff(target, heading)
    band = 0.5 * rules.turn_rate if deadband is None else deadband
    if abs(d) <= band:
        return 0
    return 1 if d > 0 else -1


def steer(ship, target, rules):
    """The turn key that brings ``ship`` to heading ``target``.

    Without the angular-momentum switch the heading moves by ``turn_rate`` per frame, so this
    is :func:`turn_towards`. With it the key changes the angular velocity w by ``angular_accel``
    (|w| <= 4 turn_rate): aim for ``w* = sign(e) sqrt(2 alpha |e|)`` (the fastest w that can still
    stop at the target, e the heading error) and press the key that moves w towards w*.
    """
    if not rules.angular_momentum:
        return turn_towards(ship.heading, target, rules)
    err = angle_diff(target, ship.heading)
    alpha = rules.angular_accel
    w_star = math.copysign(min(math.sqrt(2.0 * alpha * abs(err)), 4.0 * rules.turn_rate), err)
    w = ship.angular_velocity
    if w < w_star - 0.5 * alpha:
        return 1
    if w > w_star + 0.5 * alpha:
        return -1
    return 0


def heading_after(ship, turn, rules):
    """The heading the ship will have once this frame's ``turn`` is applied, which is the
    heading a torpedo fired this frame leaves on (the game turns, then thrusts, then fires):
    ``heading + turn turn_rate``, or with angular momentum ``heading + w'`` where
    ``w' = clip(w + turn angular_accel, -4 turn_rate, 4 turn_rate)``. Not wrapped to
    (-pi, pi]: compare it with :func:`angle_diff`."""
    if rules.angular_momentum:
        limit = 4.0 * rules.turn_rate
        w = min(limit, max(-limit, ship.angular_velocity + turn * rules.angular_accel))
        return ship.heading + w
    return ship.heading + turn * rules.turn_rate


# -- the star ---------------------------------------------------------------------------
def star_accel(pos, mu, capture):
    """The star's pull on a ship at ``pos``: -mu p / (|p|^2 + eps^2)^(3/2), eps = capture / 2."""
    if mu <= 0.0:
        return np.zeros(2)
    r2 = float(pos[0] * pos[0] + pos[1] * pos[1]) + (0.5 * capture) ** 2
    return -mu * np.asarray(pos, dtype=float) / (r2 * math.sqrt(r2))


def periapsis(pos, vel, mu):
    """Closest distance to the star that the coasting path from (pos, vel) will reach.

    ``vel`` may be (2,) or (n, 2) (candidate velocities from one position). From the conic's
    invariants about the star (two-body, Bate-Mueller-White ch. 1-2): ``h = x v_y - y v_x``,
    ``E = |v|^2 / 2 - mu / r``, ``e = sqrt(1 + 2 E h^2 / mu^2)``, ``q = h^2 / (mu (1 + e))``.
    An unbound ship moving away (E >= 0 and p.v > 0) never comes closer than it is: ``r``.
    Bound orbits return q even when the ship is receding (it will be back). Without a star
    the answer is +inf (nothing to fall into).
    """
    vel = np.asarray(vel, dtype=float)
    if mu <= 0.0:
        return np.full(vel.shape[:-1], np.inf) if vel.ndim > 1 else math.inf
    x, y = float(pos[0]), float(pos[1])
    r = math.hypot(x, y)
    if r == 0.0:
        return np.zeros(vel.shape[:-1]) if vel.ndim > 1 else 0.0
    if vel.ndim == 1:  # one velocity: plain floats are much faster than numpy here
        vx, vy = float(vel[0]), float(vel[1])
        h = x * vy - y * vx
        energy = 0.5 * (vx * vx + vy * vy) - mu / r
        if energy >= 0.0 and x * vx + y * vy > 0.0:
            return r
        e = math.sqrt(max(0.0, 1.0 + 2.0 * energy * h * h / (mu * mu)))
        return h * h / (mu * (1.0 + e))
    vx, vy = vel[..., 0], vel[..., 1]
    h = x * vy - y * vx
    energy = 0.5 * (vx * vx + vy * vy) - mu / r
    e = np.sqrt(np.maximum(0.0, 1.0 + 2.0 * energy * h * h / (mu * mu)))
    q = h * h / (mu * (1.0 + e))
    q = np.where((energy >= 0.0) & (x * vx + y * vy > 0.0), r, q)
    return q if vel.ndim > 1 else float(q)


def _candidate_velocities(vel, angles, dv):
    return np.asarray(vel, dtype=float) + dv * np.stack((np.cos(angles), np.sin(angles)), axis=1)


def safest_heading(pos, vel, mu, heading, dv, n=32, slack=0.9):
    """The thrust direction that raises the periapsis most after a velocity change ``dv``.

    Tries ``n`` directions; among those within ``slack`` of the best periapsis, returns the one
    nearest the current ``heading`` (less turning before the burn). Returns (angle, q).
    """
    offsets = np.arange(n) * (TWO_PI / n)
    offsets = np.where(offsets > math.pi, offsets - TWO_PI, offsets)
    angles = heading + offsets
    q = periapsis(pos, _candidate_velocities(vel, angles, dv), mu)
    good = q >= slack * q.max()
    k = int(np.argmin(np.where(good, np.abs(offsets), np.inf)))
    return float(angles[k]), float(q[k])


def safe_heading_near(pos, vel, mu, desired, dv, q_min, n=36, heading=None, turn_weight=0.5):
    """The thrust direction closest to ``desired`` whose burn of ``dv`` keeps periapsis >= q_min.

    Candidates are ``desired + k 2 pi / n``. Among the safe ones it takes the one minimising
    ``|offset from desired| + turn_weight |turn from heading|`` (with ``heading`` given; the
    turn term keeps the choice from flipping between the two sides of a forbidden cone from
    one frame to the next). Returns (angle, safe): when no direction is safe, the one with the
    highest periapsis and False.
    """
    if mu <= 0.0:
        return desired, True
    k = np.arange(n)
    offsets = np.where(k % 2 == 1, (k + 1) // 2, -(k // 2)) * (TWO_PI / n)  # 0, +1, -1, +2 ...
    angles = desired + offsets
    q = periapsis(pos, _candidate_velocities(vel, angles, dv), mu)
    ok = q >= q_min
    if ok.any():
        cost = np.abs(offsets)
        if heading is not None:
            cost = cost + turn_weight * np.abs((angles - heading + math.pi) % TWO_PI - math.pi)
        return float(angles[int(np.argmin(np.where(ok, cost, np.inf)))]), True
    return float(angles[int(np.argmax(q))]), False


# -- prediction -------------------------------------------------------------------------
_warm = False


def warm_up():
    """Load (or compile) ``engine.analytic``'s numba kernels once per process, so that a bot's
    first ``act`` is not slowed by it (bots call this from their constructor)."""
    global _warm
    if not _warm:
        predict_path(np.array([0.2, 0.1]), np.array([1e-4, 2e-4]), 2.5e-7, np.arange(1.0, 4.0))
        _warm = True


def _kepler():
    """``engine.analytic.kepler``, imported on the first prediction: the engine's compiled
    code is loaded by a bot that predicts along conics, not by every bot that imports this
    module."""
    global _KEPLER
    if _KEPLER is None:
        from engine.analytic import kepler

        _KEPLER = kepler
    return _KEPLER


_KEPLER = None


def predict_path(pos, vel, mu, times, capture=0.0):
    """Positions (len(times), 2) of a coasting ship, not wrapped onto the torus.

    With a star (``mu > 0``) the path is the Kepler conic about the origin through
    ``engine.analytic.kepler``. The game's kick-then-drift step stores the velocity half a
    frame behind the position (it is leapfrog's v_{n-1/2}), so the conic starts from
    ``v + a(p) / 2``. Without a star: ``p + v t``. Compare with other positions by nearest image.
    """
    times = np.asarray(times, dtype=float)
    p = np.asarray(pos, dtype=float)
    v = np.asarray(vel, dtype=float)
    if mu > 0.0 and (p[0] != 0.0 or p[1] != 0.0):
        v0 = v + 0.5 * star_accel(p, mu, capture)
        path, _ = _kepler()(p, v0, mu, times)
        if np.all(np.isfinite(path)):
            return path
    return p + times[:, None] * v


def torpedo_path(p0, v0, rules, mu, times):
    """Positions of a torpedo from launch point ``p0`` with velocity ``v0`` after ``times`` frames.

    Straight (``p0 + v0 t``) unless the rules make torpedoes feel the star (newtonian mode),
    then a Kepler conic through :func:`predict_path` (same half-kick shift as a ship's).
    """
    times = np.asarray(times, dtype=float)
    if mu > 0.0 and rules.torpedoes_feel_star:
        return predict_path(p0, v0, mu, times, rules.star_capture)
    return np.asarray(p0, dtype=float) + times[:, None] * np.asarray(v0, dtype=float)


def lead_intercept(shooter_pos, shooter_vel, target_path, times, offset, speed):
    """Firing heading and meeting time for a torpedo against a predicted target path.

    A torpedo fired now on heading u is at ``p_s + offset u + t (v_s + speed u)`` after t frames
    (straight flight). It meets the target at time t when ``D(t) = E(t) - p_s - t v_s`` (nearest
    image) satisfies ``|D(t)| = offset + speed t``; the heading is then ``atan2(D(t))``. The
    first root is found on the sampled ``times`` (f(t) = |D| - offset - speed t changes sign)
    and refined by linear interpolation. Returns (t, heading) or None if no root in ``times``.
    """
    times = np.asarray(times, dtype=float)
    drift = np.asarray(shooter_pos) + times[:, None] * np.asarray(shooter_vel)
    d = wrap(np.asarray(target_path) - drift)
    f = np.hypot(d[:, 0], d[:, 1]) - (offset + speed * times)
    below = np.nonzero(f <= 0.0)[0]
    if below.size == 0:
        return None
    i = int(below[0])
    if i == 0:
        t, dt = float(times[0]), d[0]
    else:
        frac = f[i - 1] / (f[i - 1] - f[i])
        t = float(times[i - 1] + frac * (times[i] - times[i - 1]))
        dt = d[i - 1] + frac * (d[i] - d[i - 1])
    return t, math.atan2(dt[1], dt[0])


def lead_straight(shooter_pos, shooter_vel, target_pos, target_vel, offset, speed):
    """Closed-form lead for a target moving in a straight line (no star): (t, heading) or None.

    With d = target - shooter (nearest image) and w = v_target - v_shooter, the torpedo meets
    the target when ``|d + w t| = offset + speed t``, i.e. the quadratic
    ``(w.w - s^2) t^2 + 2 (d.w - offset s) t + (d.d - offset^2) = 0``; the smallest root t > 0
    is taken and the heading is the direction of ``d + w t``.
    """
    d = torus_delta(shooter_pos, target_pos)
    w = np.asarray(target_vel, dtype=float) - np.asarray(shooter_vel, dtype=float)
    a = float(w @ w) - speed * speed
    b = 2.0 * (float(d @ w) - offset * speed)
    c = float(d @ d) - offset * offset
    if abs(a) < 1e-18:
        roots = [-c / b] if b != 0.0 else []
    else:
        disc = b * b - 4.0 * a * c
        if disc < 0.0:
            return None
        sq = math.sqrt(disc)
        roots = [(-b - sq) / (2.0 * a), (-b + sq) / (2.0 * a)]
    roots = sorted(t for t in roots if t > 0.0)
    if not roots:
        return None
    t = roots[0]
    aim = d + w * t
    return t, math.atan2(aim[1], aim[0])


def diamond_hits(rel, box, diamond):
    """The game's hit test on relative positions ``rel`` (..., 2), already nearest-image:
    ``|dx| < box and |dy| < box and |dx| + |dy| < diamond`` (the 1962 program's diamond;
    ``rules.hit_box`` 12 points, ``rules.hit_diamond`` 18)."""
    ax = np.abs(rel[..., 0])
    ay = np.abs(rel[..., 1])
    return (ax < box) & (ay < box) & (ax + ay < diamond)


def first_hit(launch_pos, launch_vel, target_path, times, rules, mu, shrink=1.0):
    """First time in ``times`` at which a torpedo meets ``target_path`` by the diamond test
    (hit box scaled by ``shrink`` for a safety margin), or None."""
    path = torpedo_path(launch_pos, launch_vel, rules, mu, times)
    hits = diamond_hits(wrap(np.asarray(target_path) - path), shrink * rules.hit_box,
                        shrink * rules.hit_diamond)
    idx = np.nonzero(hits)[0]
    return None if idx.size == 0 else float(np.asarray(times)[idx[0]])


def launch_state(ship, heading, rules):
    """Where a torpedo fired now on ``heading`` starts, and its velocity (as the game's
    ``core._fire``): ``p0 = pos + launch_offset u``, ``v0 = vel + muzzle_speed u`` with
    ``u = (cos heading, sin heading)``. Returns ``(p0, v0)``, p0 not wrapped."""
    c, s = math.cos(heading), math.sin(heading)
    p0 = np.array([ship.pos[0] + rules.launch_offset * c, ship.pos[1] + rules.launch_offset * s])
    v0 = np.array([ship.vel[0] + rules.muzzle_speed * c, ship.vel[1] + rules.muzzle_speed * s])
    return p0, v0


def ram_escape(d, w, distance, horizon):
    """Unit direction to move to avoid a collision, or None when there is none to avoid.

    ``d``: the other body relative to me (nearest image), ``w``: its velocity relative to me.
    Straight relative motion is closest at ``t* = -d.w / |w|^2``; if ``0 <= t* <= horizon`` and
    the miss ``c = d + w t*`` is shorter than ``distance``, return ``-c / |c|`` (moving that way
    widens the miss), or a perpendicular of w when c is nearly zero (a head-on approach).
    """
    ww = float(w[0] * w[0] + w[1] * w[1])
    if ww < 1e-14:
        return None
    t = -float(d[0] * w[0] + d[1] * w[1]) / ww
    if t < 0.0 or t > horizon:
        return None
    c = np.asarray(d, dtype=float) + t * np.asarray(w, dtype=float)
    cn = math.hypot(c[0], c[1])
    if cn >= distance:
        return None
    if cn < 1e-6:
        return np.array([-w[1], w[0]]) / math.sqrt(ww)
    return -c / cn
