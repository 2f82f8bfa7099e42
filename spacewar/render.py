"""Drawing Spacewar!: a replay to an animated GIF, one frame to a Pillow image.

    from spacewar.render import render_gif
    render_gif("match.json", "match.gif")          # a replay file or a replay dict

The drawing has two halves. ``scene(snapshot, size, ...)`` turns the plain data of one frame
(``Game.snapshot``) into a list of backend-neutral primitives in pixel coordinates: dots,
rings, outlined and filled polygons, lines and text. ``render_frame`` paints that list with
Pillow; the pygame window (``spacewar.viewer``, for ``play``, ``watch`` and ``replay --view``)
paints the same list with pygame, so the GIF and the live game look alike.

What is drawn: black space with a faint fixed star field, the central star as a flickering
dot with rays (nothing when the rules have no star), the two ships as outlined shapes as in
1962 (seat 0 the needle, seat 1 the wedge) turned to their heading with a flame behind a
thrusting ship, torpedoes as dots in their owner's colour (a few pixels across even in a
480-pixel GIF), expanding rings of debris where a ship died, a short flash where a ship jumps
into or back out of hyperspace (a ship in hyperspace is not drawn), a small burst where a
torpedo vanishes, and the names, scores and round at the top. Objects near an edge are also
drawn on the opposite edge (the arena is a torus). Screen y points up, as the game's: a
positive turn is anticlockwise on screen.

Given a snapshot from ``frame_snapshot(game)`` (``Game.snapshot`` plus the rules' capacities),
the top also shows the mode and, for each ship, its fuel (as a percentage and a bar), its
torpedoes and hyperspace jumps left and, in the electric mode, the sign of its charge (red +,
blue -), also drawn beside the ship and as a ring round each torpedo.

Pillow (and pygame for the window) are the optional ``[viz]`` extra; they are imported only
when something is drawn.
"""
import math
import os
import random
from itertools import product

import numpy as np

from engine import space
from engine.atomic import atomic_write, check_output_path

VIZ_HINT = "pip install -e '.[viz]'"

# -- looks --------------------------------------------------------------------------------
BLACK = (0, 0, 0)
SHIP_COLOURS = ((120, 205, 255), (255, 180, 80))  # seat 0 (needle), seat 1 (wedge)
TORPEDO_COLOURS = ((205, 240, 255), (255, 232, 150))
FLAME_COLOURS = ((255, 150, 40), (255, 240, 170))  # outer, inner
STAR_CORE = (255, 255, 235)
STAR_RAYS = ((255, 255, 200), (255, 225, 130), (215, 175, 90))
SKY = ((55, 55, 70), (85, 85, 100), (125, 125, 140))
TEXT = (225, 225, 225)
DIM_TEXT = (130, 130, 130)
CHARGE_COLOURS = ((255, 85, 85), (90, 125, 255))  # positive, negative
FIRE = ((255, 255, 255), (255, 245, 185), (255, 215, 100), (255, 160, 50), (235, 100, 35),
        (180, 60, 25), (120, 35, 15), (65, 18, 8))
FADES = (1.0, 0.7, 0.45, 0.25)

SHIP_LENGTH = 0.04  # arena units (about 40 of the PDP-1's 1024 points)
MIN_SHIP_PIXELS = 10.0
#: outlines in units of the ship's length, x forward along the heading, y to the left
NEEDLE = ((0.56, 0.0), (0.32, 0.065), (-0.30, 0.065), (-0.48, 0.17), (-0.48, -0.17),
          (-0.30, -0.065), (0.32, -0.065))
WEDGE = ((0.50, 0.0), (-0.40, 0.27), (-0.50, 0.11), (-0.50, -0.11), (-0.40, -0.27))
SHAPES = (NEEDLE, WEDGE)
EXHAUST = ((-0.48, 0.065), (-0.50, 0.11))  # (x, half width) of each shape's nozzle

EXPLOSION_FRAMES = 48
HYPERSPACE_FLASH_FRAMES = 14
TORPEDO_BURST_FRAMES = 8
FINAL_HOLD_MS = 1500  # the last GIF frame stays up this long

DEFAULT_NAMES = ("needle", "wedge")
TORPEDO_RADIUS_PER_PIXEL = 1.0 / 190.0  # of the image side: 2.5 pixels at 480
MIN_TORPEDO_RADIUS = 2.5  # pixels: a torpedo is a visible dot at any size


