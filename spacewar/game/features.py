"""Observations for learning code: egocentric, fixed-length, scaled to about [-1, 1], float32.

``learning_layout(rules)`` names the entries; ``write_learning`` (numba) writes one match's
two seats into rows of a preallocated ``(M, 2, D)`` float32 buffer inside compiled code, and
``learning_vector(raw, rules)`` computes the same numbers in NumPy from a bot's raw observation
(``Game.raw_observation``), the readable reference the tests hold the compiled writer to.

Egocentric: the star, the enemy and every torpedo are given relative to the own ship, by the
nearest image on the unit torus (``engine.space.nearest_image``), so a policy sees the same
numbers wherever on the torus a situation happens. Directions are in the arena's axes (not
rotated into the ship's heading; the heading is given as its cosine and sine). Scales:

- positions relative to the own ship: d / 0.5 (the torus's half side), in [-1, 1);
- velocities (own, and relative ones): v / (3 muzzle speeds), about [-1, 1] in play (a torpedo
  fired at the ship closes at up to twice the muzzle speed plus the ships' own);
- the rest as fractions of their rules' maxima (fuel, torpedoes, jumps, reload and recharge
  frames, flip cool-down, torpedo life, round frames), flags as 0 or 1, the charge as its sign.

The torpedo slots are fixed, each with a presence flag (an empty slot is all zeros): the own
ship's ``S`` first, then the enemy's ``S``. ``S = torpedo_slots(rules)`` is the most torpedoes
one ship can have in flight at once, not the ``T`` it carries (6 of 32 under the 1962 rules), and
a ship's k-th torpedo of a round sits in slot ``k mod S`` for all its life: a torpedo is seen
for ``torpedo_life - 1`` frames and a ship fires at most every ``max(reload, 1)`` frames, so
the torpedoes sharing a slot are never in flight together. A smaller observation is less memory
to write and to read for every agent-step, and fewer inputs to learn from.
"""
import math

import numpy as np

from engine import space

from spacewar.game import core
from spacewar.protocol import raw_layout
from spacewar.rules import Rules

jit = core.jit

HEADER = ("round_time_fraction", "rounds_fraction", "score_difference", "star_present",
          "star_strength", "electric")
OWN = ("vx", "vy", "cos_heading", "sin_heading", "turn_rate", "fuel_fraction",
       "torpedo_fraction", "hyperspace_fraction", "alive", "in_hyperspace", "reload_fraction",
       "recharge_fraction", "charge_sign", "flip_cooldown_fraction")
STAR = ("star_dx", "star_dy")
ENEMY = ("dx", "dy", "dvx", "dvy", "cos_heading", "sin_heading", "turn_rate", "fuel_fraction",
         "torpedo_fraction", "hyperspace_fraction", "alive", "in_hyperspace", "charge_sign")
TORPEDO = ("present", "dx", "dy", "dvx", "dvy", "ttl_fraction")

#: where each part starts in a learning observation
_OWN = len(HEADER)
_STAR = _OWN + len(OWN)
_ENEMY = _STAR + len(STAR)
_TORPEDOES = _ENEMY + len(ENEMY)
_NT = len(TORPEDO)


