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

from numba import prange

from engine import space
from engine.state import Model, State, Workspace

from . import compiled_bots, core
from .protocol import raw_layout
from .rules import Rules, count_at_least

jit = core.jit

#: matches are handed to the threads in this many chunks at most (one scratch space each)
CHUNKS = 256

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


_EPISODE_MIX = np.uint64(0xD1B54A32D192ED03)
_MATCH_MIX = np.uint64(0x9E3779B97F4A7C15)


@jit()
def episode_stream(base, m, episode):
    """The random-stream state of match ``m``'s episode ``episode`` under a base seed state:
    a function of the three alone, so a run is the same whatever the batch size or thread
    count (splitmix64's finaliser over the mixed words; Steele, Lea & Flood 2014)."""
    z = base ^ (np.uint64(m) * _MATCH_MIX) ^ (np.uint64(episode) * _EPISODE_MIX)
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


#: autoreset modes (Gymnasium 1.x's ``AutoresetMode``): when a match whose episode ended is
#: restarted. NEXT_STEP: at the next call, which returns its first observation with reward 0;
#: SAME_STEP: at once, the ended episode's last observation kept in ``final_observations``;
#: DISABLED: only when the caller asks (``LearningBatch.reset(mask)``).
NEXT_STEP, SAME_STEP, DISABLED = 0, 1, 2
AUTORESET_MODES = {"next_step": NEXT_STEP, "same_step": SAME_STEP, "disabled": DISABLED}

#: a seat whose actions the caller gives (not one of ``compiled_bots.KINDS``)
EXTERNAL = -1

_BOT_MIX = np.uint64(0x2545F4914F6CDD1D)


@jit(parallel=True)
def step_learning(actions, pos, vel, mass, charge, radius, active, test, pinned, n, box, kinds,
                  params, param_offsets, indices, index_offsets, accumulators, potentials,
                  ship_gauges, ship_counters,
                  torp_life, match_state, rng, rules, drifts, kicks, scales, base,
                  episodes, frame_cap, mode, play, pending, observations, final_observations,
                  rewards, terminated, truncated, seats, memory, bot_rng):
    """One call for every match, matches spread over the threads in chunks.

    A match whose episode ended (``pending[m]``) is restarted, under NEXT_STEP or DISABLED,
    instead of playing: episode ``episodes[m] + 1`` with the stream
    ``episode_stream(base, m, episode)``, reward 0, its first observation written. Under
    DISABLED the caller sets ``pending`` only for the matches it resets (and ``play`` False
    restarts those without stepping the others). Otherwise a match plays a frame: a seat
    with ``seats[s] >= 0`` is that compiled bot (``compiled_bots.decide``, its action
    written into ``actions[m, s]``), the other takes ``actions[m, s]``. ``rewards[m, s]`` is
    +1 when the frame scored a round for seat s and not for the enemy, -1 the other way, else
    0; ``terminated[m]`` at the match's end, ``truncated[m]`` at ``frame_cap`` frames (0:
    none). Under SAME_STEP an ended match writes its last observation into
    ``final_observations[m]`` and restarts at once. Every match's seats that the caller
    plays are then written into ``observations`` (M, 2, D) float32 (a compiled bot's row is
    not). Nothing is allocated per match."""
    state = State(pos, vel, mass, charge, radius, active, test, pinned, n, box)
    model = Model(kinds, params, param_offsets, indices, index_offsets, accumulators,
                  potentials)
    work = Workspace(np.empty(0), np.empty(0, dtype=np.int64), False)
    matches = pos.shape[0]
    chunks = min(matches, CHUNKS)
    for c in prange(chunks):
        scratch = core.new_scratch(pos)
        bot_scratch = compiled_bots.new_scratch(rules)
        _step_chunk(c * matches // chunks, (c + 1) * matches // chunks, actions, state, model,
                    work, ship_gauges, ship_counters, torp_life, match_state, rng, rules, drifts,
                    kicks, scales, base, episodes, frame_cap, mode, play, pending,
                    observations, final_observations, rewards, terminated, truncated, seats,
                    memory, bot_rng, scratch, bot_scratch)


