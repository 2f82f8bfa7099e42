"""The replay viewer: a replay in the window, to play, pause, step, speed up, slow down and
rewind.

    from spacewar.view.replay_view import view_replay      # also spacewar.viewer.view_replay
    view_replay("match.json")            # Space pauses, hold R rewinds, Esc quits

Going backwards re-simulates: ``spacewar.replay.timeline.ReplayTimeline`` restores the nearest
checkpoint of the compiled state at or before the target frame and steps the recorded actions
forward to it, so every frame shown backwards is bit-identical to the one shown forwards. The
window, its pacing and its loop are ``spacewar.view.window``'s.
"""

from spacewar.view import keys as K
from spacewar.view.look import DIM_TEXT, SHIP_COLOURS, TEXT
from spacewar.view.scene import Effects, footer_top, frame_snapshot, scene
from spacewar.view.window import (Pace, Window, blend, check_display, check_speed,
                                  check_window_arguments, help_lines, run_window)


#: short key help for the replay window's footer
REPLAY_SCREEN_HELP = (("Space", "pause"), (". ,", "step"), ("hold R", "rewind"),
                      ("Left/Right", f"-/+{K.JUMP_SECONDS} s"), ("Home/End", "ends"),
                      ("[ ]", "speed"), ("1", "1x"), ("click bar", "jump"), ("Esc", "quit"))
BAR_HEIGHT = 6  # pixels of the timeline bar
BAR_REACH = 8  # pixels above and below the bar that a click still counts for


class ReplayView:
    """The state of a replay window beside its timeline: speed, pause, what happened.

    Every change of the cursor goes through here, so the drawing's effects (hyperspace
    flashes, torpedo bursts) are fed each frame played forwards and reset after any jump.
    """

    def __init__(self, timeline, pace, size):
        self.timeline = timeline
        self.pace = pace
        self.size = size
        self.effects = Effects()
        self.effects.update(frame_snapshot(timeline.game))
        self.last_move = 0
        self.reason = None
        self.recorded_end = None  # whether the last frame matched the recording, once reached

    # -- moving the cursor --------------------------------------------------------------------
    def play(self, n):
        """Move ``n`` frames as time passes (forwards: every frame drawn into the effects)."""
        if n > 0:
            moved = self.timeline.step(n, on_frame=self._feed)
        else:
            moved = self.timeline.step(n)
            if moved:
                self._reset_effects()
        self.last_move = moved
        self._note_end()

    def jump(self, frame):
        """Put the cursor on ``frame`` at once (a seek, a step by hand)."""
        before = self.timeline.frame
        frame = min(max(int(frame), 0), self.timeline.total)
        self.timeline.seek(frame)
        if frame == before + 1:
            self.effects.update(frame_snapshot(self.timeline.game))
        elif frame != before:
            self._reset_effects()
        self.last_move = 0  # nothing to blend: show the frame itself
        self._note_end()

    def _feed(self, game):
        self.effects.update(frame_snapshot(game))

    def _reset_effects(self):
        self.effects = Effects()
        self.effects.update(frame_snapshot(self.timeline.game))

    def _note_end(self):
        ended = self.timeline.at_recorded_end()
        if ended is not None:
            self.recorded_end = ended

    # -- input and time -------------------------------------------------------------------------
    def hold(self, held):
        """Keys held: rewinding lasts as long as its key is down."""
        self.pace.rewinding = bool(held & K.REWIND)

    def tick(self):
        """One window tick: the frames it is worth, at the speed and direction chosen."""
        frames = self.pace.frames()
        if frames:
            self.play(frames)

    def press(self, names):
        """Act on key names just pressed (see ``keys.REPLAY_KEYS_HELP``)."""
        pace, timeline = self.pace, self.timeline
        jump = K.JUMP_SECONDS * int(round(pace.fps))
        for name in sorted(names):
            if name in K.QUIT:
                self.reason = "quit"
            elif name in K.PAUSE:
                pace.paused = not pace.paused
            elif name in K.STEP_FORWARD or name in K.STEP_BACK:
                pace.paused = True
                self.jump(timeline.frame + (1 if name in K.STEP_FORWARD else -1))
            elif pace.speed_key(name):
                pass
            elif name in K.JUMP_BACK:
                self.jump(timeline.frame - jump)
            elif name in K.JUMP_FORWARD:
                self.jump(timeline.frame + jump)
            elif name in K.TO_START:
                self.jump(0)
            elif name in K.TO_END:
                self.jump(timeline.total)

    def click(self, x, y):
        """A click or drag on the timeline bar jumps to that point of the match."""
        left, right, top = self._bar()
        if right > left and abs(y - (top + BAR_HEIGHT / 2)) <= BAR_HEIGHT / 2 + BAR_REACH:
            fraction = min(max((x - left) / (right - left), 0.0), 1.0)
            self.jump(round(fraction * self.timeline.total))

    # -- drawing --------------------------------------------------------------------------------
    def _footer(self):
        timeline, pace = self.timeline, self.pace
        fps = pace.fps
        state = []
        if pace.rewinding:
            state.append("rewinding")
        if pace.paused:
            state.append("paused")
        if timeline.frame == timeline.total:
            ok = self.recorded_end
            state.append("end: final state as recorded" if ok else
                         "end: final state DIFFERS from the recording")
        status = (f"frame {timeline.frame} / {timeline.total}   "
                  f"{_clock_text(timeline.frame / fps)} / {_clock_text(timeline.total / fps)}   "
                  f"speed {K.speed_label(pace.speed)}" + "".join(f"   {s}" for s in state))
        keys = help_lines(REPLAY_SCREEN_HELP, self.size)
        return [(status, TEXT)] + [(line, DIM_TEXT) for line in keys]

    def _bar(self):
        """``(left, right, top)`` pixels of the timeline bar, just above the footer."""
        margin = max(8.0, self.size * 0.03)
        top = footer_top(self.size, len(self._footer())) - BAR_HEIGHT - 6
        return margin, self.size - margin, top

    def draw(self, window):
        window.show(self.scene())

    def scene(self):
        timeline, pace = self.timeline, self.pace
        game = timeline.game
        snapshot = frame_snapshot(game)
        if self.last_move > 0 and timeline.previous_positions is not None:
            snapshot = blend(snapshot, game, *timeline.previous_positions, pace.alpha)
        banner = None
        if snapshot["over"] and timeline.frame == timeline.total:
            s0, s1 = snapshot["scores"]
            names = timeline.names
            banner = (f"{names[0]} wins {s0}-{s1}" if s0 > s1 else
                      f"{names[1]} wins {s1}-{s0}" if s1 > s0 else f"a draw {s0}-{s1}")
        prims = scene(snapshot, self.size, effects=self.effects, names=timeline.names,
                      rounds=timeline.rounds, footer=self._footer(), banner=banner)
        return prims + self._bar_prims()

    def _bar_prims(self):
        left, right, top = self._bar()
        bottom = top + BAR_HEIGHT
        total = max(self.timeline.total, 1)
        x = left + (right - left) * self.timeline.frame / total
        return [
            ("poly", [(left, top), (right, top), (right, bottom), (left, bottom)], DIM_TEXT, 1),
            ("fill", [(left, top), (x, top), (x, bottom), (left, bottom)], SHIP_COLOURS[0]),
            ("line", x, top - 3, x, bottom + 3, TEXT, 2),
        ]

    def status(self):
        """Plain data about the view now."""
        return {"frame": self.timeline.frame, "total": self.timeline.total,
                "speed": self.pace.speed, "paused": self.pace.paused,
                "rewinding": self.pace.rewinding}


