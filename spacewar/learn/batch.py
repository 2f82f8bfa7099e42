"""Learning at the compiled game's speed: many matches stepped in one compiled call, each
seat given to an agent or to a compiled built-in bot (``LearningBatch``, ``step_learning``),
episodes restarted from their own random streams. The observations they write are
``spacewar.game.features``' (the learning observation: its layout and scales are documented
there); its names are public here too.
"""
import numpy as np

from numba import prange

from engine.state import Model, State, Workspace

from spacewar.game import compiled_bots
from spacewar.game import core
from spacewar.game.features import (learning_layout,  # noqa: F401 (public here too)
                       learning_length, learning_scales, learning_vector, slots_in_flight,
                       torpedo_slots, write_all_learning, write_learning)
from spacewar.rules import count_at_least

jit = core.jit

#: matches are handed to the threads in this many chunks at most (one scratch space each)
CHUNKS = 256

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
        from spacewar.game.game import Game, seed_state

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
            self._codes[:] = self.game.encode_actions(actions)
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
        game.sync_with_batch()
        step_learning(self._codes, *game.frame_arguments, self.scales, self.base, self.episodes,
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


__all__ = ["learning_layout", "learning_length", "torpedo_slots", "slots_in_flight", "learning_scales", "learning_vector",
           "write_learning", "write_all_learning", "episode_stream", "step_learning",
           "LearningBatch", "seat_kinds", "copy_rows", "AUTORESET_MODES", "NEXT_STEP", "SAME_STEP", "DISABLED",
           "EXTERNAL"]
