"""A match between two bots: fault-isolated seats, optional replay, a deterministic result.

    result = play_match("chaser", "sniper", seed=7, rounds=5)
    result["winner"], result["score"]

The result is plain data (JSON-ready) holding no wall-clock figure, so the same seed and
bots give byte-identical JSON. A bot whose faults reach ``max_faults`` forfeits: the match
stops and the other bot wins.
"""
import time

import numpy as np

from . import core
from .game import Game
from .rules import Rules
from .seats import FAULT_KINDS, open_seat

DEFAULT_BUDGET = 0.05  # seconds per action
DEFAULT_MAX_FAULTS = 25


def bot_seed(seed, seat):
    """The seed a seat's bot gets: derived from the match seed, different per seat."""
    return int(np.random.SeedSequence([int(seed), 7919, seat]).generate_state(1)[0])


class FaultLog:
    """Counts of each kind of fault of one seat, and the first few messages."""

    def __init__(self):
        self.counts = {kind: 0 for kind in FAULT_KINDS}
        self.examples = []

    def add(self, frame, kind, message):
        self.counts[kind] += 1
        if len(self.examples) < 5:
            self.examples.append({"frame": int(frame), "kind": kind, "message": message})

    @property
    def total(self):
        return sum(self.counts.values())

    def to_dict(self):
        return {"total": self.total, **self.counts, "examples": self.examples}


def play_match(p1, p2, seed=0, rounds=5, rules=None, budget=DEFAULT_BUDGET,
               max_faults=DEFAULT_MAX_FAULTS, isolation="auto", record=False, on_frame=None):
    """Play one match; return the result dict (and the replay dict if ``record``).

    ``p1`` and ``p2`` are bot specifications (see ``spacewar.bots``). ``on_frame(game)`` is
    called after every frame (for progress or drawing).
    """
    rules = Rules() if rules is None else rules
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed must be an int >= 0, got {seed!r}")
    if budget <= 0:
        raise ValueError(f"budget must be > 0 seconds, got {budget!r}")
    if isinstance(max_faults, bool) or not isinstance(max_faults, int) or max_faults < 1:
        raise ValueError(f"max_faults must be an int >= 1, got {max_faults!r}")
    game = Game(rules, seeds=[seed], rounds=rounds)
    seats = []
    try:
        for s, spec in enumerate((p1, p2)):
            seats.append(open_seat(spec, bot_seed(seed, s), budget, isolation))
        faults = [FaultLog(), FaultLog()]
        actions = np.full((1, 2), core.NOOP, dtype=np.int64)
        history = bytearray() if record else None
        forfeit = None
        start = time.perf_counter()
        while not game.over[0]:
            frame = int(game.mi[0, core.FRAME])
            for s, seat in enumerate(seats):
                code, fault = seat.act(game.observe(0, s))
                actions[0, s] = code
                if fault is not None:
                    faults[s].add(frame, *fault)
            for s in range(2):
                if faults[s].total >= max_faults and forfeit is None:
                    forfeit = s
            if forfeit is not None:
                break
            game.step(actions)
            if record:
                history += bytes((int(actions[0, 0]), int(actions[0, 1])))
            if on_frame is not None:
                on_frame(game)
        wall = time.perf_counter() - start
    finally:
        for seat in seats:
            seat.close()
    result = _result(game, (p1, p2), seed, rounds, rules, faults, forfeit)
    result_timing = {"wall_seconds": wall, "frames_per_second": result["steps"] / max(wall, 1e-9)}
    if record:
        from .replay import make_replay

        return result, make_replay(result, bytes(history), game.state_hash(0)), result_timing
    return result, None, result_timing


def _result(game, bots, seed, rounds, rules, faults, forfeit):
    score = [int(x) for x in game.scores[0]]
    if forfeit is not None:
        winner = 1 - forfeit
    elif game.errored(0):
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
        "rounds": game.rounds_played(0),
        "steps": int(game.frame[0]),
        "forfeit": None if forfeit is None else bots[forfeit],
        "error": game.errored(0),
        "faults": [faults[0].to_dict(), faults[1].to_dict()],
        "seed": int(seed),
        "rounds_asked": int(rounds),
        "rules": rules.to_dict(),
    }
