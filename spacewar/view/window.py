"""The Spacewar! window: its display check, its pacing, and the replay viewer with rewind.

    from spacewar.view.window import view_replay
    view_replay("match.json")            # Space pauses, hold R rewinds, Esc quits

Simulation time is not wall time. A game frame is one fixed step of the simulation, the same
whatever the screen does; the window only decides how many of them to show per second of wall
time. ``Pace`` makes that decision in two stages, both with the engine's fixed-step clock
(``engine.clock.FixedStepClock``, the accumulator loop of Glenn Fiedler's "Fix Your Timestep!",
2004): wall time becomes whole window *ticks* (``fps`` a second), and each tick becomes a
signed number of game *frames* at the chosen speed (1/8x to 8x, negative while rewinding),
kept as an exact remainder so that 1/8x shows exactly one frame every eight ticks. What is
drawn between two frames is blended by the clocks' remainders, so slow motion moves smoothly.
Scripts (for tests and demos) give keys per tick, so a scripted session plays the same frames
whatever the machine's speed.

Going backwards re-simulates: ``spacewar.replay.timeline.ReplayTimeline`` restores the nearest
checkpoint of the compiled state at or before the target frame and steps the recorded actions
forward to it, so every frame shown backwards is bit-identical to the one shown forwards.

pygame is the optional ``[viz]`` extra and is imported only when a window opens; on Linux a
window needs a display (``DISPLAY`` or ``WAYLAND_DISPLAY``), or ``SDL_VIDEODRIVER`` set to a
driver that works (``dummy`` draws nowhere, for tests and screenshots).
"""
import os
import sys
import time

from spacewar.view import keys as K
from spacewar.view.look import DIM_TEXT, SHIP_COLOURS, TEXT, VIZ_HINT
from spacewar.view.scene import Effects, footer_pixels, footer_top, frame_snapshot, scene

RENDER_CAP = 120  # most drawn frames a second
HEADLESS_DRIVERS = ("dummy", "offscreen")  # SDL drivers that draw nowhere


class NoDisplayError(RuntimeError):
    """No window can be shown here (no display, or the requested video driver fails)."""


# -- opening a window -----------------------------------------------------------------------
def check_display(environ=None, platform=None):
    """Raise NoDisplayError unless a window can be shown, before anything is started.

    On Linux and the other X11/Wayland systems a window needs ``DISPLAY`` or
    ``WAYLAND_DISPLAY``; without them SDL would quietly pick a driver that draws nowhere and
    the game would run invisibly. ``SDL_VIDEODRIVER`` set by the user is taken as meant
    (``dummy`` runs headless on purpose); whether that driver works is found when the window
    opens (``Window``). macOS and Windows always have a display.
    """
    environ = os.environ if environ is None else environ
    platform = sys.platform if platform is None else platform
    if platform.startswith(("win", "darwin", "cygwin", "emscripten")):
        return
    if environ.get("SDL_VIDEODRIVER") or environ.get("DISPLAY") or environ.get("WAYLAND_DISPLAY"):
        return
    raise NoDisplayError("no display: DISPLAY and WAYLAND_DISPLAY are not set, so no window "
                         "can open (run it in a desktop session, or with SDL_VIDEODRIVER=dummy "
                         "to draw nowhere)")


def require_pygame():
    """The pygame module, or an ImportError saying how to get it."""
    os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
    try:
        import pygame
    except ImportError as exc:
        raise ImportError(f"the Spacewar! window needs pygame, part of the optional [viz] "
                          f"extra: {VIZ_HINT}") from exc
    return pygame