@jit(_nrt=False)
def _step_chunk(first, last, actions, state, model, work, ship_gauges, ship_counters, torp_life,
                match_state, rng, rules, drifts, kicks, scales, base, episodes, frame_cap,
                mode, play, pending, observations, final_observations, rewards, terminated,
                truncated, seats, memory, bot_rng, scratch, bot_scratch):
    """Matches ``first`` to ``last - 1`` of ``step_learning``, in one thread's scratch: the
    frame is inlined here, outside the parallel loop, whose compilation grows with its body."""
    for m in range(first, last):
        if pending[m]:
            _restart(m, state, ship_gauges, ship_counters, torp_life, match_state, rng,
                     rules, base, episodes, seats, memory, bot_rng)
            pending[m] = False
            rewards[m, 0] = 0.0
            rewards[m, 1] = 0.0
            terminated[m] = False
            truncated[m] = False
        elif play:
            _play_frame(m, actions, state, model, work, ship_gauges, ship_counters,
                        torp_life, match_state, rng, rules, drifts, kicks, scratch,
                        frame_cap, seats, memory, bot_rng, bot_scratch, rewards, terminated,
                        truncated)
            if terminated[m] or truncated[m]:
                if mode == SAME_STEP:
                    _observe(m, state, ship_gauges, ship_counters, torp_life, match_state,
                             rules, scales, final_observations, seats)
                    _restart(m, state, ship_gauges, ship_counters, torp_life, match_state,
                             rng, rules, base, episodes, seats, memory, bot_rng)
                elif mode == NEXT_STEP:
                    pending[m] = True
        _observe(m, state, ship_gauges, ship_counters, torp_life, match_state, rules,
                 scales, observations, seats)


@jit(inline="always")
def _observe(m, state, ship_gauges, ship_counters, torp_life, match_state, rules, scales, out,
             seats):
    """Match m's observations of the seats the caller plays (a compiled bot reads the state
    itself: its seat's row is left as it was)."""
    for seat in range(2):
        if seats[seat] >= 0:
            continue
        write_learning(m, seat, state.pos, state.vel, state.charge, state.active, ship_gauges,
                       ship_counters, torp_life, match_state, rules, scales, out[m, seat])


@jit(inline="always")
def _restart(m, state, ship_gauges, ship_counters, torp_life, match_state, rng, rules, base,
             episodes, seats, memory, bot_rng):
    """Match m's next episode: its own stream, fresh compiled bots."""
    episodes[m] += 1
    rng[m] = episode_stream(base, m, episodes[m])
    core.reset_match(m, state.pos, state.vel, state.mass, state.charge, state.active,
                     ship_gauges, ship_counters, torp_life, match_state, rules)
    for s in range(2):
        if seats[s] >= 0:
            compiled_bots.reset_memory(m, s, memory)
            bot_rng[m, s] = episode_stream(base ^ _BOT_MIX, m, 2 * episodes[m] + s)


@jit(inline="always")
def _play_frame(m, actions, state, model, work, ship_gauges, ship_counters, torp_life,
                match_state, rng, rules, drifts, kicks, scratch, frame_cap, seats,
                memory, bot_rng, bot_scratch, rewards, terminated, truncated):
    """One frame of match m and its rewards and ends (see ``step_learning``)."""
    for s in range(2):
        if seats[s] >= 0:
            actions[m, s] = compiled_bots.decide_with(
                seats[s], m, s, state.pos, state.vel, state.charge, state.active, ship_gauges,
                ship_counters, torp_life, match_state, rules, memory, bot_rng, bot_scratch)
    s0 = match_state[m, core.SCORE0]
    s1 = match_state[m, core.SCORE1]
    core.step_match(m, actions, state, model, work, ship_gauges, ship_counters, torp_life,
                    match_state, rng, rules, drifts, kicks, scratch)
    d0 = match_state[m, core.SCORE0] - s0
    d1 = match_state[m, core.SCORE1] - s1
    r = 0.0
    if d0 > 0 and d1 == 0:
        r = 1.0
    elif d1 > 0 and d0 == 0:
        r = -1.0
    rewards[m, 0] = r
    rewards[m, 1] = -r
    terminated[m] = match_state[m, core.OVER] == 1
    truncated[m] = (not terminated[m]) and frame_cap > 0 and match_state[m, core.FRAME] >= frame_cap


