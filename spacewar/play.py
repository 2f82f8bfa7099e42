"""Play Spacewar! at the keyboard against a bot, in a pygame window.

    from spacewar.play import play
    play("chaser", rounds=5)

You fly the needle (seat 0, blue); the bot flies the wedge (seat 1, orange). Keys:

    A / D  or  Left / Right     turn (anticlockwise / clockwise)
    W  or  Up                   thrust
    Space  or  S                fire
    H, or both turn keys        hyperspace (as on the 1962 control boxes)
    F                           flip polarity (electric mode)
    P                           pause / resume
    Esc                         quit

The game runs at ``fps`` frames a second whatever the drawing rate: an
``engine.clock.FixedStepClock`` turns wall time into whole game frames, and the drawing
blends the last two frames by the clock's ``alpha``. The bot sits in a fault-isolated seat
(``spacewar.seats.open_seat``), so a bot that raises or dawdles only loses its turn.
pygame is part of the optional ``[viz]`` extra and is imported only by ``play``.
"""
import math
import os
import time
from bisect import bisect_right

import numpy as np

from engine import space

from . import core
from .game import Game
from .match import bot_seed
from .protocol import Action
from .render import DIM_TEXT, SHIP_COLOURS, VIZ_HINT, Effects, scene
from .rules import Rules
from .seats import Limits, open_seat

BOT_BUDGET = 0.05  # seconds per bot action
RENDER_CAP = 120  # most drawn frames a second

TURN_LEFT = frozenset({"a", "left"})
TURN_RIGHT = frozenset({"d", "right"})
THRUST = frozenset({"w", "up"})
FIRE = frozenset({"space", "s"})
HYPERSPACE = frozenset({"h"})
FLIP = frozenset({"f"})
PAUSE = "p"
QUIT = "escape"
#: every key name the game reads (pygame's names for them)
KEY_NAMES = TURN_LEFT | TURN_RIGHT | THRUST | FIRE | HYPERSPACE | FLIP | {PAUSE, QUIT}

#: (keys, what they do): shown on screen and in the help
KEYS_HELP = (
    ("A/D or Left/Right", "turn"),
    ("W or Up", "thrust"),
    ("Space or S", "fire"),
    ("H or both turn keys", "hyperspace"),
    ("F", "flip polarity"),
    ("P", "pause"),
    ("Esc", "quit"),
)


def require_pygame():
    """The pygame module, or an ImportError saying how to get it."""
    os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
    try:
        import pygame
    except ImportError as exc:
        raise ImportError(f"playing Spacewar! needs pygame, part of the optional [viz] extra: "
                          f"{VIZ_HINT}") from exc
    return pygame


def action_code(held):
    """The action code for the set of held key names (pressing both turns is hyperspace)."""
    left = bool(held & TURN_LEFT)
    right = bool(held & TURN_RIGHT)
    both = left and right
    turn = 0 if left == right else (1 if left else -1)  # +1 is anticlockwise, screen y is up
    return Action(turn=turn, thrust=bool(held & THRUST), fire=bool(held & FIRE),
                  hyperspace=bool(held & HYPERSPACE) or both, flip=bool(held & FLIP)).code()


def _key_set(keys, where):
    if isinstance(keys, str):
        keys = {keys}
    try:
        names = frozenset(str(k).lower() for k in keys)
    except TypeError:
        raise ValueError(f"{where}: keys must be a set of key names, got {keys!r}") from None
    unknown = sorted(names - KEY_NAMES)
    if unknown:
        raise ValueError(f"{where}: unknown key name(s) {', '.join(map(repr, unknown))}; "
                         f"known: {', '.join(sorted(KEY_NAMES))}")
    return names


def script_source(script):
    """A function ``frame -> frozenset of held key names`` from a ``play`` script.

    ``script`` is either a callable ``frame -> keys`` or a sequence of ``(frame, keys)``:
    from each listed frame on, exactly those keys are held (until the next entry). Frames
    count the game's fixed-rate ticks from the start, paused or not (so a script can pause
    and resume); a key appearing in a frame's set that was not held the frame before is a
    press (which is what toggles pause and quits).
    """
    if callable(script):
        return lambda frame: _key_set(script(frame), f"script({frame})")
    try:
        entries = sorted((int(f), _key_set(keys, f"script entry at frame {f}")) for f, keys in script)
    except (TypeError, ValueError) as exc:
        if isinstance(exc, ValueError) and "key" in str(exc):
            raise
        raise ValueError("script must be a callable or a sequence of (frame, set of key names), "
                         f"got {script!r}") from None
    frames = [f for f, _ in entries]
    empty = frozenset()

    def held(frame):
        i = bisect_right(frames, frame) - 1
        return entries[i][1] if i >= 0 else empty

    return held


def _pygame_keys(pygame):
    """pygame key constant -> key name, for the keys the game reads."""
    return {getattr(pygame, "K_" + (name if len(name) == 1 else name.upper())): name
            for name in KEY_NAMES}