def require_pillow():
    """``(Image, ImageDraw, ImageFont)`` from Pillow, or an ImportError saying how to get it."""
    try:
        from PIL import Image, ImageDraw, ImageFont
    except ImportError as exc:
        raise ImportError("drawing Spacewar! needs Pillow, part of the optional [viz] extra: "
                          f"{VIZ_HINT}") from exc
    return Image, ImageDraw, ImageFont


# -- geometry helpers ---------------------------------------------------------------------
def to_pixels(x, y, size):
    """Arena coordinates ([-0.5, 0.5), y up) to pixels (origin top left, y down)."""
    return (x + 0.5) * size, (0.5 - y) * size


def _images(x, y, reach):
    """The torus images of a point worth drawing: itself plus copies across near edges."""
    xs = [x]
    ys = [y]
    if x - reach < -0.5:
        xs.append(x + 1.0)
    if x + reach >= 0.5:
        xs.append(x - 1.0)
    if y - reach < -0.5:
        ys.append(y + 1.0)
    if y + reach >= 0.5:
        ys.append(y - 1.0)
    return product(xs, ys)


def _torus_distance(a, b):
    dx = space.nearest_image(b[0] - a[0], 1.0)
    dy = space.nearest_image(b[1] - a[1], 1.0)
    return math.hypot(dx, dy)


def _rng(*key):
    """A small deterministic random stream for one visual detail (flicker, debris)."""
    seed = 0
    for k in key:
        seed = (seed * 1000003 + int(k) + 7) % (1 << 62)
    return random.Random(seed)


def _fade(rgb, level):
    return tuple(int(round(c * level)) for c in rgb)


def ship_length(size):
    """The drawn length of a ship in arena units at an image of ``size`` pixels."""
    return max(SHIP_LENGTH, MIN_SHIP_PIXELS / size)


def _place(points, x, y, heading, length, size):
    c, s = math.cos(heading), math.sin(heading)
    out = []
    for u, v in points:
        px, py = to_pixels(x + length * (u * c - v * s), y + length * (u * s + v * c), size)
        out.append((px, py))
    return out


# -- effects that need more than one frame ------------------------------------------------
class Effects:
    """Remembers the previous frame to spot hyperspace jumps and vanished torpedoes.

    Feed it every simulated frame in order (``update(snapshot)``), not only the drawn ones.
    Explosions need no memory: a snapshot's ``killed_at`` dates them.
    """

    LIFETIMES = {"jump": HYPERSPACE_FLASH_FRAMES, "return": HYPERSPACE_FLASH_FRAMES,
                 "burst": TORPEDO_BURST_FRAMES}

    def __init__(self):
        self.events = []  # (kind, seat or owner, x, y, frame)
        self._prev = None

    def update(self, snapshot):
        prev, self._prev = self._prev, snapshot
        frame = snapshot["frame"]
        self.events = [e for e in self.events if 0 <= frame - e[4] < self.LIFETIMES[e[0]]]
        if prev is None:
            return
        if (snapshot["round"] != prev["round"] or snapshot["round_frame"] < prev["round_frame"]
                or frame <= prev["frame"]):
            self.events.clear()  # a new round (everything was reset) or a jump in time
            return
        for seat in range(2):
            before, now = prev["ships"][seat], snapshot["ships"][seat]
            if now["in_hyperspace"] and not before["in_hyperspace"]:
                self.events.append(("jump", seat, *before["pos"], frame))
            elif before["in_hyperspace"] and not now["in_hyperspace"]:
                self.events.append(("return", seat, *now["pos"], frame))
        self._torpedo_bursts(prev, snapshot, frame)

    def _torpedo_bursts(self, prev, snapshot, frame):
        # Live torpedoes are listed in slot order and each new one takes a higher slot than
        # any before it in the round, so this frame's list minus the newly launched ones at
        # its end is an ordered subsequence of the previous frame's list.
        for owner in range(2):
            before = [t["pos"] for t in prev["torpedoes"] if t["owner"] == owner]
            after = [t["pos"] for t in snapshot["torpedoes"] if t["owner"] == owner]
            launched = max(0, prev["ships"][owner]["torpedoes"] - snapshot["ships"][owner]["torpedoes"])
            survivors = after[:max(0, len(after) - launched)]
            if len(survivors) >= len(before):
                continue
            j = 0
            for pos in before:
                if j < len(survivors) and _torus_distance(pos, survivors[j]) < 0.02:
                    j += 1
                else:
                    self.events.append(("burst", owner, pos[0], pos[1], frame))

    def current(self, frame):
        return [e for e in self.events if 0 <= frame - e[4] < self.LIFETIMES[e[0]]]