def paint(pygame, surface, prims, fonts):
    """Paint ``spacewar.view.scene.scene`` primitives on a pygame surface (``fonts``: a dict this
    function fills, kept by the caller between frames)."""
    surface.fill((0, 0, 0))
    for p in prims:
        kind = p[0]
        if kind == "dot":
            _, x, y, r, rgb = p
            if r < 0.75:
                surface.set_at((int(x), int(y)), rgb)
            else:
                pygame.draw.circle(surface, rgb, (x, y), r)
        elif kind == "ring":
            _, x, y, r, rgb, width = p
            if r >= 1.0:
                pygame.draw.circle(surface, rgb, (x, y), r, width)
        elif kind == "poly":
            _, points, rgb, width = p
            if width <= 1:
                pygame.draw.aalines(surface, rgb, True, points)
            else:
                pygame.draw.lines(surface, rgb, True, points, width)
        elif kind == "fill":
            _, points, rgb = p
            pygame.draw.polygon(surface, rgb, points)
        elif kind == "line":
            _, x0, y0, x1, y1, rgb, width = p
            pygame.draw.line(surface, rgb, (x0, y0), (x1, y1), width)
        elif kind == "text":
            _, x, y, text, rgb, align, pixels = p
            font = fonts.get(pixels)
            if font is None:
                font = fonts[pixels] = pygame.font.Font(None, int(pixels * 1.35))
            image = font.render(text, True, rgb)
            if align == "centre":
                x -= image.get_width() / 2.0
            elif align == "right":
                x -= image.get_width()
            surface.blit(image, (x, y))
        else:
            raise ValueError(f"unknown drawing primitive {kind!r}")


class Window:
    """A square pygame window of ``size`` pixels: input in key names, output in primitives.

    Opening it checks the display first (``check_display``) and refuses to run invisibly: a
    driver that fails, or SDL falling back to one that draws nowhere when the user did not ask
    for it, raises NoDisplayError. ``close`` shuts pygame's display down again.
    """

    def __init__(self, size, caption, key_names):
        check_display()
        pygame = self.pygame = require_pygame()
        try:
            pygame.display.init()
            pygame.font.init()
            self.surface = pygame.display.set_mode((size, size))
        except pygame.error as exc:
            self.close()
            driver = os.environ.get("SDL_VIDEODRIVER") or "chosen by SDL"
            raise NoDisplayError(f"cannot open a window: {exc} (video driver {driver})") from None
        driver = pygame.display.get_driver()
        if driver in HEADLESS_DRIVERS and not os.environ.get("SDL_VIDEODRIVER"):
            self.close()
            raise NoDisplayError(f"no display: SDL found none it can use (it fell back to "
                                 f"{driver!r}); check DISPLAY / WAYLAND_DISPLAY")
        pygame.display.set_caption(caption)
        self.size = size
        self.fonts = {}
        self.keycodes = {getattr(pygame, K.KEY_CONSTANTS[name]): name for name in key_names}
        self._limiter = pygame.time.Clock()

    def poll(self):
        """``(pressed, clicks, closed)``: key names pressed since the last poll, left-button
        clicks and drags as ``(x, y)`` pixels, and whether the window was closed."""
        pygame = self.pygame
        pressed, clicks, closed = set(), [], False
        for event in pygame.event.get():
            if event.type == pygame.QUIT:
                closed = True
            elif event.type == pygame.KEYDOWN:
                pressed.add(self.keycodes.get(event.key, "other"))
            elif event.type == pygame.MOUSEBUTTONDOWN and event.button == 1:
                clicks.append(event.pos)
            elif event.type == pygame.MOUSEMOTION and event.buttons[0]:
                clicks.append(event.pos)
        return pressed, clicks, closed

    def held(self):
        """The key names held down now (the keyboard's state)."""
        state = self.pygame.key.get_pressed()
        return frozenset(name for code, name in self.keycodes.items() if state[code])

    def show(self, prims):
        paint(self.pygame, self.surface, prims, self.fonts)
        self.pygame.display.flip()
        self._limiter.tick(RENDER_CAP)

    def close(self):
        # each font holds its file open until it is freed: a program that opens and closes
        # windows would run out of file descriptors (a confined bot gets 64) with them kept
        self.fonts = {}
        self.pygame.display.quit()
        self.pygame.font.quit()