def _paint(pygame, surface, prims, fonts):
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


def _wrap(d):
    return space.wrap(d, 1.0)


def _blend(snapshot, game, prev_pos, prev_active, alpha):
    """The snapshot with bodies moved ``alpha`` of the way from their previous position."""
    pos = game.pos[0]
    active = game.active[0]
    moving = active & prev_active
    step = _wrap(pos - prev_pos)
    smooth = moving & (np.abs(step).max(axis=0) < 0.05)  # not a jump (hyperspace, new round)
    blended = np.where(smooth, _wrap(prev_pos + alpha * step), pos)
    # snapshot lists live torpedoes by body index, in order
    live = [b for b in range(2, game.n_bodies) if active[b]]
    for s in range(2):
        if smooth[s]:
            snapshot["ships"][s]["pos"] = [float(blended[0, s]), float(blended[1, s])]
    for torpedo, b in zip(snapshot["torpedoes"], live):
        if smooth[b]:
            torpedo["pos"] = [float(blended[0, b]), float(blended[1, b])]
    return snapshot


def play(p2="chaser", rules=None, seed=0, rounds=5, fps=60, scale=720, script=None,
         max_seconds=None):
    """A human (seat 0, the needle) against the bot ``p2`` (seat 1) in a pygame window.

    ``rules``: a ``Rules`` (or its dict), default the 1962 game. ``fps``: game frames a
    second. ``scale``: window side in pixels. ``script``: keys to play instead of the
    keyboard (see ``script_source``), for tests and demos. ``max_seconds``: stop after that
    much wall time. Returns a summary dict: ``reason`` (``over``, ``quit``, ``closed`` or
    ``time``), ``scores`` [human, bot], ``frames`` played, ``rounds``, ``over``, ``winner``
    (``human``, ``bot`` or None), per-seat ``torpedoes_fired``, ``distance`` flown (arena
    units) and ``hyperspace_jumps``, the bot's ``bot_faults``, ``paused_frames``,
    ``dropped_steps`` (frames the clock skipped because drawing fell behind) and
    ``wall_seconds``.
    """
    if rules is None:
        rules = Rules()
    elif isinstance(rules, dict):
        rules = Rules.from_dict(rules)
    elif not isinstance(rules, Rules):
        raise TypeError(f"rules must be a spacewar.Rules or its dict, got {rules!r}")
    if isinstance(fps, bool) or not isinstance(fps, (int, float)) or not 1 <= fps <= 1000:
        raise ValueError(f"fps must be a number in [1, 1000], got {fps!r}")
    if isinstance(scale, bool) or not isinstance(scale, int) or scale < 128:
        raise ValueError(f"scale must be an int >= 128 (pixels), got {scale!r}")
    if max_seconds is not None and (isinstance(max_seconds, bool)
                                    or not isinstance(max_seconds, (int, float))
                                    or not max_seconds > 0):
        raise ValueError(f"max_seconds must be None or a number > 0, got {max_seconds!r}")
    source = None if script is None else script_source(script)
    pygame = require_pygame()
    from engine.clock import FixedStepClock

    game = Game(rules, seeds=[seed], rounds=rounds)  # checks seed and rounds
    seat = open_seat(p2, bot_seed(seed, 1), Limits(budget=BOT_BUDGET), rules, rounds=rounds)
    if getattr(seat, "wait_ready", None) is not None and seat.wait_ready() is not None:
        seat.close()
        raise ValueError(f"bot {p2!r} could not start: {seat.dead[1]}")
    try:
        pygame.display.init()
        pygame.font.init()
        try:
            screen = pygame.display.set_mode((scale, scale))
        except pygame.error as exc:
            raise RuntimeError(f"cannot open a game window: {exc} (is there a display? "
                               "SDL_VIDEODRIVER=dummy runs without one)") from exc
        pygame.display.set_caption(f"Spacewar! - you (needle) vs {p2} (wedge)")
        return _run(pygame, screen, game, seat, p2, seed, rounds, fps, scale, source,
                    max_seconds, FixedStepClock)
    finally:
        seat.close()
        pygame.display.quit()
        pygame.font.quit()


