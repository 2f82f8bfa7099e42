"""The Spacewar! window: its display check, its painter, its pacing and its loop (the replay
viewer on top of it is ``spacewar.view.replay_view``; ``play`` and ``watch`` are
``spacewar.view.live``).
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

pygame is the optional ``[viz]`` extra and is imported only when a window opens; on Linux a
window needs a display (``DISPLAY`` or ``WAYLAND_DISPLAY``), or ``SDL_VIDEODRIVER`` set to a
driver that works (``dummy`` draws nowhere, for tests and screenshots).
"""
import os
import sys
import time

from spacewar.view import keys as K
from spacewar.view.look import VIZ_HINT
from spacewar.view.scene import footer_pixels

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


#: short key help for the watch window's footer
WATCH_SCREEN_HELP = (("Space", "pause"), (".", "step"), ("[ ]", "speed"), ("1", "1x"),
                     ("Esc", "quit"))


__all__ = ["run_window", "check_display", "NoDisplayError", "Window", "Pace", "paint", "blend",
           "require_pygame", "check_speed", "check_window_arguments", "help_lines",
           "WATCH_SCREEN_HELP"]
