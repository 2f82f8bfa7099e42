"""dodger: sidesteps incoming torpedoes (hyperspace as a last resort), snipes when safe."""
import math

import numpy as np

from spacewar.protocol import Action
from spacewar.bots.geometry import (angle_diff, diamond_hits, periapsis, predict_path, star_accel, steer,
                       wrap)
from spacewar.bots.sniper import Sniper


class Dodger(Sniper):
    """The sniper's aim and orbit keeping, plus torpedo evasion.

    **Threats.** Every enemy torpedo is followed over the next ``horizon`` frames of its life
    (straight flight, ``P + k V``) against the dodger's own coasting path (the Kepler conic of
    :func:`geometry.predict_path`); for each the closest approach (time ``t_c`` and miss vector
    ``c`` = torpedo minus ship, nearest image) is taken over integer frames. A torpedo whose
    miss is below ``danger`` is a threat; the earliest one is dodged.

    **Dodge.** With ``w`` the torpedo's velocity relative to the ship and ``n`` a unit normal
    of w, moving the ship by ``x s`` changes the miss to ``c - x s``; so it burns along
    ``s = -sign(c.n) n`` (widening the miss on the side it already lies; when the torpedo is
    dead on, the normal needing less turning). Of the two normals it never takes one whose
    burn would bring its periapsis below ``q_min`` if the other is safe. It thrusts while its
    heading is within ``thrust_cone`` of s. The lateral shift reachable before the torpedo
    arrives is ``a (t_c - t_turn)^2 / 2`` (a the thrust, t_turn the frames to turn to s).

    **Hyperspace.** Only when the torpedo is predicted to hit by the game's diamond test
    within ``hyper_frames`` frames and the shift reachable by then cannot clear it (each jump
    risks breaking up, k/8 on jump k).

    **Electric mode.** While dodging a torpedo whose charge is opposite to its own (so it is
    drawn in), it presses ``flip`` to take the torpedo's sign and repel it.

    With no threat it plays the :class:`Sniper`.
    """

    def __init__(self, seed=None, horizon=80, danger=0.024, clearance=0.026, hyper_frames=4,
                 thrust_cone=1.0, **sniper_options):
        super().__init__(seed=seed, **sniper_options)
        self.horizon = horizon
        self.danger = danger
        self.clearance = clearance
        self.hyper_frames = hyper_frames
        self.thrust_cone = thrust_cone
        self._threat_times = None

    def threat(self, obs):
        """The most urgent torpedo threat, or None: ``(t_c, c, w, t_hit, charge)`` with t_c the
        time of closest approach, c the miss vector then, w the torpedo's velocity relative to
        the ship, t_hit the first frame the diamond test would hit (None if it misses) and the
        torpedo's charge."""
        theirs = [t for t in obs.torpedoes if not t.mine and t.ttl > 1]
        if not theirs:
            return None
        me, rules = obs.me, obs.rules
        pos = np.array([t.pos for t in theirs])
        vel = np.array([t.vel for t in theirs])
        ttl = np.array([t.ttl for t in theirs])
        # cheap first pass: straight relative motion, with a generous margin for the star's
        # pull on the ship (a t^2 / 2) and for the ship's own burns
        d = wrap(pos - np.asarray(me.pos))
        w = vel - np.asarray(me.vel)
        ww = np.maximum((w * w).sum(axis=1), 1e-18)
        t_c = np.clip(-(d * w).sum(axis=1) / ww, 0.0, np.minimum(ttl, self.horizon))
        miss = d + t_c[:, None] * w
        g = float(np.hypot(*star_accel(me.pos, obs.star_mu, obs.star_capture)))
        margin = 2.0 * self.danger + 0.5 * (g + rules.thrust) * t_c * t_c
        near = (miss * miss).sum(axis=1) < margin * margin
        if not near.any():
            return None
        charge = np.array([t.charge for t in theirs])[near]
        pos, vel, ttl = pos[near], vel[near], ttl[near]
        n = max(1, min(self.horizon, int(ttl.max()) - 1))
        if self._threat_times is None or self._threat_times.shape[0] != n:
            self._threat_times = np.arange(1.0, n + 1.0)
        times = self._threat_times
        my_path = predict_path(me.pos, me.vel, obs.star_mu, times, obs.star_capture)
        rel = wrap(pos[:, None, :] + times[None, :, None] * vel[:, None, :] - my_path[None, :, :])
        dist2 = rel[..., 0] ** 2 + rel[..., 1] ** 2
        dist2 = np.where(times[None, :] < ttl[:, None], dist2, np.inf)
        k = np.argmin(dist2, axis=1)
        rows = np.arange(pos.shape[0])
        best = dist2[rows, k]
        danger = best < self.danger ** 2
        if not danger.any():
            return None
        idx = np.nonzero(danger)[0]
        j = int(idx[np.argmin(k[idx])])
        hits = np.nonzero(diamond_hits(rel[j], rules.hit_box, rules.hit_diamond)
                          & (times < ttl[j]))[0]
        t_hit = float(times[hits[0]]) if hits.size else None
        return (float(times[k[j]]), rel[j, k[j]].copy(), vel[j] - np.asarray(me.vel), t_hit,
                float(charge[j]))

    def dodge(self, obs, threat):
        """The evasive Action against ``threat`` (see the class docstring)."""
        me, rules, mu = obs.me, obs.rules, obs.star_mu
        t_c, c, w, t_hit, charge = threat
        wn = math.hypot(w[0], w[1])
        if wn < 1e-12:
            normal = np.array([1.0, 0.0])
        else:
            normal = np.array([-w[1], w[0]]) / wn
        cn = float(c @ normal)
        options = [-normal, normal] if cn > 0.0 else [normal, -normal]
        if abs(cn) < 0.2 * rules.hit_box:  # dead on: the side needing less turning first
            options.sort(key=lambda s: abs(angle_diff(math.atan2(s[1], s[0]), me.heading)))
        if mu > 0.0:
            dv = rules.thrust * self.burn_frames
            vel = np.asarray(me.vel, dtype=float)
            safe = [periapsis(me.pos, vel + dv * s, mu) >= self.q_min for s in options]
            if not safe[0] and safe[1]:
                options.reverse()
        s = options[0]
        target = math.atan2(s[1], s[0])
        off = abs(angle_diff(target, me.heading))
        t_turn = max(0.0, off - self.thrust_cone) / rules.turn_rate
        t_arrive = t_c if t_hit is None else t_hit
        reach = 0.5 * rules.thrust * max(0.0, t_arrive - t_turn) ** 2
        need = self.clearance - abs(cn)
        if (t_hit is not None and t_hit <= self.hyper_frames and reach < need
                and me.hyperspace > 0 and me.hyperspace_recharge == 0):
            self.mode = "hyperspace"
            return Action(hyperspace=True)
        self.mode = "dodge"
        turn = steer(me, target, rules)
        thrust = off < self.thrust_cone and me.fuel > 0.0
        visible = obs.enemy.alive and not obs.enemy.in_hyperspace
        fire = self.fire_ok(obs, turn, self.enemy_path(obs)) if visible else False
        # electric mode: a torpedo of the opposite charge is drawn in; take its sign to repel it
        flip = rules.mode == "electric" and charge * me.charge < 0.0
        return Action(turn=turn, thrust=bool(thrust), fire=fire, flip=bool(flip))

    def decide(self, obs):
        threat = self.threat(obs)
        if threat is not None:
            return self.dodge(obs, threat)
        return super().decide(obs)