@jit()
def slots_in_flight(torpedoes, life, reload):
    """The most torpedoes one ship can have in flight at once: a torpedo is in flight (seen)
    for ``life - 1`` frames after the one it is fired in, and the next can be fired
    ``max(reload, 1)`` frames later, so ``(life - 2) // max(reload, 1) + 1``, at most
    ``torpedoes`` and at least 1."""
    if life < 2:
        return 1
    return max(1, min(torpedoes, (life - 2) // max(reload, 1) + 1))


def torpedo_slots(rules):
    """S, the learning observation's torpedo slots per ship under these rules.

    The same formula as the compiled code's, run by Python: reading a policy file validates
    its layout through this, and need not start numba's JIT (about 48 MiB resident) to do so."""
    plain = getattr(slots_in_flight, "py_func", slots_in_flight)  # NUMBA_DISABLE_JIT=1: itself
    return int(plain(int(rules.torpedoes), int(rules.torpedo_life), int(rules.reload)))


def learning_length(rules):
    """D, the length of a learning observation under these rules."""
    return _TORPEDOES + 2 * torpedo_slots(rules) * _NT


def learning_layout(rules):
    """Names of the learning observation's entries, in order (see the module's text)."""
    names = list(HEADER) + [f"me.{f}" for f in OWN] + list(STAR)
    names += [f"enemy.{f}" for f in ENEMY]
    for owner in ("mine", "enemy"):
        for k in range(torpedo_slots(rules)):
            names += [f"torpedo.{owner}{k}.{f}" for f in TORPEDO]
    return names


def learning_scales(rules, rounds):
    """The numbers that scale the entries, as one float64 vector for the compiled writer."""
    return np.array([
        1.0 / max(rules.max_round_frames, 1),              # 0 round frames
        1.0 / max(rounds, 1),                               # 1 rounds
        1.0 / 0.5,                                          # 2 positions: half the torus side
        1.0 / (3.0 * max(rules.muzzle_speed, 1e-300)),      # 3 velocities
        1.0 / max(4.0 * rules.turn_rate, 1e-300),           # 4 turn rate (the game's limit)
        1.0 / max(rules.fuel, 1e-300),                      # 5 fuel
        1.0 / max(rules.torpedoes, 1),                      # 6 torpedoes
        1.0 / max(rules.hyperspace_jumps, 1),               # 7 jumps
        1.0 / max(rules.reload, 1),                         # 8 reload
        1.0 / max(rules.hyperspace_recharge, 1),            # 9 recharge
        1.0 / max(rules.flip_cooldown, 1),                  # 10 flip cool-down
        1.0 / max(rules.torpedo_life, 1),                   # 11 torpedo life
        1.0 / Rules().star_mu,                              # 12 star strength: heavy = 1
        float(rules.mode == "electric"),                    # 13 electric mode
    ])


@jit(inline="always")
def _sign(x):
    return 1.0 if x > 0.0 else (-1.0 if x < 0.0 else 0.0)


@jit(inline="always")
def _write_gauges(out, o, m, s, ship_gauges, ship_counters, scales):
    """Ship s's heading (cos, sin), turn rate, fuel, torpedoes, jumps and flags from out[o]:
    the eight entries the own ship and the enemy share."""
    h = ship_gauges[m, s, core.HEADING]
    out[o] = math.cos(h)
    out[o + 1] = math.sin(h)
    out[o + 2] = ship_gauges[m, s, core.OMEGA] * scales[4]
    out[o + 3] = ship_gauges[m, s, core.FUEL] * scales[5]
    out[o + 4] = ship_counters[m, s, core.TORPS] * scales[6]
    out[o + 5] = ship_counters[m, s, core.HYPER_LEFT] * scales[7]
    out[o + 6] = ship_counters[m, s, core.ALIVE]
    out[o + 7] = ship_counters[m, s, core.IN_HYPER]


@jit(_nrt=False, inline="always")  # allocates nothing; inlined (see core's note)
def write_learning(m, seat, pos, vel, charge, active, ship_gauges, ship_counters, torp_life,
                   match_state, rules, scales, out):
    """Match ``m`` seen from ``seat`` as a learning observation, into ``out`` (float32, D)."""
    me = seat
    en = 1 - seat
    ntorp = int(rules[core.R_NTORP])
    side = 1.0
    sp = scales[2]
    sv = scales[3]
    x0 = pos[m, 0, me]
    y0 = pos[m, 1, me]
    vx0 = vel[m, 0, me]
    vy0 = vel[m, 1, me]
    # header
    out[0] = match_state[m, core.ROUND_FRAME] * scales[0]
    out[1] = match_state[m, core.ROUNDS_PLAYED] * scales[1]
    out[2] = (match_state[m, core.SCORE0 + me] - match_state[m, core.SCORE0 + en]) * scales[1]
    out[3] = 1.0 if rules[core.R_STAR] > 0.0 else 0.0
    out[4] = rules[core.R_STAR] * scales[12]
    out[5] = scales[13]
    # the own ship
    o = _OWN
    out[o] = vx0 * sv
    out[o + 1] = vy0 * sv
    _write_gauges(out, o + 2, m, me, ship_gauges, ship_counters, scales)
    out[o + 10] = ship_counters[m, me, core.RELOAD] * scales[8]
    out[o + 11] = ship_counters[m, me, core.HYPER_RECHARGE] * scales[9]
    out[o + 12] = _sign(charge[m, me])
    out[o + 13] = ship_counters[m, me, core.FLIP_CD] * scales[10]
    # the star at the origin, relative to the own ship
    out[_STAR] = space.wrap_scalar(0.0 - x0, side) * sp
    out[_STAR + 1] = space.wrap_scalar(0.0 - y0, side) * sp
    # the enemy
    e = _ENEMY
    out[e] = space.wrap_scalar(pos[m, 0, en] - x0, side) * sp
    out[e + 1] = space.wrap_scalar(pos[m, 1, en] - y0, side) * sp
    out[e + 2] = (vel[m, 0, en] - vx0) * sv
    out[e + 3] = (vel[m, 1, en] - vy0) * sv
    _write_gauges(out, e + 4, m, en, ship_gauges, ship_counters, scales)
    out[e + 12] = _sign(charge[m, en])
    # the torpedo slots, own first: the k-th torpedo in slot k mod S
    slots = slots_in_flight(ntorp, int(rules[core.R_TLIFE]), int(rules[core.R_RELOAD]))
    for j in range(_TORPEDOES, _TORPEDOES + 2 * slots * _NT):
        out[j] = 0.0
    for row in range(2):
        owner = me if row == 0 else en
        for k in range(ntorp):
            b = 2 + owner * ntorp + k
            if active[m, b]:
                o = _TORPEDOES + (row * slots + k % slots) * _NT
                out[o] = 1.0
                out[o + 1] = space.wrap_scalar(pos[m, 0, b] - x0, side) * sp
                out[o + 2] = space.wrap_scalar(pos[m, 1, b] - y0, side) * sp
                out[o + 3] = (vel[m, 0, b] - vx0) * sv
                out[o + 4] = (vel[m, 1, b] - vy0) * sv
                out[o + 5] = torp_life[m, owner * ntorp + k] * scales[11]


@jit(parallel=False)
def write_all_learning(pos, vel, charge, active, ship_gauges, ship_counters, torp_life,
                       match_state, rules, scales, out):
    """Every match's two seats into ``out`` (M, 2, D) float32."""
    for m in range(pos.shape[0]):
        for seat in range(2):
            write_learning(m, seat, pos, vel, charge, active, ship_gauges, ship_counters,
                           torp_life, match_state, rules, scales, out[m, seat])


def learning_vector(raw, rules, rounds):
    """The learning observation of one seat from its raw observation (``Game.raw_observation``),
    in NumPy: the readable definition the compiled writer follows, float32."""
    names = raw_layout(rules)
    r = dict(zip(names, np.asarray(raw, dtype=np.float64).tolist()))
    s = learning_scales(rules, rounds)
    sp, sv = s[2], s[3]

    def rel(x):
        return float(space.nearest_image(x, 1.0)) * sp

    def sign(x):
        return float(np.sign(x))

    x0, y0, vx0, vy0 = r["me.x"], r["me.y"], r["me.vx"], r["me.vy"]
    out = [r["round_frame"] * s[0], r["round"] * s[1], (r["score_me"] - r["score_enemy"]) * s[1],
           1.0 if r["star_mu"] > 0.0 else 0.0, r["star_mu"] * s[12], s[13]]
    out += [vx0 * sv, vy0 * sv, math.cos(r["me.heading"]), math.sin(r["me.heading"]),
            r["me.angular_velocity"] * s[4], r["me.fuel"] * s[5], r["me.torpedoes"] * s[6],
            r["me.hyperspace"] * s[7], r["me.alive"], r["me.in_hyperspace"], r["me.reload"] * s[8],
            r["me.hyperspace_recharge"] * s[9], sign(r["me.charge"]), r["me.flip_cooldown"] * s[10]]
    out += [rel(0.0 - x0), rel(0.0 - y0)]
    out += [rel(r["enemy.x"] - x0), rel(r["enemy.y"] - y0), (r["enemy.vx"] - vx0) * sv,
            (r["enemy.vy"] - vy0) * sv, math.cos(r["enemy.heading"]), math.sin(r["enemy.heading"]),
            r["enemy.angular_velocity"] * s[4], r["enemy.fuel"] * s[5], r["enemy.torpedoes"] * s[6],
            r["enemy.hyperspace"] * s[7], r["enemy.alive"], r["enemy.in_hyperspace"],
            sign(r["enemy.charge"])]
    slots = torpedo_slots(rules)
    torpedoes = [[0.0] * _NT for _ in range(2 * slots)]
    for k in range(2 * rules.torpedoes):  # the raw slots: own torpedoes in firing order, then the enemy's
        t = {f: r[f"torpedo{k}.{f}"] for f in ("present", "x", "y", "vx", "vy", "ttl")}
        if t["present"]:
            row, fired = divmod(k, rules.torpedoes)
            torpedoes[row * slots + fired % slots] = [
                1.0, rel(t["x"] - x0), rel(t["y"] - y0), (t["vx"] - vx0) * sv,
                (t["vy"] - vy0) * sv, t["ttl"] * s[11]]
    for slot in torpedoes:
        out += slot
    return np.array(out, dtype=np.float32)


__all__ = ["HEADER", "OWN", "STAR", "ENEMY", "TORPEDO", "learning_layout", "learning_length",
           "torpedo_slots", "slots_in_flight", "learning_scales", "learning_vector",
           "write_learning", "write_all_learning"]