def _run(pygame, screen, game, seat, p2, seed, rounds, fps, scale, source, max_seconds,
         FixedStepClock):
    keycodes = _pygame_keys(pygame)
    fonts = {}
    effects = Effects()
    effects.update(game.snapshot(0))
    actions = np.full((1, 2), core.NOOP, dtype=np.int64)
    fired = [0, 0]
    distance = [0.0, 0.0]
    jumps = [0, 0]
    faults = 0
    fault_examples = []
    paused = False
    paused_frames = 0
    ticks = 0  # the clock's frames since the start, paused or not (a script's time line)
    held = frozenset()
    scripted_before = frozenset()
    prev_pos = game.pos[0].copy()
    prev_active = game.active[0].copy()
    reason = None
    help_lines = ["   ".join(f"{keys}: {what}" for keys, what in KEYS_HELP[:4]),
                  "   ".join(f"{keys}: {what}" for keys, what in KEYS_HELP[4:])]
    clock = FixedStepClock(dt=1.0 / fps, max_steps_per_frame=max(2, int(fps) // 10))
    frame_limiter = pygame.time.Clock()
    start = time.perf_counter()
    clock.tick()  # starts the wall-time measurement
    while reason is None:
        pressed = set()
        for event in pygame.event.get():
            if event.type == pygame.QUIT:
                reason = "closed"
            elif event.type == pygame.KEYDOWN:
                pressed.add(keycodes.get(event.key, "other"))
        if QUIT in pressed:
            reason = "quit"
        if source is None:
            state = pygame.key.get_pressed()
            held = frozenset(name for code, name in keycodes.items() if state[code])
            if PAUSE in pressed and not game.over[0]:
                paused = not paused
        if game.over[0]:
            if source is not None or (pressed and reason is None):
                reason = reason or "over"
        for _ in range(clock.tick()):
            if reason is not None:
                break
            if source is not None:
                held = source(ticks)
                new = held - scripted_before
                scripted_before = held
                if QUIT in new:
                    reason = "quit"
                    break
                if PAUSE in new:
                    paused = not paused
            ticks += 1
            if game.over[0]:
                break
            if paused:
                paused_frames += 1
                continue
            actions[0, 0] = action_code(held)
            code, fault = seat.act(game.raw_observation(0, 1))
            actions[0, 1] = code
            if fault is not None:
                faults += 1
                if len(fault_examples) < 3:
                    fault_examples.append({"frame": int(game.frame[0]), "kind": fault[0],
                                           "message": fault[1]})
            before_torps = game.ship_counters[0, :, core.TORPS].copy()
            before_hyper = game.ship_counters[0, :, core.IN_HYPER].copy()
            before_round = game.rounds_played(0)
            prev_pos = game.pos[0].copy()
            prev_active = game.active[0].copy()
            game.step(actions)
            if game.rounds_played(0) == before_round:
                after_torps = game.ship_counters[0, :, core.TORPS]
                for s in range(2):
                    fired[s] += int(max(0, before_torps[s] - after_torps[s]))
                    if game.ship_counters[0, s, core.IN_HYPER] and not before_hyper[s]:
                        jumps[s] += 1
                    if prev_active[s] and game.active[0, s]:
                        step = _wrap(game.pos[0, :, s] - prev_pos[:, s])
                        if abs(step).max() < 0.05:
                            distance[s] += float(math.hypot(*step))
            effects.update(game.snapshot(0))
        if max_seconds is not None and time.perf_counter() - start >= max_seconds and reason is None:
            reason = "time"
        _draw(pygame, screen, fonts, game, effects, p2, rounds, clock, prev_pos, prev_active,
              paused, help_lines, source is not None)
        frame_limiter.tick(RENDER_CAP)
    scores = [int(x) for x in game.scores[0]]
    over = bool(game.over[0])
    winner = None
    if over and scores[0] != scores[1]:
        winner = "human" if scores[0] > scores[1] else "bot"
    return {"reason": reason, "scores": scores, "frames": int(game.frame[0]),
            "rounds": game.rounds_played(0), "over": over, "winner": winner,
            "torpedoes_fired": fired, "distance": distance, "hyperspace_jumps": jumps,
            "bot": p2, "seed": seed, "bot_faults": faults, "bot_fault_examples": fault_examples,
            "paused_frames": paused_frames, "dropped_steps": clock.dropped_steps,
            "wall_seconds": time.perf_counter() - start}


def _draw(pygame, screen, fonts, game, effects, p2, rounds, clock, prev_pos, prev_active,
          paused, help_lines, scripted):
    snapshot = game.snapshot(0)
    if not paused and not snapshot["over"]:
        snapshot = _blend(snapshot, game, prev_pos, prev_active, clock.alpha)
    me = game.ship_counters[0, 0]
    fuel = 100.0 * game.ship_gauges[0, 0, core.FUEL] / max(game.rules.fuel, 1e-300)
    status = (f"fuel {fuel:3.0f}%   torpedoes {int(me[core.TORPS])}   "
              f"hyperspace {int(me[core.HYPER_LEFT])}")
    footer = [(status, SHIP_COLOURS[0])] + [(line, DIM_TEXT) for line in help_lines]
    banner = None
    if snapshot["over"]:
        s0, s1 = snapshot["scores"]
        outcome = "you win" if s0 > s1 else "you lose" if s1 > s0 else "a draw"
        banner = f"game over: {outcome}" + ("" if scripted else " - press a key")
    elif paused:
        banner = "paused (P to resume)"
    size = screen.get_width()
    prims = scene(snapshot, size, effects=effects, names=("you", p2), rounds=rounds,
                  footer=footer, banner=banner)
    _paint(pygame, screen, prims, fonts)
    pygame.display.flip()


__all__ = ["play", "action_code", "script_source", "KEYS_HELP", "KEY_NAMES", "require_pygame"]
