"""Many matches in one game: a batch bot (``spacewar.bots.batch``) answers for all of its
matches in one call per frame.

    results = play_matches([(policy, "chaser", 1), ("chaser", policy, 1)], rounds=3)

Each match's result is what ``spacewar.arena.match.play_match`` gives for it alone, to the byte
(tested): the matches are the rows of one ``Game``, each with its own seed, so nothing of one
reaches another. A batch bot (an object with ``act_batch``, a policy file ``*.npz``, or a
bot from a file whose class defines ``act_batch``: ``spacewar.bots.declares_act_batch``) is
one instance for all of its matches; every other bot, a built-in one, gets its own instance
per match and seat, as in a match alone. A batch bot from a file is untrusted code: its one
instance runs in its own confined process (``spacewar.sandbox.process.BatchProcessSeat``), which gets
all its matches' observations in one message per frame and answers one code per match, with
every protection a bot's process has (deadlines, pauses between turns, limits; CPU time and
start-up as for one match, the CPU time times the number of matches). Its constructor gets a
seed derived from all its matches' seeds and seats. Other bots from files are not played
here: they run in their own confined process, one match at a time (``play_match``).

A bot with both ``act`` and ``act_batch`` plays ``act_batch`` here and ``act`` alone: the
results are the same when the two agree.

Faults are those of a match alone, counted per match and seat. A batch bot's call is timed
as a whole and each live match charged its share against that match's budget; when it
raises or answers anything but one valid code per row, each of its live matches records the
fault and plays a no-op. A confined batch bot that dies, hangs past its allowance (all its
live matches' allowances together) or breaks the wire protocol forfeits all of its live
matches, each recording why; its output is in each of its matches' results. A match whose
seat forfeits stops where it is (as a match alone stops), while the others play on.
"""
import array
import time

import numpy as np

from spacewar.game import core
from spacewar.bots.batch import ask_batch, is_batch_bot
from spacewar.bots import declares_act_batch, is_builtin, is_policy_file
from spacewar.game.game import Game
from spacewar.game.features import learning_length
from spacewar.arena.match import (DEFAULT_BUDGET, DEFAULT_MAX_FAULTS, cpu_seconds, match_result,
                    act_time_summary, bot_seed, checked_limits)
from spacewar.protocol import raw_length
from spacewar.rules import Rules, count_at_least
from spacewar.faults import KIND_BY_STATUS
from spacewar.game.referee import Referee
from spacewar.sandbox.process import BatchProcessSeat
from spacewar.sandbox.limits import TimeBank
from spacewar.arena.seats import bot_name, open_seat
from spacewar.wire import INVALID, MAX_ROWS, OK, exception_text


def is_batch_spec(spec, batch_files=None):
    """Whether ``spec`` plays as one batch bot in ``play_matches``: a batch bot object, a
    policy file, or a bot from a file whose class defines ``act_batch`` (in
    ``batch_files`` when that is given, a set of specifications already looked at)."""
    if not isinstance(spec, str):
        return is_batch_bot(spec)
    if is_policy_file(spec):
        return True
    if batch_files is not None:
        return spec in batch_files
    return declares_act_batch(spec)


def can_play_together(spec, batch_files=None):
    """Whether ``play_matches`` takes ``spec``: a batch bot, a policy file or a built-in bot."""
    return is_batch_spec(spec, batch_files) or (isinstance(spec, str) and is_builtin(spec))


def batch_seed(rows, matches):
    """The seed a batch bot from a file is made with: one for all of its ``rows`` ((match,
    seat) pairs) of ``matches``, derived from their seeds and seats."""
    entropy = [7919] + [int(x) for m, s in rows for x in (matches[m][2], s)]
    return int(np.random.SeedSequence(entropy).generate_state(1)[0])