# -- what a frame shows -------------------------------------------------------------------
def frame_snapshot(game, m=0):
    """``game.snapshot(m)`` with what the top of the screen shows beside it: ``mode``,
    ``fuel_capacity``, ``torpedo_capacity``, ``hyperspace_capacity``, each ship's
    ``hyperspace`` jumps left and each torpedo's ``charge``. Plain data, as the snapshot."""
    from . import core

    snap = game.snapshot(m)
    rules = game.rules
    snap["mode"] = rules.mode
    snap["fuel_capacity"] = float(rules.fuel)
    snap["torpedo_capacity"] = int(rules.torpedoes)
    snap["hyperspace_capacity"] = int(rules.hyperspace_jumps)
    for seat, ship in enumerate(snap["ships"]):
        ship["hyperspace"] = int(game.ship_counters[m, seat, core.HYPER_LEFT])
    # the snapshot lists the live torpedoes in body order
    live = [b for b in range(2, game.n_bodies) if game.active[m, b]]
    for torpedo, body in zip(snap["torpedoes"], live):
        torpedo["charge"] = float(game.charge[m, body])
    return snap


# -- the scene ----------------------------------------------------------------------------
_SKY_CACHE = {}


def _starfield(size):
    """Faint fixed background stars, clear of the centre (so the central star stands alone)."""
    if size not in _SKY_CACHE:
        rng = random.Random(1962)
        prims = []
        while len(prims) < 70:
            x, y = rng.random() - 0.5, rng.random() - 0.5
            if x * x + y * y < 0.1 ** 2:
                continue
            px, py = to_pixels(x, y, size)
            prims.append(("dot", px, py, 0.5 if rng.random() < 0.8 else 1.0, rng.choice(SKY)))
        _SKY_CACHE[size] = prims
    return _SKY_CACHE[size]


def _star(frame, size):
    rng = _rng(frame, 1)
    cx, cy = to_pixels(0.0, 0.0, size)
    reach = max(8.0, 0.028 * size)
    prims = []
    base = rng.random() * 2.0 * math.pi
    rays = 4 + rng.randrange(3)
    for k in range(rays):
        angle = base + 2.0 * math.pi * (k + 0.3 * rng.random()) / rays
        length = reach * (0.4 + 0.6 * rng.random())
        prims.append(("line", cx, cy, cx + length * math.cos(angle), cy - length * math.sin(angle),
                      rng.choice(STAR_RAYS), 1))
    prims.append(("dot", cx, cy, max(2.0, size / 200.0), STAR_CORE))
    return prims


def _ship(ship, seat, frame, size):
    x, y = ship["pos"]
    heading = ship["heading"]
    length = ship_length(size)
    width = 1 if size < 600 else 2
    prims = []
    for ix, iy in _images(x, y, length):
        if ship["thrusting"]:
            rng = _rng(frame, seat, 2)
            nozzle, half = EXHAUST[seat]
            long_flame = 0.3 + 0.4 * rng.random()
            short_flame = 0.45 * long_flame
            prims.append(("fill", _place(((nozzle, half), (nozzle - long_flame, 0.0), (nozzle, -half)),
                                         ix, iy, heading, length, size), FLAME_COLOURS[0]))
            prims.append(("fill", _place(((nozzle, 0.5 * half), (nozzle - short_flame, 0.0),
                                          (nozzle, -0.5 * half)), ix, iy, heading, length, size),
                          FLAME_COLOURS[1]))
        prims.append(("poly", _place(SHAPES[seat], ix, iy, heading, length, size), SHIP_COLOURS[seat],
                      width))
    return prims