class LearningBatch:
    """M matches stepped for learning code: (M, 2) actions in; (M, 2, D) float32 observations,
    (M, 2) rewards and (M,) terminated and truncated flags out, from one compiled call.

    Match m's episode e plays the stream ``episode_stream(seed state, m, e)``, so a run is
    reproducible whatever the batch size or thread count. ``frame_cap`` truncates an episode
    after that many frames (0: only the match's end ends it). ``autoreset``: ``"next_step"``
    (Gymnasium's default), ``"same_step"`` (``final_observations`` and ``ended`` tell the
    matches that ended) or ``"disabled"`` (``reset(mask)``). ``opponents``: per seat, None
    for actions given to ``step``, or the name of a compiled bot (``compiled_bots.KINDS``)
    that decides inside the compiled call; a compiled seat's rows of ``observations`` are
    not written (they stay zeros)."""

    def __init__(self, matches, rules=None, seed=0, rounds=3, frame_cap=0,
                 autoreset="next_step", opponents=(None, None)):
        from .game import Game, seed_state

        count_at_least("frame_cap", frame_cap, 0)
        if autoreset not in AUTORESET_MODES:
            raise ValueError(f"autoreset must be one of {', '.join(AUTORESET_MODES)}, "
                             f"got {autoreset!r}")
        self.seats = seat_kinds(opponents)
        self.game = Game(rules, seeds=[0] * int(matches), rounds=rounds)  # streams set per episode
        self.rules = self.game.rules
        self.frame_cap = int(frame_cap)
        self.mode = AUTORESET_MODES[autoreset]
        self.base = seed_state(seed)
        m = self.game.n_matches
        self.episodes = np.full(m, -1, dtype=np.int64)
        self.pending = np.ones(m, dtype=np.bool_)  # the first call starts every match
        self.scales = learning_scales(self.rules, rounds)
        shape = (m, 2, learning_length(self.rules))
        self.observations = np.zeros(shape, dtype=np.float32)
        self.final_observations = np.zeros(shape if self.mode == SAME_STEP else (0, 2, 0),
                                           dtype=np.float32)
        self.rewards = np.zeros((m, 2), dtype=np.float32)
        self.terminated = np.zeros(m, dtype=np.bool_)
        self.truncated = np.zeros(m, dtype=np.bool_)
        self.memory = compiled_bots.new_memory(m)
        self.bot_rng = np.zeros((m, 2), dtype=np.uint64)
        self._codes = np.full((m, 2), core.NOOP, dtype=np.int64)
        self._awaiting = np.zeros(m, dtype=np.bool_)  # ended, autoreset disabled, not yet reset

    @property
    def ended(self):
        """The matches whose episode ended at the last call (terminated or truncated)."""
        return self.terminated | self.truncated

    def step(self, actions=None):
        """One frame of every match (a restart for those whose episode ended at the last call,
        under next-step autoreset). ``actions`` (M, 2) codes: the compiled seats' entries are
        ignored, and may be left out (None) when both seats are compiled bots."""
        if self._awaiting.any():
            ended = np.flatnonzero(self._awaiting)
            raise RuntimeError(f"matches {ended[:10].tolist()} ended (autoreset disabled): reset "
                               f"them with reset(mask) before stepping")
        if actions is not None:
            self._codes[:] = self.game._encode(actions)
        elif (self.seats < 0).any():
            raise ValueError("actions are needed for the seats without a compiled bot")
        out = self._call(True)
        if self.mode == DISABLED:
            self._awaiting |= self.ended
        return out

    def reset(self, mask=None):
        """Restart the matches of ``mask`` ((M,) bool; all if None) without stepping the
        others; returns the observations."""
        if mask is None:
            mask = np.ones_like(self.pending)
        else:
            mask = np.asarray(mask)
            if mask.shape != self.pending.shape or mask.dtype != np.bool_:
                raise ValueError(f"mask must be a bool array of shape {self.pending.shape}, got "
                                 f"{mask.dtype} {mask.shape}")
            if not mask.any():
                raise ValueError("mask must select at least one match to reset, got none")
        later = self.pending & ~mask  # ended, outside the mask: restarted by the next step
        self.pending[:] = mask
        self._awaiting &= ~mask
        self._call(False)
        self.pending |= later
        return self.observations

    def _call(self, play):
        game = self.game
        game._sync_with_batch()
        step_learning(self._codes, *game._frame_arguments, self.scales, self.base, self.episodes,
                      self.frame_cap, self.mode, play, self.pending, self.observations,
                      self.final_observations, self.rewards, self.terminated, self.truncated,
                      self.seats, self.memory, self.bot_rng)
        return self.observations, self.rewards, self.terminated, self.truncated

    @property
    def actions(self):
        """The (M, 2) action codes of the last frame played, the compiled bots' included (a
        match restarted by the last call keeps its previous frame's)."""
        return self._codes


@jit(parallel=True)
def copy_rows(source, out):
    """``out[:] = source`` for (K, D) float32 rows, the rows spread over the threads (the
    vector env's fresh observations each step: a copy of megabytes that one thread would
    take a quarter of the step on)."""
    for k in prange(source.shape[0]):
        for j in range(source.shape[1]):
            out[k, j] = source[k, j]


def seat_kinds(opponents):
    """(2,) int64: each seat's compiled bot kind, ``EXTERNAL`` for None."""
    if not isinstance(opponents, (tuple, list)) or len(opponents) != 2:
        raise ValueError(f"opponents must be a pair (one per seat), got {opponents!r}")
    kinds = []
    for name in opponents:
        if name is None:
            kinds.append(EXTERNAL)
        elif name in compiled_bots.KINDS:
            kinds.append(compiled_bots.KINDS[name])
        else:
            raise ValueError(f"opponent must be None or one of "
                             f"{', '.join(sorted(compiled_bots.KINDS))}, got {name!r}")
    return np.array(kinds, dtype=np.int64)


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


__all__ = ["learning_layout", "learning_length", "torpedo_slots", "slots_in_flight", "learning_scales", "learning_vector",
           "write_learning", "write_all_learning", "episode_stream", "step_learning",
           "LearningBatch", "seat_kinds", "copy_rows", "AUTORESET_MODES", "NEXT_STEP", "SAME_STEP", "DISABLED",
           "EXTERNAL"]
