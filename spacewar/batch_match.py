"""Many matches in one game: a batch bot (``spacewar.batch_bots``) answers for all of its
matches in one call per frame.

    results = play_matches([(policy, "chaser", 1), ("chaser", policy, 1)], rounds=3)

Each match's result is what ``spacewar.match.play_match`` gives for it alone, to the byte
(tested): the matches are the rows of one ``Game``, each with its own seed, so nothing of one
reaches another. A batch bot (an object with ``act_batch``, or a policy file ``*.npz``) is
one instance for all of its matches; every other bot, a built-in one, gets its own instance
per match and seat, as in a match alone. Bots from files are not played here: they run in
their own confined process, one match at a time (``play_match``).

A bot with both ``act`` and ``act_batch`` plays ``act_batch`` here and ``act`` alone: the
results are the same when the two agree.

Faults are those of a match alone, counted per match and seat. A batch bot's call is timed
as a whole and each live match charged its share against that match's budget; when it
raises or answers anything but one valid code per row, each of its live matches records the
fault and plays a no-op. A match whose seat forfeits stops where it is (as a match alone
stops), while the others play on.
"""
import time

import numpy as np

from . import core
from .batch_bots import ask_batch, is_batch_bot
from .bots import is_builtin, is_policy_file
from .game import Game
from .learning import learning_length
from .match import (DEFAULT_BUDGET, DEFAULT_MAX_FAULTS, FaultLog, _cpu_seconds, _result,
                    bot_seed, checked_limits)
from .protocol import raw_length
from .rules import Rules, count_at_least
from .seats import _KIND_BY_STATUS, _Bank, bot_name, open_seat
from .wire import INVALID, OK, exception_text


def is_batch_spec(spec):
    """Whether ``spec`` plays as one batch bot in ``play_matches``."""
    return is_policy_file(spec) or (not isinstance(spec, str) and is_batch_bot(spec))


def can_play_together(spec):
    """Whether ``play_matches`` takes ``spec``: a batch bot, a policy file or a built-in bot."""
    return is_batch_spec(spec) or (isinstance(spec, str) and is_builtin(spec))


class _BatchSide:
    """One batch bot and the (match, seat) rows it plays, in match order. A policy file is
    ``spacewar.policy.PolicyBatch``: each row played as ``PolicyBot`` plays that match."""

    def __init__(self, spec, rows, rules):
        self.spec = spec
        self.rows = rows  # list of (m, seat)
        self.index = (np.array([m for m, _ in rows]), np.array([s for _, s in rows]))
        self.dead = None
        self.bot = spec
        try:
            if isinstance(spec, str):
                from .policy import PolicyBatch

                self.bot = PolicyBatch(spec, rules, [s for _, s in rows])
            reset = getattr(self.bot, "reset", None)
            if callable(reset):
                reset()
        except BaseException as exc:  # a bad file, or the caller's reset: a fault, not a crash
            self.dead = ("startup", exception_text(exc))


