"""A match between two bots: fault-isolated seats, optional replay, a deterministic result.

    from spacewar import play_match          # or spacewar.arena.match.play_match
    result, replay, timing = play_match("chaser", "sniper", seed=7, rounds=5)
    result["winner"], result["score"]

The result is plain data (JSON-ready) holding no wall-clock figure, so the same seed and
bots give byte-identical JSON. A bot whose faults reach ``max_faults`` forfeits, and so does
one that cannot start, dies, breaks the wire protocol or hangs: the match stops and the other
bot wins. ``result["faults"]`` counts each kind of fault per seat with the first messages,
``result["forfeits"]`` says which seats forfeited, ``result["output"]`` holds the first
bytes each isolated bot wrote to its stdout and stderr (never this process's stdout).
"""
import math
import time

import numpy as np

from spacewar.game import core
from spacewar.game.game import Game
from spacewar.protocol import raw_length
from spacewar.rules import Rules, count_at_least
from spacewar.game.referee import Referee
from spacewar.sandbox.limits import Limits
from spacewar.arena.seats import bot_name, open_seat

DEFAULT_BUDGET = 0.05  # seconds per action
DEFAULT_MAX_FAULTS = 25


def bot_seed(seed, seat):
    """The seed a seat's bot gets: derived from the match seed, different per seat."""
    return int(np.random.SeedSequence([int(seed), 7919, seat]).generate_state(1)[0])


def play_match(p1, p2, seed=0, rounds=5, rules=None, budget=DEFAULT_BUDGET,
               max_faults=DEFAULT_MAX_FAULTS, isolation="auto", record=False, on_frame=None,
               limits=None, act_seconds=False):
    """Play one match; return ``(result, replay, timing)``.

    ``p1`` and ``p2`` (seats 0 and 1) are each a bot specification (a built-in name,
    ``package.module:Class``, ``path/to/file.py:Class`` or a policy ``.npz``: see
    ``spacewar.bots``) or a bot object (an instance of any class with ``act(self, obs) ->
    Action``, or a batch bot with ``act_batch``). Built-in bots and bot objects play in this
    process (an object is the caller's own code), every other bot in its own confined
    process (``spacewar.sandbox.process``). A class instead of an instance is refused (TypeError).

    ``seed`` (int >= 0) fixes the match: the same seed and bots give a byte-identical result.
    ``rounds``: rounds to play (ties add up to ``rules.max_extra_rounds``). ``rules``: a
    ``spacewar.Rules`` (default the 1962 game). ``limits`` (a ``spacewar.sandbox.limits.Limits``) sets
    every budget; ``budget`` alone sets the per-action one (seconds). A bot that cannot start,
    dies, breaks the protocol, hangs or reaches ``max_faults`` faults forfeits; the other bot
    wins (if both forfeit, nobody does). ``isolation``: ``"auto"``, ``"process"`` (built-in
    bots confined too) or ``"inline"``. ``on_frame(game)`` is called after every frame.

    Returns:

    - ``result``: plain data, JSON-ready, holding no wall-clock figure: ``bots`` (names),
      ``winner`` (a name or None), ``winner_seat`` (0, 1 or None), ``score`` [seat 0, seat 1],
      ``rounds`` (played), ``steps`` (frames), ``forfeit``, ``forfeits``, ``error``,
      ``faults`` (per seat), ``seed``, ``rounds_asked``, ``rules`` (a dict), ``output``;
    - ``replay``: the replay dict (``spacewar.replay``) when ``record`` is true, else None;
    - ``timing``: wall-clock figures, kept out of the result so that results are
      byte-identical: ``wall_seconds``, ``frames_per_second`` (both from the first seat's
      opening to the last seat's closing), ``startup_seconds`` (until both seats were ready:
      a confined bot's process started, confined, its module loaded), ``play_seconds`` and
      ``play_frames_per_second`` (from then on: the frames alone), ``act`` (per seat, a summary of
      the time of each action as charged against the budget: ``count``, ``mean``, ``p50``,
      ``p95``, ``p99``, ``max`` in seconds, see ``act_time_summary``) and, when
      ``act_seconds`` is true, ``act_seconds`` (per seat, a float64 array of every action's
      time, in the order asked).
    """
    for field, bot in (("p1", p1), ("p2", p2)):
        check_bot_argument(field, bot)
    rules = Rules() if rules is None else rules
    count_at_least("seed", seed, 0)
    limits = checked_limits(max_faults, budget, limits)
    game = Game(rules, seeds=[seed], rounds=rounds)
    cpu = cpu_seconds(rules, rounds, limits)
    seats = []
    referee = Referee(max_faults, record)
    outputs = [None, None]
    start = time.perf_counter()
    try:
        for s, spec in enumerate((p1, p2)):
            seats.append(open_seat(spec, bot_seed(seed, s), limits, rules, isolation, cpu,
                                   rounds=rounds))
        for s, seat in enumerate(seats):
            if hasattr(seat, "wait_ready") and seat.wait_ready() is not None:
                referee.could_not_start(s, seat.dead)
        ready = time.perf_counter()
        actions = np.full((1, 2), core.NOOP, dtype=np.int64)
        raws = np.empty((2, raw_length(rules)))  # every seat copies what it keeps
        for s in range(2):
            game.write_raw(0, s, raws[s])
        match_state = game.match_state[0]
        # codes from protocol.action_code, already checked; the frame, then what each seat
        # sees next, in one compiled call (spacewar.game.referee)
        while not match_state[core.OVER] and not referee.forfeited:
            if not referee.play_frame(game, seats, raws, actions):
                break
            if on_frame is not None:
                on_frame(game)
    finally:
        for s, seat in enumerate(seats):
            outputs[s] = seat.close()
    end = time.perf_counter()
    wall = end - start
    result = match_result(game, (bot_name(p1), bot_name(p2)), seed, rounds, rules,
                          referee.faults, referee.forfeits, outputs)
    playing = end - ready
    result_timing = {"wall_seconds": wall, "frames_per_second": result["steps"] / max(wall, 1e-9),
                     "startup_seconds": ready - start, "play_seconds": playing,
                     "play_frames_per_second": result["steps"] / max(playing, 1e-9)}
    times = [np.frombuffer(seat.act_seconds, dtype=np.float64).copy() for seat in seats]
    result_timing["act"] = [act_time_summary(t) for t in times]
    if act_seconds:
        result_timing["act_seconds"] = times
    if record:
        from spacewar.replay import make_replay

        replay = make_replay(result, bytes(referee.history), game.state_hash(0),
                             faults=bytes(referee.fault_codes), max_faults=max_faults)
        return result, replay, result_timing
    return result, None, result_timing


