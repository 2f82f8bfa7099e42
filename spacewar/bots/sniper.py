"""sniper: predicts the enemy's orbit about the star and fires with lead, from a safe orbit."""
import math

import numpy as np

from spacewar.protocol import NOOP, Action
from spacewar.bots.geometry import (angle_diff, diamond_hits, first_hit, heading_after, launch_state,
                       lead_intercept, periapsis, predict_path, safe_heading_near, safest_heading,
                       star_accel, steer, torpedo_path, torus_delta, warm_up, wrap)


class Sniper:
    """A marksman: keeps a safe orbit, predicts where the enemy will be and shoots ahead of it.

    **Prediction.** The enemy's path over the next frames is the Kepler conic about the star
    at the origin (``engine.analytic.kepler`` with ``mu = obs.star_mu``, started from
    ``v + a(p)/2`` because the game's kick-then-drift step stores the velocity half a frame
    behind the position), or a straight line when ``star_mu == 0``, plus ``a t^2 / 2`` for
    the enemy's mean thrust ``a`` estimated from its last frames (:meth:`track`; zero for a
    coasting ship). Positions are compared by nearest image on the torus.

    **Lead.** A torpedo fired now on heading u starts at ``p + offset u`` with velocity
    ``v + muzzle u`` and (classic mode) flies straight, so it meets the predicted enemy
    position E(t) when ``|D(t)| = offset + muzzle t`` with ``D(t) = E(t) - p - v t`` (nearest
    image); the firing heading is ``atan2(D(t))`` at the first such t (see
    :func:`geometry.lead_intercept`). Where torpedoes feel the star (newtonian mode) the aim
    point is corrected twice by the miss of a Kepler-propagated torpedo.

    **Firing.** It fires when the heading it will have after this frame's turn gives a
    predicted hit by the game's own diamond test, shrunk by ``aim_shrink`` for margin
    (:func:`geometry.first_hit`), within ``shot_time`` frames. Not wasting torpedoes: the
    longest accepted flight shrinks as the magazine empties (``shot_time = clip(base + per
    torpedo left, lo, torpedo_life - 1)``), no shot is taken while one of its own torpedoes in
    flight is already predicted to hit, and none at an enemy whose path falls into the star
    before the torpedo would arrive.

    **Flying.** Safety first: when its own periapsis (``q = h^2 / (mu (1 + e))``, see
    :func:`geometry.periapsis`) is below ``q_min`` it burns in the direction that raises q most
    until q is above ``1.5 q_min``. Otherwise it coasts, unless the enemy is out of shot (no
    solution within ``shot_time``: it wants to close at ``min(approach_speed, gain (distance -
    max_range / 2))``), too close (below ``min_range``: it wants to open at ``retreat_speed``)
    or passing sideways faster than ``max_rel_speed`` (that part is damped). The velocity
    change ``(closing_wanted - closing_now) u`` (u the unit vector to the enemy, nearest image;
    plus the sideways damping; never speeding up past ``max_speed``) is burnt along the
    nearest direction that keeps its periapsis above ``1.3 q_min``, and only while more than
    ``fuel_reserve`` fuel is left (the rest is for the star).
    """

    def __init__(self, seed=None, q_min=0.08, aim_shrink=0.6, shot_base=35.0, shot_per_torpedo=1.8,
                 shot_min=40.0, min_range=0.1, max_range=0.3, approach_speed=1.0e-3,
                 retreat_speed=6e-4, max_speed=1.4e-3, max_rel_speed=1.6e-3, nav_tolerance=4e-4,
                 burn_frames=12, fuel_reserve=250.0, gain=0.01, thrust_smoothing=0.1,
                 thrust_weight=1.0):
        self.seed = seed
        self.q_min = q_min
        self.aim_shrink = aim_shrink
        self.shot_base = shot_base
        self.shot_per_torpedo = shot_per_torpedo
        self.shot_min = shot_min
        self.min_range = min_range
        self.max_range = max_range
        self.approach_speed = approach_speed
        self.retreat_speed = retreat_speed
        self.max_speed = max_speed
        self.max_rel_speed = max_rel_speed
        self.nav_tolerance = nav_tolerance
        self.burn_frames = burn_frames
        self.fuel_reserve = fuel_reserve
        self.gain = gain
        self.thrust_smoothing = thrust_smoothing
        self.thrust_weight = thrust_weight
        self.enemy_thrust = np.zeros(2)
        self._last = None
        self.escaping = False
        self._times = None
        self.mode = ""
        warm_up()

    def reset(self):
        self.escaping = False
        self.enemy_thrust = np.zeros(2)
        self._last = None

    # -- helpers ----------------------------------------------------------------------
    def times(self, rules):
        """Frames 1 .. torpedo_life - 1 after launch: when a torpedo can hit."""
        n = max(int(rules.torpedo_life) - 1, 1)
        if self._times is None or self._times.shape[0] != n:
            self._times = np.arange(1.0, n + 1.0)
        return self._times

    def shot_time(self, obs):
        """Longest torpedo flight worth a shot: shorter as the magazine empties."""
        life = obs.rules.torpedo_life - 1
        return float(np.clip(self.shot_base + self.shot_per_torpedo * obs.me.torpedoes,
                             min(self.shot_min, life), life))

    def track(self, obs):
        """Update the estimate of the enemy's own (engine) acceleration.

        Between two consecutive frames the game did ``v' = v + a_star(p) + a_thrust`` (plus
        Coulomb / ship gravity in the newer modes), so ``a_thrust = v' - v - a_star(p)``; it is
        smoothed by an exponential average of weight ``thrust_smoothing``. Reset whenever the
        enemy is not visible on two consecutive frames of one round.
        """
        enemy = obs.enemy
        visible = enemy.alive and not enemy.in_hyperspace
        key = (obs.round, obs.round_frame)
        prev = self._last
        self._last = None
        if visible:
            self._last = (key, np.array(enemy.pos, dtype=float), np.array(enemy.vel, dtype=float))
        if (not visible or prev is None or prev[0][0] != key[0] or prev[0][1] + 1 != key[1]):
            self.enemy_thrust = np.zeros(2)
            return
        a = (self._last[2] - prev[2]) - star_accel(prev[1], obs.star_mu, obs.star_capture)
        if math.hypot(a[0], a[1]) > 4.0 * obs.rules.thrust + 1e-12:
            return  # not a thrust (a wrap glitch or a collision): ignore
        k = self.thrust_smoothing
        self.enemy_thrust = (1.0 - k) * self.enemy_thrust + k * a

    def enemy_path(self, obs):
        """The enemy's predicted (unwrapped) positions at ``times`` frames from now: the Kepler
        conic plus ``thrust_weight a_thrust t^2 / 2`` for its estimated mean thrust."""
        enemy = obs.enemy
        times = self.times(obs.rules)
        path = predict_path(enemy.pos, enemy.vel, obs.star_mu, times, obs.star_capture)
        if self.thrust_weight > 0.0 and np.any(self.enemy_thrust != 0.0):
            path = path + (0.5 * self.thrust_weight) * (times * times)[:, None] * self.enemy_thrust
        return path

    def solve(self, obs, path):
        """(meeting time, firing heading) against ``path``, or None (see the class docstring)."""
        me, rules, mu = obs.me, obs.rules, obs.star_mu
        times = self.times(rules)
        sol = lead_intercept(me.pos, me.vel, path, times, rules.launch_offset, rules.muzzle_speed)
        if sol is None or not (rules.torpedoes_feel_star and mu > 0.0):
            return sol
        shift = np.zeros(2)
        for _ in range(2):  # the torpedo's path bends: aim off by its miss
            p0, v0 = launch_state(me, sol[1], rules)
            k = min(int(round(sol[0])) - 1, times.shape[0] - 1)
            k = max(k, 0)
            tp = torpedo_path(p0, v0, rules, mu, times[k:k + 1])[0]
            straight = p0 + times[k] * v0
            shift = shift + (tp - straight)
            new = lead_intercept(me.pos, me.vel, path - shift, times, rules.launch_offset,
                                 rules.muzzle_speed)
            if new is None:
                return sol
            sol = new
        return sol

    def doomed_before(self, obs, path, t):
        """True if the coasting enemy falls into the star within ``t`` frames."""
        if obs.star_mu <= 0.0:
            return False
        n = max(1, min(int(math.ceil(t)), path.shape[0]))
        r2 = path[:n, 0] ** 2 + path[:n, 1] ** 2
        return bool(np.any(r2 < (1.2 * obs.star_capture) ** 2))

    def pending_hit(self, obs, path):
        """True if one of my torpedoes in flight is predicted to hit the coasting enemy."""
        mine = [t for t in obs.torpedoes if t.mine]
        if not mine:
            return False
        rules = obs.rules
        times = self.times(rules)
        pos = np.array([t.pos for t in mine])
        vel = np.array([t.vel for t in mine])
        ttl = np.array([t.ttl for t in mine])
        tp = pos[:, None, :] + times[None, :, None] * vel[:, None, :]
        hits = diamond_hits(wrap(path[None, :, :] - tp), rules.hit_box, rules.hit_diamond)
        hits &= times[None, :] < ttl[:, None]
        return bool(hits.any())

    def fire_ok(self, obs, turn, path):
        """Fire this frame? Only for a predicted hit (shrunk hit box) within ``shot_time``."""
        me, enemy, rules = obs.me, obs.enemy, obs.rules
        if (me.torpedoes <= 0 or me.reload > 0 or not enemy.alive or enemy.in_hyperspace
                or path is None):
            return False
        p0, v0 = launch_state(me, heading_after(me, turn, rules), rules)
        t = first_hit(p0, v0, path, self.times(rules), rules, obs.star_mu, self.aim_shrink)
        if t is None or t > self.shot_time(obs):
            return False
        if self.doomed_before(obs, path, t):
            return False
        return not self.pending_hit(obs, path)

    def safety(self, obs):
        """An escape Action when the own periapsis is too low, else None."""
        me, rules, mu = obs.me, obs.rules, obs.star_mu
        if mu <= 0.0:
            self.escaping = False
            return None
        q = periapsis(me.pos, me.vel, mu)
        if q >= self.q_min * (1.5 if self.escaping else 1.0):
            self.escaping = False
            return None
        self.escaping = True
        target, _ = safest_heading(me.pos, me.vel, mu, me.heading, rules.thrust * self.burn_frames)
        turn = steer(me, target, rules)
        thrust = abs(angle_diff(target, me.heading)) < 0.8
        return Action(turn=turn, thrust=bool(thrust))

    def navigation(self, obs, in_shot):
        """The velocity change wanted relative to the enemy, or None to stay on this orbit."""
        me, enemy = obs.me, obs.enemy
        if me.fuel <= self.fuel_reserve:
            return None
        d = torus_delta(me.pos, enemy.pos)
        dist = math.hypot(d[0], d[1])
        unit = d / max(dist, 1e-12)
        v_me = np.asarray(me.vel, dtype=float)
        rel = v_me - np.asarray(enemy.vel, dtype=float)  # my velocity relative to the enemy
        closing_now = float(rel @ unit)
        across = rel - closing_now * unit
        if not in_shot and dist > self.min_range:
            closing = min(self.approach_speed, self.gain * max(dist - 0.5 * self.max_range, 0.0))
        elif dist < self.min_range:
            closing = -self.retreat_speed
        else:
            closing = closing_now
        # change the closing speed as wanted; damp the sideways relative speed only past a limit
        corr = (closing - closing_now) * unit
        side = math.hypot(across[0], across[1])
        if side > self.max_rel_speed:
            corr -= across * (1.0 - self.max_rel_speed / side)
        new = v_me + corr
        speed = math.hypot(new[0], new[1])
        if speed > self.max_speed and speed > math.hypot(v_me[0], v_me[1]):
            corr -= new * (1.0 - self.max_speed / speed)  # not faster than max_speed
        if math.hypot(corr[0], corr[1]) <= self.nav_tolerance:
            return None
        return corr

    # -- the bot ------------------------------------------------------------------------
    def act(self, obs):
        me = obs.me
        self.track(obs)
        if not me.alive or me.in_hyperspace:
            return NOOP
        return self.decide(obs)

    def decide(self, obs):
        """The Action of a live ship out of hyperspace."""
        enemy = obs.enemy
        visible = enemy.alive and not enemy.in_hyperspace
        path = self.enemy_path(obs) if visible else None
        escape = self.safety(obs)
        if escape is not None:
            self.mode = "escape"
            fire = self.fire_ok(obs, escape.turn, path)
            return Action(turn=escape.turn, thrust=escape.thrust, fire=fire)
        if not visible:
            self.mode = "wait"
            return NOOP
        return self.engage(obs, path)

    def engage(self, obs, path):
        """Navigate or aim at the coasting enemy's predicted path (no star emergency)."""
        me, rules, mu = obs.me, obs.rules, obs.star_mu
        sol = self.solve(obs, path)
        in_shot = sol is not None and sol[0] <= self.shot_time(obs)
        corr = self.navigation(obs, in_shot)
        if corr is not None:
            self.mode = "navigate"
            want = math.atan2(corr[1], corr[0])
            nav, safe = safe_heading_near(me.pos, me.vel, mu, want, rules.thrust * self.burn_frames,
                                          self.q_min * 1.3, heading=me.heading)
            turn = steer(me, nav, rules)
            thrust = safe and abs(angle_diff(nav, me.heading)) < 0.35
            return Action(turn=turn, thrust=bool(thrust), fire=self.fire_ok(obs, turn, path))
        self.mode = "aim"
        if sol is not None:
            target = sol[1]
        else:
            d = torus_delta(me.pos, obs.enemy.pos)
            target = math.atan2(d[1], d[0])
        turn = steer(me, target, rules)
        return Action(turn=turn, fire=self.fire_ok(obs, turn, path))
