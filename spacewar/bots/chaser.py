"""chaser: closes in on the enemy, points at it and fires, without falling into the star."""
import math

import numpy as np

from spacewar.protocol import NOOP, Action
from spacewar.bots.geometry import (angle_diff, heading_after, lead_straight, periapsis, ram_escape,
                       safe_heading_near, safest_heading, steer, torus_delta)


class Chaser:
    """A pursuit bot: fly to the enemy, point at it, fire when aligned.

    Each frame, in order of priority:

    1. **The star.** The periapsis of its own coasting path about the star (Kepler invariants,
       ``q = h^2 / (mu (1 + e))``, see :func:`geometry.periapsis`) must stay above ``q_min``.
       When it is lower the ship turns to the thrust direction that raises q most (tried over
       32 directions for a burn of ``burn_frames`` frames) and burns until q is back above
       ``1.5 q_min``.
    2. **Pursuit.** It wants to close on the enemy (nearest image on the torus) at a speed
       ``clip(gain (distance - standoff), -retreat_speed, approach_speed)``, i.e. it wants the
       velocity ``v_want = v_enemy + closing u`` (u the unit vector to the enemy), capped at
       ``max_speed`` (a fast ship crosses the torus and meets the star again and again). When
       ``|v_want - v_me|`` exceeds ``nav_tolerance`` and more than ``fuel_reserve`` fuel is
       left (the rest is kept for the star) it turns to that correction and burns along it,
       but only along a direction whose burn keeps the periapsis above ``1.3 q_min`` (the
       nearest safe direction to the wanted one, see :func:`geometry.safe_heading_near`: when
       the straight path to the enemy passes the star it steers tangentially around the star
       instead of through it).
       If the straight relative motion brings the enemy within ``ram_distance`` in the next
       ``ram_horizon`` frames (a collision kills both), the wanted velocity change is instead
       away from the enemy's closest-approach point (:func:`geometry.ram_escape`).
    3. **Attack.** Otherwise it turns to the enemy with a straight-line lead (the torpedo
       meets the target when ``|d + w t| = offset + muzzle t``, see
       :func:`geometry.lead_straight`) and fires when the heading after this frame's turn is
       within ``atan(aim_margin hit_box / distance)`` of it and the enemy is within
       ``fire_range``. Its shots ignore the star's pull on the target: that is the sniper's job.
       It also takes such a shot whenever one lines up while it is busy with 1 or 2.
    """

    def __init__(self, seed=None, q_min=0.06, fire_range=0.24, standoff=0.1, gain=0.01,
                 approach_speed=1.6e-3, retreat_speed=8e-4, nav_tolerance=5e-4, burn_frames=12,
                 aim_margin=0.8, fire_cone=math.radians(6.0), ram_distance=0.04, ram_horizon=50,
                 max_speed=1.6e-3, fuel_reserve=250.0):
        self.seed = seed
        self.q_min = q_min
        self.fire_range = fire_range
        self.standoff = standoff
        self.gain = gain
        self.approach_speed = approach_speed
        self.retreat_speed = retreat_speed
        self.nav_tolerance = nav_tolerance
        self.burn_frames = burn_frames
        self.aim_margin = aim_margin
        self.fire_cone = fire_cone
        self.ram_distance = ram_distance
        self.ram_horizon = ram_horizon
        self.max_speed = max_speed
        self.fuel_reserve = fuel_reserve
        self.escaping = False

    def reset(self):
        self.escaping = False

    def act(self, obs):
        me, enemy, rules = obs.me, obs.enemy, obs.rules
        if not me.alive or me.in_hyperspace:
            return NOOP
        mu = obs.star_mu
        dv = rules.thrust * self.burn_frames
        # 1. the star
        if mu > 0.0:
            q = periapsis(me.pos, me.vel, mu)
            limit = self.q_min * (1.5 if self.escaping else 1.0)
            if q < limit:
                self.escaping = True
                target, _ = safest_heading(me.pos, me.vel, mu, me.heading, dv)
                turn = steer(me, target, rules)
                thrust = abs(angle_diff(target, me.heading)) < 0.8
                return Action(turn=turn, thrust=bool(thrust), fire=self._fire(obs, turn))
            self.escaping = False
        if not enemy.alive or enemy.in_hyperspace:
            return NOOP
        # 2. pursuit
        d = torus_delta(me.pos, enemy.pos)
        dist = math.hypot(d[0], d[1])
        unit = d / max(dist, 1e-12)
        closing = float(np.clip(self.gain * (dist - self.standoff),
                                -self.retreat_speed, self.approach_speed))
        v_rel = np.asarray(me.vel) - np.asarray(enemy.vel)
        want = np.asarray(enemy.vel) + closing * unit
        speed = math.hypot(want[0], want[1])
        if speed > self.max_speed:
            want *= self.max_speed / speed
        corr = want - np.asarray(me.vel)
        dodge = ram_escape(d, -v_rel, self.ram_distance, self.ram_horizon)
        if dodge is not None:
            corr = dodge * self.approach_speed
        aim = self._aim(obs, d)
        if math.hypot(corr[0], corr[1]) > self.nav_tolerance and me.fuel > self.fuel_reserve:
            want = math.atan2(corr[1], corr[0])
            nav, safe = safe_heading_near(me.pos, me.vel, mu, want, dv, self.q_min * 1.3,
                                          heading=me.heading)
            turn = steer(me, nav, rules)
            thrust = safe and abs(angle_diff(nav, me.heading)) < 0.35
            return Action(turn=turn, thrust=bool(thrust), fire=self._fire(obs, turn, aim))
        # 3. attack
        turn = steer(me, aim, rules)
        return Action(turn=turn, fire=self._fire(obs, turn, aim))

    def _aim(self, obs, d=None):
        me, enemy, rules = obs.me, obs.enemy, obs.rules
        lead = lead_straight(me.pos, me.vel, enemy.pos, enemy.vel, rules.launch_offset,
                             rules.muzzle_speed)
        if lead is not None and lead[0] < rules.torpedo_life:
            return lead[1]
        if d is None:
            d = torus_delta(me.pos, enemy.pos)
        return math.atan2(d[1], d[0])

    def _fire(self, obs, turn, aim=None):
        """Fire if the enemy is in range and the heading after ``turn`` is on the aim."""
        me, enemy, rules = obs.me, obs.enemy, obs.rules
        if (not enemy.alive or enemy.in_hyperspace or me.torpedoes <= 0 or me.reload > 0):
            return False
        d = torus_delta(me.pos, enemy.pos)
        dist = math.hypot(d[0], d[1])
        if dist > self.fire_range:
            return False
        if aim is None:
            aim = self._aim(obs, d)
        cone = min(self.fire_cone, math.atan2(self.aim_margin * rules.hit_box, dist))
        return abs(angle_diff(aim, heading_after(me, turn, rules))) < cone
