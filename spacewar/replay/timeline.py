"""A replay cursor: put a recorded match on any frame, forwards or backwards, exactly.

    from spacewar.replay.timeline import ReplayTimeline
    timeline = ReplayTimeline("match.json")
    timeline.seek(1200)          # the state after 1200 recorded frames
    timeline.step(-1)            # one frame back: frame 1199
    timeline.game.state_hash()   # bit-identical to a straight run stopped at frame 1199

Simulation time is not wall time. The game advances in whole frames of its own fixed step
(one time unit, drawn at 60 frames a second by default); how fast those frames are shown,
and in which order, is a separate choice of the viewer. A window that plays a replay at 1/8
or 8 times the speed, pauses, steps frame by frame or runs backwards does not change a single
number of the simulation: every frame shown is the state the recorded actions produce, and
the lecture's fixed-step loop (``engine.clock.FixedStepClock``) is only what turns wall time
into a count of frames to show.

Going backwards cannot run the physics backwards: the game is not reversible (fuel burns a
random amount, hyperspace throws ships to random places, torpedoes are destroyed), and
floating-point steps do not undo exactly anyway. So the cursor keeps **checkpoints**, copies of
the whole compiled state (``Game.checkpoint``), every ``checkpoint_every`` frames as it first
passes them. Seeking to frame f restores the nearest checkpoint at or before f and steps the
recorded action codes forward to f: the result is the state of the straight run, bit for bit.

Memory is bounded. At most ``max_checkpoints`` periodic checkpoints are kept: when one more
would be needed, the spacing doubles and every other checkpoint is dropped (the re-simulation
of a seek then costs at most the spacing in frames). Scrubbing backwards frame by frame would
re-simulate a whole spacing for each frame shown, so a backward seek also keeps the states of
the frames it steps through just before its target (at most ``segment_limit`` of them): the
next frames back are then restored, not re-simulated. ``stored_bytes`` is the total.

No pygame here: the window (``spacewar.view.window``) is a thin layer over this, and the tests drive
this module headless.
"""
import os

import numpy as np

from spacewar import replay as replay_io
from spacewar.replay import ReplayError
from spacewar.rules import count_at_least

DEFAULT_CHECKPOINT_EVERY = 64  # frames: about a second of the game at its usual 60 frames a second
DEFAULT_MAX_CHECKPOINTS = 512  # about 2.5 MB under the 1962 rules
DEFAULT_SEGMENT_LIMIT = 128


