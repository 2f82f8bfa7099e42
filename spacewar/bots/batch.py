"""Batch bots: one call decides for every match a bot plays at once.

A batch bot is any object with ``act_batch(self, obs) -> codes``:

- ``obs`` is a (K, D) float32 array, one learning observation per match
  (``spacewar.game.features.learning_layout(rules)`` names the D entries: egocentric, scaled to
  about [-1, 1]; the same numbers ``spacewar.learn.envs`` gives learning code);
- ``codes`` is K game action codes, integers in [0, ``spacewar.codes.N_ACTIONS``) (``turn + 1
  + 3 thrust + 6 fire + 12 hyperspace + 24 flip``; ``spacewar.learn.envs.codes_from_parts`` turns
  MultiDiscrete parts into codes), as a sequence or array of K ints.

It may define ``reset(self)``, called before the first frame. When its matches are played
together (``spacewar.arena.batch_match.play_matches``), the rows are its matches in a fixed order,
every frame until the last one ends: the row of a finished match keeps its last observation
and its action is ignored. A batch bot from a file plays so in its own confined process
(``spacewar.sandbox.process.BatchProcessSeat``) when its class defines ``act_batch`` in its body
(``spacewar.bots.declares_act_batch``). Played one match at a time (``spacewar match``), it
is called with K = 1; ``spacewar check`` plays it as a tournament does, K matches at once
(``spacewar.author.check``). Over the wire its process answers each call with exactly K codes
and status OK, or with no code and another status; any other count is a breach of the
protocol (``spacewar.wire``), which forfeits all its live matches.

A NumPy or PyTorch policy so plays hundreds of matches in one forward pass.
"""
import numpy as np

from spacewar import codes
from spacewar.wire import INVALID, MEMORY, OK, RAISED, exception_text


def is_batch_bot(bot):
    """Whether ``bot`` answers for many matches at once (it has a callable ``act_batch``)."""
    try:
        return callable(getattr(bot, "act_batch", None))
    except BaseException:  # a hostile __getattr__ is not a batch bot
        return False


def ask_batch(bot, obs):
    """``(status, codes, text)`` for ``bot.act_batch(obs)``, whatever it does: ``codes`` is a
    (K,) int64 array of valid action codes when ``status`` is OK, else K no-ops, and ``text``
    says what went wrong (the statuses of ``spacewar.wire``)."""
    k = obs.shape[0]
    noop = np.full(k, codes.NOOP, dtype=np.int64)
    try:
        answer = bot.act_batch(obs)
    except MemoryError:
        return MEMORY, noop, "MemoryError in act_batch"
    except BaseException as exc:  # SystemExit and KeyboardInterrupt from a bot are its faults
        return RAISED, noop, exception_text(exc)
    try:
        return OK, checked_codes(answer, k), ""
    except ValueError as exc:
        return INVALID, noop, str(exc)
    except BaseException as exc:
        return INVALID, noop, exception_text(exc)


def checked_codes(answer, k):
    """``answer`` as (k,) int64 action codes, or ValueError saying why it is not."""
    if isinstance(answer, np.ndarray):
        # a plain copy of its memory: a subclass's own methods (astype, indexing) never run
        array = np.array(answer, copy=True, subok=False)
    elif isinstance(answer, (list, tuple)):
        if len(answer) != k or not all(type(x) in _INT_TYPES for x in answer):
            raise ValueError(f"act_batch must return {k} integer action codes")
        array = np.array([int(x) for x in answer], dtype=np.int64)
    else:
        raise ValueError(f"act_batch must return a sequence or array of {k} action codes, got "
                         f"{type(answer).__name__}")
    if array.shape != (k,) or array.dtype.kind not in "iu":
        raise ValueError(f"act_batch must return {k} integer action codes, got "
                         f"{array.dtype} {array.shape}")
    bad = (array < 0) | (array >= codes.N_ACTIONS)
    if bad.any():
        raise ValueError(f"action code {array[bad][0]} out of range [0, {codes.N_ACTIONS})")
    return array.astype(np.int64)


_INT_TYPES = (int, np.int8, np.int16, np.int32, np.int64, np.uint8, np.uint16, np.uint32,
              np.uint64)


def one_match_bot(bot, rules, rounds):
    """``bot`` as a match alone asks it: a batch bot without ``act`` wrapped in
    ``SingleFromBatch`` (K = 1), any other bot as it is."""
    if is_batch_bot(bot) and not callable(getattr(bot, "act", None)):
        return SingleFromBatch(bot, rules, rounds)
    return bot


class SingleFromBatch:
    """A batch bot playing one match: ``act(obs)`` asks ``act_batch`` with K = 1 on the
    learning observation of the ``Observation`` it gets (``spacewar.game.features.learning_vector``
    of its raw numbers). ``rounds`` is the match's (the learning observation scales the
    score and round count by it)."""

    def __init__(self, bot, rules, rounds):
        from spacewar.game.features import (learning_vector)  # imported now, in the bot's start-up time

        self.bot = bot
        self.rules = rules
        self.rounds = int(rounds)
        self._vector = learning_vector

    def reset(self):
        reset = getattr(self.bot, "reset", None)
        if callable(reset):
            reset()

    def answer(self, obs):
        """``(status, code, text)`` as ``spacewar.bots.ask.ask`` gives for a bot with ``act``."""
        row = self._vector(obs.raw(), self.rules, self.rounds)[None]
        status, answer, text = ask_batch(self.bot, row)
        return status, int(answer[0]), text

    def act(self, obs):
        """The ``Action`` (for a caller that wants one; raises what act_batch raised)."""
        from spacewar.protocol import Action

        status, code, text = self.answer(obs)
        if status != OK:
            raise ValueError(f"act_batch failed: {text}")
        return Action.from_code(code)


__all__ = ["is_batch_bot", "ask_batch", "checked_codes", "one_match_bot", "SingleFromBatch"]