class _BatchSide:
    """One batch bot and the (match, seat) rows it plays, in match order. A policy file is
    ``spacewar.policy.PolicyBatch``: each row played as ``PolicyBot`` plays that match. A
    batch bot from a file is a ``BatchProcessSeat`` (``self.seat``; ``self.bot`` None)."""

    def __init__(self, spec, rows, rules, seat_options=None):
        self.spec = spec
        self.rows = rows  # list of (m, seat)
        self.index = (np.array([m for m, _ in rows]), np.array([s for _, s in rows]))
        self.dead = None
        self.bot = spec
        self.seat = None
        # each row's charged share of every call (``spacewar.sandbox.process``' ``act_seconds``)
        self.act_seconds = [array.array("d") for _ in rows]
        if seat_options is not None:  # untrusted: its own process
            self.bot = None
            self.seat = BatchProcessSeat(spec, rules=rules, rows=len(rows), **seat_options)
            self.dead = self.seat.dead
            return
        try:
            if isinstance(spec, str):
                from spacewar.bots.policy import PolicyBatch

                self.bot = PolicyBatch(spec, rules, [s for _, s in rows])
            reset = getattr(self.bot, "reset", None)
            if callable(reset):
                reset()
        except BaseException as exc:  # a bad file, or the caller's reset: a fault, not a crash
            self.dead = ("startup", exception_text(exc))

    def wait_ready(self):
        if self.seat is not None and self.dead is None:
            self.dead = self.seat.wait_ready()
        return self.dead

    def close(self):
        return None if self.seat is None else self.seat.close()


def play_matches(matches, rounds=5, rules=None, budget=DEFAULT_BUDGET,
                 max_faults=DEFAULT_MAX_FAULTS, limits=None, batch_files=None, record=False,
                 act_seconds=False):
    """Play ``matches`` (a list of ``(p1, p2, seed)``) together; return a list of
    ``(result, timing)``, one per match in order, ``result`` as ``play_match`` gives it.
    ``batch_files``: the bots from files to play as batch bots (default: those whose class
    defines ``act_batch``, ``spacewar.bots.declares_act_batch``).

    ``timing`` holds ``wall_seconds`` (the game's, shared equally), ``frames_per_second``,
    ``act`` (per seat, ``act_time_summary`` of the times charged to that match: a batch
    bot's share of each call) and, with ``act_seconds``, every one of those times per seat.
    With ``record`` each entry is ``(result, replay, timing)``, the replay each match's as
    ``play_match`` records it."""
    rules = Rules() if rules is None else rules
    matches = [tuple(x) for x in matches]
    if not matches:
        raise ValueError("matches must hold at least one (p1, p2, seed)")
    for match in matches:
        if len(match) != 3:
            raise ValueError(f"each match must be (p1, p2, seed), got {match!r:.200}")
    batch_files = _batch_files(matches, batch_files)
    for p1, p2, seed in matches:
        for spec in (p1, p2):
            if not can_play_together(spec, batch_files):
                raise ValueError(f"play_matches plays batch bots, policy files and built-in "
                                 f"bots; {bot_name(spec)!r} plays with play_match")
        count_at_least("seed", seed, 0)
    limits = checked_limits(max_faults, budget, limits)
    for spec in batch_files:
        rows = sum(x == spec for match in matches for x in match[:2] if isinstance(x, str))
        if rows > MAX_ROWS:
            raise ValueError(f"a batch bot from a file plays at most {MAX_ROWS} matches "
                             f"together; {spec!r} has {rows}")
    count = len(matches)
    game = Game(rules, seeds=[seed for _, _, seed in matches], rounds=rounds)
    referees = [Referee(max_faults, record) for _ in range(count)]
    banks = [[TimeBank(limits), TimeBank(limits)] for _ in range(count)]
    sides, seats = _open(matches, limits, rules, rounds, batch_files)
    try:
        wall = _play(game, sides, seats, referees, banks)
    finally:
        outputs = [[None, None] for _ in range(count)]
        for m, row in enumerate(seats):
            for s, seat in enumerate(row):
                if seat is not None:
                    outputs[m][s] = seat.close()
        for side in sides:
            output = side.close()
            for m, s in side.rows:
                outputs[m][s] = output
    out = []
    for m, (p1, p2, seed) in enumerate(matches):
        referee = referees[m]
        result = match_result(game, (bot_name(p1), bot_name(p2)), seed, rounds, rules,
                              referee.faults, referee.forfeits, outputs[m], m=m)
        times = _act_times(m, sides, seats)
        timing = {"wall_seconds": wall / count,
                  "frames_per_second": result["steps"] / max(wall / count, 1e-9),
                  "act": [act_time_summary(t) for t in times]}
        if act_seconds:
            timing["act_seconds"] = times
        if record:
            from spacewar.replay import make_replay

            replay = make_replay(result, bytes(referee.history), _final_hash(game, m, result),
                                 faults=bytes(referee.fault_codes), max_faults=max_faults)
            out.append((result, replay, timing))
        else:
            out.append((result, timing))
    return out