class ReplayTimeline:
    """A recorded match that can be put on any of its frames (0 .. ``total``).

    ``replay``: a replay dict (checked with ``spacewar.replay.validate``) or the path of a
    replay file (``spacewar.replay.load``, which also checks its digest). ``checkpoint_every``:
    frames between periodic checkpoints at the start (it doubles as needed to keep at most
    ``max_checkpoints``); ``segment_limit``: most states a backward seek keeps for the frames
    just before its target.

    Frame f is the state after the first f recorded frames were played: 0 is the start,
    ``total`` the end (whose ``state_hash`` is the replay's ``final_state_sha256``).
    """

    def __init__(self, replay, checkpoint_every=DEFAULT_CHECKPOINT_EVERY,
                 max_checkpoints=DEFAULT_MAX_CHECKPOINTS, segment_limit=DEFAULT_SEGMENT_LIMIT):
        self.interval = count_at_least("checkpoint_every", checkpoint_every, 1)
        self.max_checkpoints = count_at_least("max_checkpoints", max_checkpoints, 2)
        self.segment_limit = count_at_least("segment_limit", segment_limit, 0)
        if isinstance(replay, (str, bytes, os.PathLike)):
            replay = replay_io.load(replay)
        else:
            replay = replay_io.validate(replay, "replay")
        self.replay = replay
        self.actions = replay_io.actions(replay)  # (total, 2) int64 codes
        self.total = int(self.actions.shape[0])
        self.game = replay_io.new_game(replay)
        self.frame = 0
        self.checkpoints = {0: self.game.checkpoint(0)}  # frame -> Checkpoint, periodic
        self.segment = {}  # frame -> Checkpoint, the frames before the last backward target
        self.previous_positions = None  # (pos, active) one frame before, after a forward step
        self._on_frame = None

    # -- what it holds ----------------------------------------------------------------------
    @property
    def names(self):
        """The two bots' names as recorded (``("needle", "wedge")`` if none were)."""
        bots = self.replay.get("bots") or ["needle", "wedge"]
        return tuple(bots)

    @property
    def rounds(self):
        return int(self.replay["rounds"])

    @property
    def rules(self):
        return self.game.rules

    @property
    def checkpoint_frames(self):
        """The frames of the periodic checkpoints now kept, in order."""
        return sorted(self.checkpoints)

    @property
    def stored_states(self):
        return len(self.checkpoints) + len(self.segment)

    @property
    def stored_bytes(self):
        """Bytes held by every checkpoint kept (periodic and segment)."""
        return sum(c.nbytes for c in self.checkpoints.values()) + sum(
            c.nbytes for c in self.segment.values())

    def at_recorded_end(self):
        """True when the cursor is on the last frame and its state is the one recorded
        (``final_state_sha256``), False on the last frame with another state, None before it."""
        if self.frame != self.total:
            return None
        return self.game.state_hash(0) == self.replay["final_state_sha256"]

    # -- moving -----------------------------------------------------------------------------
    def seek(self, frame, on_frame=None):
        """Put the cursor on ``frame`` (an int in [0, ``total``]) and return it.

        ``on_frame(game)`` is called after each frame stepped forward on the way (for drawing
        effects that need every frame); not for frames restored from a checkpoint. A target
        out of range raises ValueError naming it, with the cursor left where it was.
        """
        target = self._check_target(frame)
        self.previous_positions = None
        if target == self.frame:
            return target
        backwards = target < self.frame
        start = self._nearest_stored(target)
        if start < self.frame <= target:
            start = self.frame  # already on the way: step on from here
        elif start != self.frame:
            self.game.restore(self._stored(start), 0)
            self.frame = start
        if backwards and start < target:
            self.segment = {}  # a new stretch is re-simulated: keep its frames instead
        keep_from = target - self.segment_limit if backwards else target + 1
        self._on_frame = on_frame
        try:
            self._advance_to(target, keep_from)
        finally:
            self._on_frame = None
        if backwards:
            self.previous_positions = None  # the frame before is not where it came from
        return self.frame

    def step(self, n=1, on_frame=None):
        """Move ``n`` frames (negative: backwards), stopping at either end; return the frames
        actually moved."""
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)):
            raise ValueError(f"n must be an int (frames to move, negative backwards), got {n!r}")
        target = min(max(self.frame + int(n), 0), self.total)
        before = self.frame
        self.seek(target, on_frame=on_frame)
        return self.frame - before

    def _check_target(self, frame):
        if isinstance(frame, bool) or not isinstance(frame, (int, np.integer)):
            raise ValueError(f"frame must be an int in [0, {self.total}], got {frame!r}")
        if not 0 <= frame <= self.total:
            raise ValueError(f"frame must be in [0, {self.total}] (the replay's frames), "
                             f"got {frame}")
        return int(frame)

    def _nearest_stored(self, target):
        """The latest frame at or before ``target`` whose state is kept (0 always is)."""
        best = (target // self.interval) * self.interval
        while best not in self.checkpoints:  # not reached yet, or thinned away
            best -= self.interval
        in_segment = [f for f in self.segment if f <= target]
        return max([best] + in_segment)

    def _stored(self, frame):
        saved = self.segment.get(frame)
        return saved if saved is not None else self.checkpoints[frame]

    def _advance_to(self, target, keep_from):
        """Step the recorded actions from the cursor to ``target``, taking periodic
        checkpoints on the way and keeping segment states for frames >= ``keep_from``."""
        game = self.game
        while self.frame < target:
            if self.frame >= keep_from and self.frame not in self.checkpoints:
                self.segment[self.frame] = game.checkpoint(0)
            if game.over[0]:
                raise ReplayError(f"replay has actions recorded past the end of the match: "
                                  f"frame {self.frame} of {self.total} comes after the game "
                                  "was over")
            if self.frame == target - 1:
                self.previous_positions = (game.pos[0].copy(), game.active[0].copy())
            game.step(self.actions[self.frame][None, :])
            self.frame += 1
            if self._on_frame is not None:
                self._on_frame(game)
            if self.frame % self.interval == 0 and self.frame not in self.checkpoints:
                self._add_checkpoint()

    def _add_checkpoint(self):
        self.checkpoints[self.frame] = self.game.checkpoint(0)
        self.segment.pop(self.frame, None)
        while len(self.checkpoints) > self.max_checkpoints:
            self.interval *= 2  # half as many, twice as far apart: memory stays bounded
            self.checkpoints = {f: c for f, c in self.checkpoints.items()
                                if f % self.interval == 0}


__all__ = ["ReplayTimeline", "DEFAULT_CHECKPOINT_EVERY", "DEFAULT_MAX_CHECKPOINTS",
           "DEFAULT_SEGMENT_LIMIT"]
