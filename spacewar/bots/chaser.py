"""chaser: turns to the enemy, thrusts towards it, fires when aligned."""
import math

import numpy as np

from ..protocol import Action
from .geometry import angle_diff, torus_delta, turn_towards


class Chaser:
    """Points at the enemy (nearest image), thrusts while the enemy is far and the ship is
    not already closing fast, fires when the heading is within a few degrees; steers away
    from the star when falling towards it."""

    def __init__(self, fire_cone=math.radians(6.0), star_margin=0.12):
        self.fire_cone = fire_cone
        self.star_margin = star_margin

    def act(self, obs):
        me, enemy, rules = obs.me, obs.enemy, obs.rules
        if not me.alive or me.in_hyperspace:
            return Action()
        r = float(np.hypot(*me.pos))
        if obs.star_mu > 0 and r < self.star_margin:
            # escape: point away from the star and burn
            away = math.atan2(me.pos[1], me.pos[0])
            return Action(turn=turn_towards(me.heading, away, rules), thrust=True)
        if not enemy.alive or enemy.in_hyperspace:
            return Action()
        d = torus_delta(me.pos, enemy.pos)
        bearing = math.atan2(d[1], d[0])
        off = abs(angle_diff(bearing, me.heading))
        closing = -float(np.dot(torus_delta(me.vel, enemy.vel), d)) / max(np.hypot(*d), 1e-12)
        thrust = off < 0.5 and np.hypot(*d) > 0.15 and closing < 2.5e-3
        return Action(turn=turn_towards(me.heading, bearing, rules), thrust=bool(thrust),
                      fire=off < self.fire_cone)