# -- pacing -----------------------------------------------------------------------------------
class Pace:
    """Wall time to window ticks, and window ticks to game frames at a speed (see the module).

    ``ticks()``: how many window ticks are due now (at most a tenth of a second's worth: a
    slow frame drops time rather than falling ever further behind, counted in
    ``dropped_ticks``). ``frames()``: the signed game frames of one tick, at ``speed`` times
    real time, backwards while ``rewinding``, none while ``paused`` (unless rewinding).
    """

    def __init__(self, fps, speed=1.0):
        from engine.clock import FixedStepClock

        self.fps = fps
        self.wall = FixedStepClock(dt=1.0 / fps, max_steps_per_frame=max(2, int(fps) // 10))
        self.game = FixedStepClock(dt=1.0, max_steps_per_frame=int(max(K.SPEEDS)))
        self.speed = check_speed(speed)
        self.paused = False
        self.rewinding = False
        self.wall.tick()  # starts the wall-time measurement

    def ticks(self):
        return self.wall.tick()

    def frames(self):
        """Game frames for one window tick (negative: backwards)."""
        if self.rewinding:
            scale = -self.speed
        else:
            scale = 0.0 if self.paused else self.speed
        self.game.time_scale = scale
        return self.game.tick(1.0)

    @property
    def alpha(self):
        """How far the drawing is from the frame before the last one to the last one (1: the
        last frame itself): the game clock's remainder plus the part of a tick gone by."""
        if self.paused and not self.rewinding:
            return 1.0
        return min(1.0, self.game.alpha + self.wall.alpha * self.speed)

    @property
    def dropped_ticks(self):
        return self.wall.dropped_steps

    def faster(self):
        self.speed = next((s for s in K.SPEEDS if s > self.speed), self.speed)

    def slower(self):
        self.speed = next((s for s in reversed(K.SPEEDS) if s < self.speed), self.speed)

    def normal(self):
        self.speed = 1.0

    def speed_key(self, name):
        """Apply a speed key (faster, slower, normal); whether ``name`` was one."""
        for keys, change in ((K.FASTER, self.faster), (K.SLOWER, self.slower),
                             (K.NORMAL_SPEED, self.normal)):
            if name in keys:
                change()
                return True
        return False


def check_speed(speed):
    """``speed`` if it is one of ``keys.SPEEDS``, else ValueError naming it."""
    if (isinstance(speed, bool) or not isinstance(speed, (int, float))
            or float(speed) not in K.SPEEDS):
        raise ValueError(f"speed must be one of {', '.join(f'{s:g}' for s in K.SPEEDS)}, "
                         f"got {speed!r}")
    return float(speed)


def check_window_arguments(fps, scale, max_seconds):
    """ValueError naming the first bad one of a window's common arguments."""
    if isinstance(fps, bool) or not isinstance(fps, (int, float)) or not 1 <= fps <= 1000:
        raise ValueError(f"fps must be a number in [1, 1000], got {fps!r}")
    if isinstance(scale, bool) or not isinstance(scale, int) or scale < 128:
        raise ValueError(f"scale must be an int >= 128 (pixels), got {scale!r}")
    if max_seconds is not None and (isinstance(max_seconds, bool)
                                    or not isinstance(max_seconds, (int, float))
                                    or not max_seconds > 0):
        raise ValueError(f"max_seconds must be None or a number > 0, got {max_seconds!r}")


def blend(snapshot, game, prev_pos, prev_active, alpha):
    """The snapshot with bodies moved ``alpha`` of the way from their previous position
    (``prev_pos``/``prev_active``: the game's ``pos[0]``/``active[0]`` one frame before);
    a body that jumped (hyperspace, a new round, the torus edge) is shown where it is."""
    import numpy as np

    from engine import space

    pos = game.pos[0]
    active = game.active[0]
    moving = active & prev_active
    step = space.wrap(pos - prev_pos, 1.0)
    smooth = moving & (np.abs(step).max(axis=0) < 0.05)
    blended = np.where(smooth, space.wrap(prev_pos + alpha * step, 1.0), pos)
    live = [b for b in range(2, game.n_bodies) if active[b]]  # the snapshot's torpedo order
    for s in range(2):
        if smooth[s]:
            snapshot["ships"][s]["pos"] = [float(blended[0, s]), float(blended[1, s])]
    for torpedo, b in zip(snapshot["torpedoes"], live):
        if smooth[b]:
            torpedo["pos"] = [float(blended[0, b]), float(blended[1, b])]
    return snapshot


def help_lines(rows, size, prefix=""):
    """Key help rows as footer lines of ``keys: what`` that fit a window of ``size`` pixels
    (pygame's default font is under 0.45 of its nominal height wide per character)."""
    width = int(0.92 * size / (0.45 * footer_pixels(size)))
    lines, parts = [], [prefix + rows[0][0] + ": " + rows[0][1]]
    for keys, what in rows[1:]:
        part = f"{keys}: {what}"
        if len("   ".join(parts + [part])) > width:
            lines.append("   ".join(parts))
            parts = []
        parts.append(part)
    return lines + ["   ".join(parts)]


# -- the loop ----------------------------------------------------------------------------------
def run_window(window, pace, session, source=None, max_seconds=None, on_tick=None):
    """Run ``session`` in ``window`` until its ``reason`` is set; return ``(ticks, seconds)``.

    Each pass reads the window's events (a closed window ends it, clicks go to
    ``session.click(x, y)``), then plays the window ticks that are due: keys come from the
    keyboard once a pass or, with a script ``source``, per tick (``session.hold(held)`` with
    the keys held, ``session.press(names)`` with those just pressed), and ``session.tick()``
    advances it. ``max_seconds`` of wall time end it with reason ``time``, Ctrl-C with
    ``interrupted``. ``on_tick(tick, session)`` is called after each tick, numbered from 0
    as a script's. Then ``session.draw(window)``.
    """
    tick = 0
    scripted_before = frozenset()
    start = time.perf_counter()
    try:
        while session.reason is None:
            pressed, clicks, closed = window.poll()
            if closed:
                session.reason = "closed"
            for x, y in clicks:
                session.click(x, y)
            if source is None:
                session.hold(window.held())
                session.press(pressed)
            for _ in range(pace.ticks()):
                if session.reason is not None:
                    break
                if source is not None:
                    held = source(tick)
                    session.hold(held)
                    session.press(held - scripted_before)
                    scripted_before = held
                    if session.reason is not None:
                        break
                index, tick = tick, tick + 1
                session.tick()
                if on_tick is not None:
                    on_tick(index, session)
            if (max_seconds is not None and session.reason is None
                    and time.perf_counter() - start >= max_seconds):
                session.reason = "time"
            session.draw(window)
    except KeyboardInterrupt:
        session.reason = "interrupted"
    return tick, time.perf_counter() - start


# -- the replay viewer ------------------------------------------------------------------------
#: short key help for the replay window's footer
REPLAY_SCREEN_HELP = (("Space", "pause"), (". ,", "step"), ("hold R", "rewind"),
                      ("Left/Right", f"-/+{K.JUMP_SECONDS} s"), ("Home/End", "ends"),
                      ("[ ]", "speed"), ("1", "1x"), ("click bar", "jump"), ("Esc", "quit"))
#: short key help for the watch window's footer
WATCH_SCREEN_HELP = (("Space", "pause"), (".", "step"), ("[ ]", "speed"), ("1", "1x"),
                     ("Esc", "quit"))
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
    from spacewar.replay.timeline import DEFAULT_CHECKPOINT_EVERY, DEFAULT_MAX_CHECKPOINTS, ReplayTimeline

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


__all__ = ["view_replay", "run_window", "check_display", "NoDisplayError", "Window", "Pace",
           "ReplayView", "paint", "blend", "require_pygame", "check_speed"]