def play_matches(matches, rounds=5, rules=None, budget=DEFAULT_BUDGET,
                 max_faults=DEFAULT_MAX_FAULTS, limits=None):
    """Play ``matches`` (a list of ``(p1, p2, seed)``) together; return a list of
    ``(result, timing)``, one per match in order, ``result`` as ``play_match`` gives it."""
    rules = Rules() if rules is None else rules
    matches = [tuple(x) for x in matches]
    if not matches:
        raise ValueError("matches must hold at least one (p1, p2, seed)")
    for match in matches:
        if len(match) != 3:
            raise ValueError(f"each match must be (p1, p2, seed), got {match!r:.200}")
    for p1, p2, seed in matches:
        for spec in (p1, p2):
            if not can_play_together(spec):
                raise ValueError(f"play_matches plays batch bots, policy files and built-in "
                                 f"bots; {bot_name(spec)!r} plays with play_match")
        count_at_least("seed", seed, 0)
    limits = checked_limits(max_faults, budget, limits)
    count = len(matches)
    game = Game(rules, seeds=[seed for _, _, seed in matches], rounds=rounds)
    faults = [[FaultLog(), FaultLog()] for _ in range(count)]
    forfeits = np.zeros((count, 2), dtype=bool)
    banks = [[_Bank(limits), _Bank(limits)] for _ in range(count)]
    sides, seats = _open(matches, limits, rules, rounds)
    for side in sides:
        if side.dead is not None:
            for m, s in side.rows:
                faults[m][s].add(0, *side.dead)
                forfeits[m, s] = True
    for m, row in enumerate(seats):
        for s, seat in enumerate(row):
            if seat is not None and seat.wait_ready() is not None:
                faults[m][s].add(0, *seat.dead)
                forfeits[m, s] = True
    match_state = game.match_state
    # a match whose seat forfeits stops where it is, as a match alone stops: over, so that
    # the game steps it no more and the loop below asks nothing of it
    match_state[forfeits.any(axis=1), core.OVER] = 1
    actions = np.full((count, 2), core.NOOP, dtype=np.int64)
    raw = np.empty(raw_length(rules))
    learning = np.zeros((count, 2, learning_length(rules)), dtype=np.float32) if sides else None
    start = time.perf_counter()
    live = match_state[:, core.OVER] == 0
    while live.any():
        if learning is not None:
            game.learning_observations(learning)
        for side in sides:
            _ask_side(side, learning, live, match_state, actions, faults, banks)
        for m in np.flatnonzero(live):
            for s, seat in enumerate(seats[m]):
                if seat is None:
                    continue
                code, fault = seat.act(game._write_raw(int(m), s, raw))
                actions[m, s] = code
                if fault is not None:
                    faults[m][s].add(int(match_state[m, core.FRAME]), *fault)
        for m in np.flatnonzero(live):
            for s in range(2):
                if faults[m][s].total >= max_faults:
                    forfeits[m, s] = True
            if forfeits[m].any():
                match_state[m, core.OVER] = 1
        game._step_codes(actions)  # codes from the checks above: valid
        live = match_state[:, core.OVER] == 0
    wall = time.perf_counter() - start
    outputs = [[None, None] for _ in range(count)]
    for m, row in enumerate(seats):
        for s, seat in enumerate(row):
            if seat is not None:
                outputs[m][s] = seat.close()
    out = []
    for m, (p1, p2, seed) in enumerate(matches):
        result = _result(game, (bot_name(p1), bot_name(p2)), seed, rounds, rules, faults[m],
                         forfeits[m].tolist(), outputs[m], m=m)
        out.append((result, {"wall_seconds": wall / count,
                             "frames_per_second": result["steps"] / max(wall / count, 1e-9)}))
    return out


def _open(matches, limits, rules, rounds):
    """The batch sides (one per distinct batch bot) and the per-match seats of the others."""
    sides = {}
    seats = [[None, None] for _ in matches]
    cpu = _cpu_seconds(rules, rounds, limits)
    for m, (p1, p2, seed) in enumerate(matches):
        for s, spec in enumerate((p1, p2)):
            if is_batch_spec(spec):
                key = spec if isinstance(spec, str) else id(spec)
                sides.setdefault(key, (spec, []))[1].append((m, s))
            else:
                seats[m][s] = open_seat(spec, bot_seed(seed, s), limits, rules, "auto", cpu,
                                        rounds=rounds)
    return [_BatchSide(spec, rows, rules) for spec, rows in sides.values()], seats


def _ask_side(side, learning, live, match_state, actions, faults, banks):
    """The batch bot's codes for all its rows (a no-op and a fault on each live row when its
    answer is not usable), judged in the order of a match alone (``InlineSeat.act``): no
    answer at all (raised, out of memory) costs no time; a late answer is a timeout, whatever
    it holds; an answer in time that is not K valid codes is invalid."""
    ms, ss = side.index
    alive = live[ms]
    if side.dead is not None or not alive.any():
        return  # nothing of it to play: not asked (its finished rows' actions are ignored)
    start = time.perf_counter()
    status, codes, text = ask_batch(side.bot, learning[ms, ss])
    share = (time.perf_counter() - start) / int(alive.sum())
    for k, (m, s) in enumerate(side.rows):
        if not alive[k]:
            continue
        frame = int(match_state[m, core.FRAME])
        actions[m, s] = core.NOOP
        if status in _KIND_BY_STATUS and status != INVALID:
            faults[m][s].add(frame, _KIND_BY_STATUS[status], text)
        elif not banks[m][s].charge(share):
            faults[m][s].add(frame, "timeout", banks[m][s].late(share))
        elif status != OK:
            faults[m][s].add(frame, _KIND_BY_STATUS[status], text)
        else:
            actions[m, s] = codes[k]


__all__ = ["play_matches", "is_batch_spec", "can_play_together"]