def _explosion(ship, seat, age, size):
    """Rings of debris flying out from where a ship died, cooling from white to dark red."""
    x, y = ship["pos"]
    t = age / EXPLOSION_FRAMES
    rng = _rng(ship["killed_at"], seat, 3)
    reach = 0.055
    prims = []
    spread = 1.0 - (1.0 - t) ** 2  # fast at first, then slowing
    n = 36
    for k in range(n):
        shell = 1.0 if k % 2 == 0 else 0.55
        angle = 2.0 * math.pi * (k + 0.8 * rng.random()) / n
        r = reach * shell * (0.85 + 0.3 * rng.random()) * spread
        heat = min(len(FIRE) - 1, int(t * len(FIRE) + rng.random() * 1.5))
        for ix, iy in _images(x + r * math.cos(angle), y + r * math.sin(angle), 0.0):
            px, py = to_pixels(ix, iy, size)
            prims.append(("dot", px, py, 1.5 if t < 0.4 else 1.0, FIRE[heat]))
    if age < 14:  # a shock ring and the first flash
        ring_t = age / 14.0
        for ix, iy in _images(x, y, reach):
            px, py = to_pixels(ix, iy, size)
            prims.append(("ring", px, py, reach * 0.9 * ring_t * size, FIRE[min(7, int(ring_t * 6))], 1))
            if age < 3:
                prims.append(("dot", px, py, ship_length(size) * size * (0.45 - 0.1 * age), FIRE[age]))
    return prims


def _flash(event, frame, size):
    kind, who, x, y, start = event
    t = (frame - start) / Effects.LIFETIMES[kind]
    prims = []
    if kind == "burst":
        colour = _fade(TORPEDO_COLOURS[who], FADES[min(3, int(t * 4))])
        r = (2.0 + 6.0 * t) * size / 480.0
        for ix, iy in _images(x, y, 0.01):
            px, py = to_pixels(ix, iy, size)
            for k in range(6):
                a = k * math.pi / 3.0 + 0.5
                prims.append(("dot", px + r * math.cos(a), py + r * math.sin(a), 0.5, colour))
        return prims
    colour = _fade(SHIP_COLOURS[who], FADES[min(3, int(t * 4))])
    grow = t if kind == "return" else 1.0 - t
    r = ship_length(size) * size * (0.25 + 0.75 * grow)
    for ix, iy in _images(x, y, ship_length(size)):
        px, py = to_pixels(ix, iy, size)
        for k in range(8):
            a = k * math.pi / 4.0 + (frame - start) * 0.2
            inner = 0.3 * r if k % 2 else 0.0
            prims.append(("line", px + inner * math.cos(a), py + inner * math.sin(a),
                          px + r * math.cos(a), py + r * math.sin(a), colour, 1))
    return prims


def _round_label(snapshot, rounds):
    played = snapshot["round"]
    if snapshot.get("over"):
        return "final"
    current = played + 1
    if rounds is None:
        return f"round {current}"
    if current > rounds:
        return f"round {current} (extra)"
    return f"round {current}/{rounds}"