def _act_times(m, sides, seats):
    """Per seat of match ``m``, the float64 array of the times charged to it."""
    times = [None, None]
    for s, seat in enumerate(seats[m]):
        if seat is not None:
            times[s] = seat.act_seconds
    for side in sides:
        for k, (row_m, s) in enumerate(side.rows):
            if row_m == m:
                times[s] = side.act_seconds[k]
    return [np.frombuffer(t, dtype=np.float64).copy() for t in times]


def _final_hash(game, m, result):
    """Match ``m``'s final state hash as ``play_match`` (and a replay's check) sees it: a
    match that stopped on a forfeit was marked over here only to be stepped no more, while
    a match alone just stops, live (a forfeit happens only to a live match)."""
    if not any(result["forfeits"]):
        return game.state_hash(m)
    match_state = game.match_state
    match_state[m, core.OVER] = 0
    try:
        return game.state_hash(m)
    finally:
        match_state[m, core.OVER] = 1


def _play(game, sides, seats, referees, banks):
    """Play every match to its end or its forfeit, each judged by its referee
    (``spacewar.game.referee``: faults, forfeits, and what its replay needs); return the
    wall-clock seconds."""
    count = len(seats)
    for side in sides:
        if side.wait_ready() is not None:
            for m, s in side.rows:
                referees[m].could_not_start(s, side.dead)
    for m, row in enumerate(seats):
        for s, seat in enumerate(row):
            if seat is not None and seat.wait_ready() is not None:
                referees[m].could_not_start(s, seat.dead)
    match_state = game.match_state
    # a match whose seat forfeits stops where it is, as a match alone stops: over, so that
    # the game steps it no more and the loop below asks nothing of it
    for m, referee in enumerate(referees):
        if referee.forfeited:
            match_state[m, core.OVER] = 1
    actions = np.full((count, 2), core.NOOP, dtype=np.int64)
    raw = np.empty(raw_length(game.rules))
    learning = (np.zeros((count, 2, learning_length(game.rules)), dtype=np.float32)
                if sides else None)
    start = time.perf_counter()
    live = match_state[:, core.OVER] == 0
    call = 0
    while live.any():
        if learning is not None:
            game.learning_observations(learning)
        for side in sides:
            _ask_side(side, call, learning, live, match_state, actions, referees, banks)
        call += 1
        for m in np.flatnonzero(live):
            referee = referees[m]
            frame = int(match_state[m, core.FRAME])
            for s, seat in enumerate(seats[m]):
                if seat is None:
                    continue
                code, fault = seat.act(game.write_raw(int(m), s, raw))
                actions[m, s] = code
                referee.judge(s, frame, fault, seat.dead is not None)
            if referee.questions_done():
                match_state[m, core.OVER] = 1
            else:
                referee.played(actions[m, 0], actions[m, 1])
        game.step_codes(actions)  # codes from the checks above: valid
        live = match_state[:, core.OVER] == 0
    return time.perf_counter() - start