def check_bot_argument(field, bot):
    """A bot argument of ``play_match`` that can never play is a TypeError naming it."""
    if isinstance(bot, str):
        return
    if isinstance(bot, type):
        raise TypeError(f"{field} must be a bot specification or a bot object, got the class "
                        f"{bot.__qualname__}: pass an instance, {bot.__qualname__}()")
    if not callable(getattr(bot, "act", None)) and not callable(getattr(bot, "act_batch", None)):
        raise TypeError(f"{field} must be a bot specification (str) or an object with "
                        f"act(obs), got {type(bot).__name__} {bot!r:.80}")


def act_time_summary(seconds):
    """A summary of per-action times (seconds): ``count``, ``mean``, ``p50``, ``p95``,
    ``p99`` and ``max``, the percentiles by linear interpolation between the order statistics
    (numpy's default). Every figure is None when there is no time at all."""
    seconds = np.asarray(seconds, dtype=np.float64)
    if seconds.size == 0:
        return {"count": 0, "mean": None, "p50": None, "p95": None, "p99": None, "max": None}
    p50, p95, p99 = np.percentile(seconds, (50.0, 95.0, 99.0)).tolist()
    return {"count": int(seconds.size), "mean": float(seconds.mean()), "p50": p50, "p95": p95,
            "p99": p99, "max": float(seconds.max())}


def checked_limits(max_faults, budget, limits):
    """The ``Limits`` a match plays under (``budget`` alone when ``limits`` is None), after
    checking them and ``max_faults``."""
    if isinstance(max_faults, bool) or not isinstance(max_faults, int) or max_faults < 1:
        raise ValueError(f"max_faults must be an int >= 1, got {max_faults!r}")
    limits = Limits(budget=budget) if limits is None else limits
    if not isinstance(limits, Limits):
        raise TypeError(f"limits must be a spacewar.sandbox.limits.Limits, got {limits!r}")
    return limits


def cpu_seconds(rules, rounds, limits):
    """CPU seconds a bot's process may use: its start-up and every frame at full budget."""
    frames = (rounds + rules.max_extra_rounds) * (rules.max_round_frames + rules.post_round_delay)
    if limits.cpu_seconds is not None:
        return limits.cpu_seconds
    return int(math.ceil(limits.startup + limits.overage + frames * limits.budget)) + 5


def match_result(game, bots, seed, rounds, rules, faults, forfeits, outputs, m=0):
    """Match ``m``'s plain-data result (see the module's text)."""
    score = [int(x) for x in game.scores[m]]
    forfeit = forfeits.index(True) if forfeits.count(True) == 1 else None
    if any(forfeits):
        winner = None if forfeit is None else 1 - forfeit
    elif game.errored(m):
        winner = None
    elif score[0] != score[1]:
        winner = 0 if score[0] > score[1] else 1
    else:
        winner = None
    return {
        "bots": list(bots),
        "winner": None if winner is None else bots[winner],
        "winner_seat": winner,
        "score": score,
        "rounds": game.rounds_played(m),
        "steps": int(game.frame[m]),
        "forfeit": None if forfeit is None else bots[forfeit],
        "forfeits": [bool(f) for f in forfeits],
        "error": game.errored(m),
        "faults": [faults[0].to_dict(), faults[1].to_dict()],
        "seed": int(seed),
        "rounds_asked": int(rounds),
        "rules": rules.to_dict(),
        "output": [o or {"text": "", "bytes": 0, "truncated": False} for o in outputs],
    }