def _clock_text(seconds):
    minutes, seconds = divmod(seconds, 60.0)
    return f"{int(minutes)}:{seconds:04.1f}"


def view_replay(replay, fps=60, scale=720, speed=1.0, script=None, max_seconds=None,
                on_tick=None, checkpoint_every=None, max_checkpoints=None):
    """Show a replay in a window, to play, pause, step, speed up, slow down and rewind.

    ``replay``: a replay dict or file. ``fps``: game frames a second at 1x. ``scale``: window
    side in pixels. ``speed``: the speed to start at (one of ``keys.SPEEDS``). ``script``: keys
    per window tick instead of the keyboard (``keys.script_source``; mouse events still come
    from pygame's queue), for tests and demos. ``max_seconds``: close after that much wall
    time. ``on_tick(tick, view)``: called after each window tick (numbered from 0, as a
    script's) with the ``ReplayView`` (its ``status()``, its ``timeline``).
    ``checkpoint_every`` and ``max_checkpoints``: the timeline's (``spacewar.replay.timeline``).

    Returns a summary dict: ``reason`` (``quit``, ``closed``, ``time`` or ``interrupted``),
    ``frame`` and ``total``, ``state_sha256`` (the state shown last), ``recorded_end``
    (whether the last frame's state was the recorded ``final_state_sha256``; None if never
    shown), ``ticks``, ``speed``, ``paused``, ``checkpoints`` kept and their
    ``checkpoint_bytes``, ``dropped_ticks`` and ``wall_seconds``.
    """
    from spacewar.replay.timeline import (DEFAULT_CHECKPOINT_EVERY, DEFAULT_MAX_CHECKPOINTS,
                                          ReplayTimeline)

    check_window_arguments(fps, scale, max_seconds)
    speed = check_speed(speed)
    source = None if script is None else K.script_source(script, K.REPLAY_KEY_NAMES)
    if on_tick is not None and not callable(on_tick):
        raise ValueError(f"on_tick must be None or a callable (tick, view), got {on_tick!r}")
    check_display()
    timeline = ReplayTimeline(
        replay,
        checkpoint_every=DEFAULT_CHECKPOINT_EVERY if checkpoint_every is None else checkpoint_every,
        max_checkpoints=DEFAULT_MAX_CHECKPOINTS if max_checkpoints is None else max_checkpoints)
    names = timeline.names
    window = Window(scale, f"Spacewar! replay - {names[0]} (needle) vs {names[1]} (wedge)",
                    K.REPLAY_KEY_NAMES)
    try:
        pace = Pace(fps, speed)
        view = ReplayView(timeline, pace, window.size)
        ticks, seconds = run_window(window, pace, view, source, max_seconds, on_tick)
    finally:
        window.close()
    return {"reason": view.reason, "frame": timeline.frame, "total": timeline.total,
            "state_sha256": timeline.game.state_hash(0), "recorded_end": view.recorded_end,
            "ticks": ticks, "speed": pace.speed, "paused": pace.paused,
            "checkpoints": len(timeline.checkpoints), "checkpoint_bytes": timeline.stored_bytes,
            "dropped_ticks": pace.dropped_ticks, "wall_seconds": seconds}


__all__ = ["view_replay", "ReplayView", "REPLAY_SCREEN_HELP"]