def font_pixels(size):
    """The score line's text height at an image of ``size`` pixels."""
    return max(10, size // 32)


def footer_pixels(size):
    """The footer's (and the ships' gauges') text height."""
    return max(9, int(font_pixels(size) * 0.8))


def footer_top(size, lines):
    """The y pixel where a footer of ``lines`` lines starts (a window may draw above it)."""
    return size - lines * footer_pixels(size) * 1.35 - font_pixels(size) * 0.5 * 0.3


def _gauge_top(size):
    """The y pixel where the line under the score (mode and gauges) starts."""
    return font_pixels(size) * (0.3 + 1.45)


def hud_bottom(size):
    """The y pixel below the top lines (score, and the gauges of a ``frame_snapshot``)."""
    return _gauge_top(size) + footer_pixels(size) * 1.35 + 6


def _torpedoes(snapshot, size):
    """Each torpedo as a dot in its owner's colour, ringed by its charge's in electric mode."""
    radius = max(MIN_TORPEDO_RADIUS, size * TORPEDO_RADIUS_PER_PIXEL)
    electric = snapshot.get("mode") == "electric"
    prims = []
    for torpedo in snapshot["torpedoes"]:
        charge = torpedo.get("charge", 0.0) if electric else 0.0
        for ix, iy in _images(*torpedo["pos"], 0.0):
            px, py = to_pixels(ix, iy, size)
            prims.append(("dot", px, py, radius, TORPEDO_COLOURS[torpedo["owner"]]))
            if charge:
                prims.append(("ring", px, py, radius + 1.5, CHARGE_COLOURS[charge < 0], 1))
    return prims


def _sign_glyph(x, y, half, charge):
    """A plus or minus sign centred on (x, y), ``half`` pixels to each side, in the charge's
    colour (drawn with lines, so it reads the same in every font and backend)."""
    rgb = CHARGE_COLOURS[charge < 0]
    width = 2 if half >= 3 else 1
    prims = [("line", x - half, y, x + half, y, rgb, width)]
    if charge > 0:
        prims.append(("line", x, y - half, x, y + half, rgb, width))
    return prims


def _ship_charge(ship, size):
    """The ship's charge sign just above and ahead of it on screen."""
    if not ship.get("charge"):
        return []
    length = ship_length(size)
    half = max(2.5, 0.16 * length * size)
    prims = []
    for ix, iy in _images(*ship["pos"], length):
        px, py = to_pixels(ix, iy, size)
        prims.extend(_sign_glyph(px + 0.7 * length * size, py - 0.7 * length * size, half,
                                 ship["charge"]))
    return prims


def _gauges(ship, snapshot, size, seat):
    """One ship's line under its name: fuel as text and a bar, torpedoes and hyperspace jumps
    left (the jumps only where there is room), its charge sign in electric mode."""
    text_px = font_pixels(size)
    small = footer_pixels(size)
    margin = text_px * 0.5
    top = _gauge_top(size)
    fraction = min(1.0, max(0.0, ship["fuel"] / max(snapshot["fuel_capacity"], 1e-300)))
    text = f"fuel {100.0 * fraction:.0f}%  torp {ship['torpedoes']}"
    if size >= 400 and "hyperspace" in ship:
        text += f"  hyp {ship['hyperspace']}"
    left = seat == 0
    edge = margin if left else size - margin
    inward = 1.0 if left else -1.0
    prims = []
    if snapshot["mode"] == "electric" and ship.get("charge"):
        half = max(2.5, small * 0.3)
        prims.extend(_sign_glyph(edge + inward * half, top + small * 0.55, half, ship["charge"]))
        edge += inward * (2 * half + small * 0.5)
    colour = SHIP_COLOURS[seat]
    prims.append(("text", edge, top, text, colour, "left" if left else "right", small))
    # the fuel bar under the text: outline, then the fuel left from the outer edge inwards
    bar_top = top + small * 1.3
    bar_height = max(2.0, small * 0.3)
    width = size * 0.2
    outer = margin if left else size - margin
    inner = outer + inward * width
    full = outer + inward * width * fraction
    prims.append(("poly", [(outer, bar_top), (inner, bar_top), (inner, bar_top + bar_height),
                           (outer, bar_top + bar_height)], _fade(colour, FADES[2]), 1))
    if fraction > 0:
        prims.append(("fill", [(outer, bar_top), (full, bar_top), (full, bar_top + bar_height),
                               (outer, bar_top + bar_height)], colour))
    return prims


def _hud(snapshot, size):
    """The mode in the middle and each ship's gauges under its name."""
    prims = [("text", size / 2.0, _gauge_top(size), snapshot["mode"], DIM_TEXT, "centre", footer_pixels(size))]
    for seat, ship in enumerate(snapshot["ships"]):
        prims.extend(_gauges(ship, snapshot, size, seat))
    return prims


def scene(snapshot, size, effects=None, names=None, rounds=None, footer=(), banner=None,
          starfield=True):
    """The primitives that draw ``snapshot`` on a ``size`` x ``size`` image, in paint order.

    Each is a tuple, coordinates in pixels and colours RGB:
    ``("dot", x, y, r, rgb)``, ``("ring", x, y, r, rgb, width)``, ``("poly", points, rgb,
    width)`` (closed outline), ``("fill", points, rgb)``, ``("line", x0, y0, x1, y1, rgb,
    width)``, ``("text", x, y_top, text, rgb, align, font_pixels)`` with align ``left``,
    ``centre`` or ``right``.

    ``effects``: an ``Effects`` fed every frame so far (hyperspace flashes, torpedo bursts);
    ``names``: the two players' names for the score line; ``rounds``: rounds asked for;
    ``footer``: lines ``(text, rgb)`` along the bottom; ``banner``: large text in the middle.
    A snapshot from ``frame_snapshot`` (which has a ``mode``) also gets the mode and each
    ship's gauges under the score line (``hud_bottom`` is where they end), and in the
    electric mode the charge signs; a plain ``Game.snapshot`` gets the score line only.
    """
    prims = []
    frame = snapshot["frame"]
    if starfield:
        prims.extend(_starfield(size))
    if snapshot.get("star"):
        prims.extend(_star(frame, size))
    prims.extend(_torpedoes(snapshot, size))
    for seat, ship in enumerate(snapshot["ships"]):
        if ship["alive"]:
            if not ship["in_hyperspace"]:
                prims.extend(_ship(ship, seat, frame, size))
        elif ship.get("killed_at", -1) >= 0 and 0 <= frame - ship["killed_at"] < EXPLOSION_FRAMES:
            prims.extend(_explosion(ship, seat, frame - ship["killed_at"], size))
    if snapshot.get("mode") == "electric":
        for ship in snapshot["ships"]:
            if ship["alive"] and not ship["in_hyperspace"]:
                prims.extend(_ship_charge(ship, size))
    if effects is not None:
        for event in effects.current(frame):
            prims.extend(_flash(event, frame, size))
    # the score line
    text_px = font_pixels(size)
    names = DEFAULT_NAMES if names is None else names
    s0, s1 = snapshot["scores"]
    margin = text_px * 0.5
    prims.append(("text", margin, margin * 0.6, f"{names[0]}  {s0}", SHIP_COLOURS[0], "left", text_px))
    prims.append(("text", size - margin, margin * 0.6, f"{s1}  {names[1]}", SHIP_COLOURS[1], "right", text_px))
    prims.append(("text", size / 2.0, margin * 0.6, _round_label(snapshot, rounds), TEXT, "centre", text_px))
    if "mode" in snapshot:
        prims.extend(_hud(snapshot, size))
    small = footer_pixels(size)
    for k, (text, rgb) in enumerate(reversed(list(footer))):
        prims.append(("text", size / 2.0, size - (k + 1) * small * 1.35 - margin * 0.3, text, rgb,
                      "centre", small))
    if banner:
        big = 2 * text_px
        prims.append(("text", size / 2.0, size * 0.3, banner, TEXT, "centre", big))
    return prims


# -- Pillow backend -----------------------------------------------------------------------
def _build_palette():
    colours = [BLACK]
    ramps = list(SHIP_COLOURS) + list(TORPEDO_COLOURS)
    for rgb in ramps:
        colours.extend(_fade(rgb, f) for f in FADES)
    colours.extend(FLAME_COLOURS)
    colours.append(STAR_CORE)
    colours.extend(STAR_RAYS)
    colours.extend(SKY)
    colours.extend((TEXT, DIM_TEXT))
    colours.extend(CHARGE_COLOURS)
    colours.extend(FIRE)
    for grey in (40, 90, 170, 255):
        colours.append((grey, grey, grey))
    unique = []
    for c in colours:
        if c not in unique:
            unique.append(c)
    assert len(unique) < 63
    while len(unique) < 63:
        unique.append(BLACK)
    unique.append((1, 2, 3))  # index 63: "unchanged" (transparent) in GIF delta frames
    return unique


PALETTE = _build_palette()
TRANSPARENT = len(PALETTE) - 1
_PALETTE_BYTES = bytes(c for rgb in PALETTE for c in rgb)
_INDEX = {}


def palette_index(rgb):
    """The index of the palette colour nearest ``rgb`` (never the transparent one)."""
    rgb = tuple(int(c) for c in rgb)
    index = _INDEX.get(rgb)
    if index is None:
        index = min(range(TRANSPARENT),
                    key=lambda i: sum((a - b) ** 2 for a, b in zip(PALETTE[i], rgb)))
        _INDEX[rgb] = index
    return index


_FONTS = {}


def _pil_font(pixels):
    if pixels not in _FONTS:
        _, _, ImageFont = require_pillow()
        try:
            font = ImageFont.load_default(size=pixels)  # scalable (Pillow >= 10.1 with FreeType)
        except Exception:
            font = ImageFont.load_default()
        _FONTS[pixels] = font
    return _FONTS[pixels]


def paint_pil(image, prims):
    """Paint ``scene`` primitives onto a Pillow image in the module's palette ('P' mode)."""
    _, ImageDraw, _ = require_pillow()
    draw = ImageDraw.Draw(image)
    for p in prims:
        kind = p[0]
        if kind == "dot":
            _, x, y, r, rgb = p
            if r < 0.75:
                draw.point((x, y), fill=palette_index(rgb))
            else:
                draw.ellipse((x - r, y - r, x + r, y + r), fill=palette_index(rgb))
        elif kind == "ring":
            _, x, y, r, rgb, width = p
            if r >= 1.0:
                draw.ellipse((x - r, y - r, x + r, y + r), outline=palette_index(rgb), width=width)
        elif kind == "poly":
            _, points, rgb, width = p
            draw.line(list(points) + [points[0]], fill=palette_index(rgb), width=width)
        elif kind == "fill":
            _, points, rgb = p
            draw.polygon(points, fill=palette_index(rgb))
        elif kind == "line":
            _, x0, y0, x1, y1, rgb, width = p
            draw.line((x0, y0, x1, y1), fill=palette_index(rgb), width=width)
        elif kind == "text":
            _, x, y, text, rgb, align, pixels = p
            font = _pil_font(pixels)
            left, _, right, _ = draw.textbbox((0, 0), text, font=font)
            w = right - left
            if align == "centre":
                x -= w / 2.0
            elif align == "right":
                x -= w
            draw.text((x - left, y), text, fill=palette_index(rgb), font=font)
        else:
            raise ValueError(f"unknown drawing primitive {kind!r}")
    return image


def new_image(size):
    """A black ``size`` x ``size`` 'P' image carrying the module's palette."""
    Image, _, _ = require_pillow()
    image = Image.new("P", (size, size), 0)
    image.putpalette(_PALETTE_BYTES)
    return image


def render_frame(snapshot, size=480, effects=None, names=None, rounds=None, footer=(), banner=None):
    """One snapshot (``frame_snapshot(game, m)``, or ``Game.snapshot(m)`` without the gauges)
    as a ``size`` x ``size`` Pillow image in 'P' mode (a fixed 64-colour palette;
    ``.convert("RGB")`` for other uses). The other arguments are those of ``scene``."""
    size = _check_size(size)
    image = new_image(size)
    return paint_pil(image, scene(snapshot, size, effects=effects, names=names, rounds=rounds,
                                  footer=footer, banner=banner))


# -- GIF output ---------------------------------------------------------------------------
class _GifWriter:
    """Writes frames as they come: each frame after the first holds only the box that changed,
    with unchanged pixels transparent, so memory stays flat however long the match.

    Uses Pillow's GIF header and frame encoders (``GifImagePlugin.getheader`` / ``getdata``);
    if a Pillow lacks them, frames are kept and saved by ``Image.save(save_all=True)``.
    A frame identical to the one before only lengthens that one's display time.
    """

    def __init__(self, stream, fps):
        from PIL import GifImagePlugin

        self._gif = GifImagePlugin
        self.streaming = hasattr(GifImagePlugin, "getheader") and hasattr(GifImagePlugin, "getdata")
        self.stream = stream
        self.fps = fps
        self.added = 0  # frames given to add()
        self.written = 0  # GIF frames in the file
        self._pending = None  # [pixels, image, centiseconds]: held back to merge or extend
        self._last = None  # pixels of the last frame written
        self._kept = []  # (image, centiseconds) when not streaming

    def add(self, image):
        # whole centiseconds whose running total tracks the exact frame times (30 fps: 3,3,4,..)
        cs = round(100 * (self.added + 1) / self.fps) - round(100 * self.added / self.fps)
        self.added += 1
        pixels = np.asarray(image)
        if self._pending is not None and np.array_equal(pixels, self._pending[0]):
            self._pending[2] += cs
            return
        if self._pending is not None:
            self._write(*self._pending)
        self._pending = [pixels, image, cs]

    def close(self, hold_ms=FINAL_HOLD_MS):
        if self._pending is not None:
            self._pending[2] += hold_ms // 10
            self._write(*self._pending)
            self._pending = None
        if self.streaming:
            if self.written:
                self.stream.write(b";")
        elif self._kept:
            images = [im for im, _ in self._kept]
            images[0].save(self.stream, format="GIF", save_all=True, append_images=images[1:],
                           duration=[10 * cs for _, cs in self._kept], loop=0, optimize=True)
            self.written = len(images)

    def _write(self, pixels, image, cs):
        cs = max(1, min(cs, 65535))
        if not self.streaming:
            self._kept.append((image, cs))
            return
        if self._last is None:
            header, _ = self._gif.getheader(image, None, {"loop": 0, "duration": 10 * cs})
            chunks = list(header) + list(self._gif.getdata(image, (0, 0), duration=10 * cs,
                                                           disposal=1))
        else:
            changed = pixels != self._last
            rows = np.flatnonzero(changed.any(axis=1))
            cols = np.flatnonzero(changed.any(axis=0))
            y0, y1, x0, x1 = rows[0], rows[-1] + 1, cols[0], cols[-1] + 1
            box = np.where(changed[y0:y1, x0:x1], pixels[y0:y1, x0:x1], TRANSPARENT).astype(np.uint8)
            Image, _, _ = require_pillow()
            delta = Image.frombytes("P", (int(x1 - x0), int(y1 - y0)), box.tobytes())
            delta.putpalette(_PALETTE_BYTES)
            chunks = self._gif.getdata(delta, (int(x0), int(y0)), duration=10 * cs, disposal=1,
                                       transparency=TRANSPARENT)
        for chunk in chunks:
            self.stream.write(chunk)
        self._last = pixels
        self.written += 1


class _Enough(Exception):
    """Raised inside the replay callback once ``max_frames`` frames are drawn."""


#: the largest image side in pixels: a frame's buffers (the painted image, the previous
#: frame, the changed-pixel mask and the encoder's copy) take about 8 bytes a pixel, so
#: 4096 keeps them near 128 MiB, where 10^6 would ask for terabytes
MIN_SIZE, MAX_SIZE = 64, 4096


def _check_size(size):
    if isinstance(size, bool) or not isinstance(size, int) or not MIN_SIZE <= size <= MAX_SIZE:
        raise ValueError(f"size must be an int in [{MIN_SIZE}, {MAX_SIZE}] (pixels a side; "
                         f"a frame takes about 8 bytes a pixel), got {size!r}")
    return size


def render_gif(replay, out_path, every=2, size=480, fps=30, max_frames=None):
    """Draw a replay as an animated GIF at ``out_path``; return a summary dict.

    ``replay``: a replay dict or the path of a replay file. Every ``every``-th game frame is
    drawn (and the last one); the GIF plays ``fps`` of those a second (30 with ``every=2``
    shows the game at 60 frames a second, about the original's pace) and holds the final
    frame a moment. ``max_frames`` stops after that many drawn frames. ``out_path`` is checked
    first (``engine.atomic.check_output_path(out_path, "gif")``: a missing directory, or an
    existing file that is not a GIF, such as the replay itself, is refused before anything is
    drawn); the file is written by ``engine.atomic.atomic_write`` (a temporary file beside it,
    moved into place at the end), so a crash or an interrupt never leaves a partial GIF there.
    """
    if isinstance(every, bool) or not isinstance(every, int) or every < 1:
        raise ValueError(f"every must be an int >= 1, got {every!r}")
    size = _check_size(size)
    if isinstance(fps, bool) or not isinstance(fps, (int, float)) or not 0 < fps <= 50:
        raise ValueError(f"fps must be a number in (0, 50] (GIF frame times are whole "
                         f"hundredths of a second and viewers slow faster ones), got {fps!r}")
    if max_frames is not None and (isinstance(max_frames, bool) or not isinstance(max_frames, int)
                                   or max_frames < 1):
        raise ValueError(f"max_frames must be None or an int >= 1, got {max_frames!r}")
    require_pillow()
    out_path = check_output_path(out_path, "gif")  # before any work: never over a replay
    from .replay import load, simulate

    if isinstance(replay, (str, bytes, os.PathLike)):
        replay = load(replay)
    names = tuple(replay.get("bots") or DEFAULT_NAMES)
    rounds = replay.get("rounds")
    effects = Effects()
    last = {"frame": 0}
    state = {}

    def draw(f):
        writer = state["writer"] = _GifWriter(f, fps)

        def on_frame(game):
            snap = game.snapshot(0)
            effects.update(snap)
            last["frame"] = snap["frame"]
            if snap["frame"] % every == 0 or snap["over"]:
                writer.add(render_frame(frame_snapshot(game), size, effects=effects, names=names,
                                        rounds=rounds))
                if max_frames is not None and writer.added >= max_frames:
                    raise _Enough

        try:
            simulate(replay, on_frame)
        except _Enough:
            pass
        writer.close()

    atomic_write(out_path, draw, "wb")  # never a partial GIF at out_path; mode 0o666 & ~umask
    writer = state["writer"]
    return {"path": out_path, "frames": writer.written, "drawn": writer.added,
            "game_frames": last["frame"], "size": size, "bytes": os.path.getsize(out_path)}


__all__ = ["Effects", "render_frame", "render_gif", "scene", "frame_snapshot", "paint_pil",
           "new_image", "palette_index", "require_pillow", "to_pixels", "footer_top",
           "hud_bottom", "PALETTE", "VIZ_HINT"]
