"""Batch bots written to attack the match from their confined process (tests/spacewar/
test_untrusted_batch_bots.py plays each): every one answers for many matches at once, and
would change a result, crash or hang the game, or reach another match, if the wire let it."""
import os
import struct
import sys
import time

import numpy as np

CODES = struct.Struct("<4sqBBHI")  # the CODES header (spacewar.wire), written by hand here


def _answer_fd():
    return int(sys.argv[-1])


class Steady:
    """The honest baseline: thrust in every match, one NumPy call a frame; prints how many
    matches it was asked for and counts its calls."""

    def __init__(self, seed=None):
        self.seed = seed
        self.calls = 0

    def act_batch(self, obs):
        if self.calls == 0:
            print(f"rows {len(obs)} seed {self.seed}", flush=True)
        self.calls += 1
        return np.full(len(obs), 4, dtype=np.int64)  # thrust, no turn (1 + 3)


class WrongCount(Steady):
    """Answers one code too many: its host refuses the answer (invalid)."""

    def act_batch(self, obs):
        return np.zeros(len(obs) + 1, dtype=np.int64)


class ForgedCount(Steady):
    """Writes its own CODES message claiming one row more than it was asked, then lets its
    host answer too."""

    def act_batch(self, obs):
        self.calls += 1
        os.write(_answer_fd(), CODES.pack(b"SWC1", self.calls - 1, 1, 0, 0, len(obs) + 1)
                 + b"\x04" * (len(obs) + 1))
        return np.zeros(len(obs), dtype=np.int64)


class ForgedRange(Steady):
    """Writes its own answer for the right call with codes out of range (invalid), and then
    its host answers the same call again (an answer nobody asked for: a breach)."""

    def act_batch(self, obs):
        os.write(_answer_fd(), CODES.pack(b"SWC1", self.calls, 1, 0, 0, len(obs))
                 + b"\xc8" * len(obs))
        self.calls += 1
        return np.zeros(len(obs), dtype=np.int64)


class StaleCall(Steady):
    """Answers for a call it was not asked (the previous one)."""

    def act_batch(self, obs):
        os.write(_answer_fd(), CODES.pack(b"SWC1", self.calls + 1000, 1, 0, 0, len(obs))
                 + b"\x00" * len(obs))
        time.sleep(60)


class HugeText(Steady):
    """Claims a 60 kB error text."""

    def act_batch(self, obs):
        os.write(_answer_fd(), CODES.pack(b"SWC1", 0, 2, 0, 60000, 0) + b"x" * 100)
        time.sleep(60)


class Flood(Steady):
    """Writes a megabyte into its answer pipe."""

    def act_batch(self, obs):
        try:
            os.write(_answer_fd(), b"SWC1" * (1 << 18))
        except OSError:
            pass
        time.sleep(60)


class ReadyAgain(Steady):
    """Sends a READY answer in the middle of play."""

    def act_batch(self, obs):
        os.write(_answer_fd(), CODES.pack(b"SWC1", 0, 0, 0, 0, 0))
        time.sleep(60)


class Slow(Steady):
    """Takes half a second for every batch: late for every match it plays."""

    def act_batch(self, obs):
        time.sleep(0.5)
        return super().act_batch(obs)


class Hang(Steady):
    """Never answers."""

    def act_batch(self, obs):
        while True:
            pass


class DiesLater(Steady):
    """Plays honestly for ten calls, then its process dies."""

    def act_batch(self, obs):
        if self.calls >= 10:
            os._exit(9)
        return super().act_batch(obs)


class Raises(Steady):
    def act_batch(self, obs):
        raise RuntimeError("no policy here")


class Pretender:
    """Defines act_batch in its source, then takes it away when it is made."""

    def __init__(self):
        self.act_batch = None

    def act_batch(self, obs):  # noqa: F811 (the point of the bot)
        return np.zeros(len(obs), dtype=np.int64)


class ThinksThenRaises(Steady):
    """Thinks for most of its allowance, then says it raised: a confined bot's word that it
    raised is no reason to charge it nothing (found by a red team: it banked free thinking)."""

    def act_batch(self, obs):
        end = time.perf_counter() + 0.2 * len(obs)
        while time.perf_counter() < end:
            pass
        raise RuntimeError("thought for free")


class _OwnAnswer(Steady):
    """Answers a call with a CODES message of its own making (``forged``; None lets its host
    answer honestly) and keeps its host's answer to that call off the wire: the answer pipe
    then points, until its next call, at a pipe of its own that nobody reads."""

    def __init__(self, seed=None):
        super().__init__(seed)
        self._wire = self._sink = self._drain = None

    def forged(self, call, k):
        return None

    def act_batch(self, obs):
        fd = _answer_fd()
        if self._wire is None:
            self._wire = os.dup(fd)
            self._drain, self._sink = os.pipe()
            os.set_blocking(self._drain, False)
        os.dup2(self._wire, fd)  # the real answer pipe, for this call
        try:
            while os.read(self._drain, 1 << 16):  # what its host said last time: dropped
                pass
        except BlockingIOError:
            pass
        message = self.forged(self.calls, len(obs))
        self.calls += 1
        if message is not None:
            os.write(fd, message)
            os.dup2(self._sink, fd)  # its host's answer to this call goes nowhere
        return np.full(len(obs), 4, dtype=np.int64)


def _codes_message(call, status, codes):
    return CODES.pack(b"SWC1", call, status, 0, 0, len(codes)) + bytes(codes)


class NoCodes(_OwnAnswer):
    """Status OK with no code at all, every call."""

    act_batch = _OwnAnswer.act_batch  # in its body: it plays as a batch bot

    def forged(self, call, k):
        return _codes_message(call, 1, [])


class OneCodeShort(_OwnAnswer):
    """Status OK with K - 1 codes."""

    act_batch = _OwnAnswer.act_batch  # in its body: it plays as a batch bot

    def forged(self, call, k):
        return _codes_message(call, 1, [4] * (k - 1))


class OneCodeOver(_OwnAnswer):
    """Status OK with K + 1 codes."""

    act_batch = _OwnAnswer.act_batch  # in its body: it plays as a batch bot

    def forged(self, call, k):
        return _codes_message(call, 1, [4] * (k + 1))


class RaisedWithCodes(_OwnAnswer):
    """Says it raised, and sends K codes all the same."""

    act_batch = _OwnAnswer.act_batch  # in its body: it plays as a batch bot

    def forged(self, call, k):
        return _codes_message(call, 2, [4] * k)


class OneBadCode(_OwnAnswer):
    """K codes on its first call, the last one out of range (200); honest afterwards."""

    act_batch = _OwnAnswer.act_batch  # in its body: it plays as a batch bot

    def forged(self, call, k):
        return _codes_message(call, 1, [4] * (k - 1) + [200]) if call == 0 else None


class IdlesAlone(Steady):
    """Does nothing when asked for one match at a time (as ``spacewar check`` used to ask
    every batch bot) and turns, thrusts and fires when asked for several (as a tournament
    asks it): a check that asks it alone sees another bot than the tournament gets."""

    def act_batch(self, obs):
        if len(obs) == 1:
            return np.full(1, 1, dtype=np.int64)  # no turn, nothing else: a no-op
        return np.full(len(obs), 2 + 3 + 6, dtype=np.int64)  # turn, thrust, fire


class FromTheClock(Steady):
    """Turns one way or the other as the clock's nanoseconds say: never the same play twice."""

    def act_batch(self, obs):
        return np.array([time.perf_counter_ns() % 3 for _ in range(len(obs))], dtype=np.int64)