def _batch_files(matches, batch_files):
    """The set of bots from files that play as batch bots here."""
    specs = {spec for match in matches for spec in match[:2]
             if isinstance(spec, str) and not is_builtin(spec)}
    if batch_files is None:
        return {spec for spec in specs if declares_act_batch(spec)}
    return {spec for spec in specs if spec in set(batch_files)}


def _open(matches, limits, rules, rounds, batch_files):
    """The batch sides (one per distinct batch bot) and the per-match seats of the others."""
    sides = {}
    seats = [[None, None] for _ in matches]
    cpu = cpu_seconds(rules, rounds, limits)
    for m, (p1, p2, seed) in enumerate(matches):
        for s, spec in enumerate((p1, p2)):
            if is_batch_spec(spec, batch_files):
                key = spec if isinstance(spec, str) else id(spec)
                sides.setdefault(key, (spec, []))[1].append((m, s))
            else:
                seats[m][s] = open_seat(spec, bot_seed(seed, s), limits, rules, "auto", cpu,
                                        rounds=rounds)
    out = []
    for spec, rows in sides.values():
        options = None
        if isinstance(spec, str) and spec in batch_files:
            options = {"seed": batch_seed(rows, matches), "limits": limits, "rounds": rounds,
                       "cpu_seconds": cpu * len(rows)}
        out.append(_BatchSide(spec, rows, rules, options))
    return out, seats


def _ask_side(side, call, learning, live, match_state, actions, referees, banks):
    """The batch bot's codes for all its rows (a no-op and a fault on each live row when its
    answer is not usable), judged in the order of a match alone (``InlineSeat.act``): no
    answer at all (raised, out of memory) costs no time; a late answer is a timeout, whatever
    it holds; an answer in time that is not K valid codes is invalid. A confined batch bot
    is given the allowances of all its live rows together; when it can play no more, its live
    rows forfeit."""
    ms, ss = side.index
    alive = live[ms]
    if side.dead is not None or not alive.any():
        return  # nothing of it to play: not asked (its finished rows' actions are ignored)
    alive_rows = [side.rows[k] for k in np.flatnonzero(alive)]
    if side.seat is None:
        start = time.perf_counter()
        status, codes, text = ask_batch(side.bot, learning[ms, ss])
        seconds, fault = time.perf_counter() - start, None
    else:
        budget = sum(banks[m][s].budget for m, s in alive_rows)
        allowance = len(alive_rows) * max(banks[m][s].allowance() for m, s in alive_rows)
        status, codes, text, seconds, fault = side.seat.act_batch(call, learning[ms, ss],
                                                                  budget, allowance)
        side.dead = side.seat.dead
    share = None if seconds is None else seconds / len(alive_rows)
    for k, (m, s) in enumerate(side.rows):
        if not alive[k]:
            continue
        frame = int(match_state[m, core.FRAME])
        actions[m, s] = core.NOOP
        if share is not None:
            side.act_seconds[k].append(share)
        if fault is not None:  # its process gave no answer
            referees[m].judge(s, frame, fault, side.dead is not None)
            if side.dead is None and share is not None:
                banks[m][s].left = 0.0  # silent for the whole allowance: every bank is spent
        elif side.seat is None and status in KIND_BY_STATUS and status != INVALID:
            # no answer at all from code in this process; a confined bot's status is its own word
            referees[m].judge(s, frame, (KIND_BY_STATUS[status], text))
        elif not banks[m][s].charge(share):
            referees[m].judge(s, frame, ("timeout", banks[m][s].late(share)))
        elif status != OK:
            referees[m].judge(s, frame, (KIND_BY_STATUS[status], text))
        else:
            actions[m, s] = codes[k]


__all__ = ["play_matches", "is_batch_spec", "can_play_together", "batch_seed"]
