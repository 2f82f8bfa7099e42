"""A frame of Spacewar! as backend-neutral primitives (``scene``): dots, rings, outlined and
filled polygons, lines and text in pixel coordinates, from the plain data of one frame
(``frame_snapshot``, ``Game.snapshot``). ``spacewar.view.paint_pil`` paints them with Pillow (the
GIF), ``spacewar.view.window`` with pygame (the window); ``spacewar.render`` documents what is
drawn."""
import math
import random
from itertools import product

from engine import space

from spacewar.view.look import (CHARGE_COLOURS, DEFAULT_NAMES, DIM_TEXT, EXHAUST, EXPLOSION_FRAMES, FADES, FIRE,
                   FLAME_COLOURS, HYPERSPACE_FLASH_FRAMES, MIN_SHIP_PIXELS, MIN_TORPEDO_RADIUS,
                   SHAPES, SHIP_COLOURS, SHIP_LENGTH, SKY, STAR_CORE, STAR_RAYS, TEXT,
                   TORPEDO_BURST_FRAMES, TORPEDO_COLOURS, TORPEDO_RADIUS_PER_PIXEL)

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


def fade(rgb, level):
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
    from spacewar.game import core

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


def starfield_primitives(size):
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
        colour = fade(TORPEDO_COLOURS[who], FADES[min(3, int(t * 4))])
        r = (2.0 + 6.0 * t) * size / 480.0
        for ix, iy in _images(x, y, 0.01):
            px, py = to_pixels(ix, iy, size)
            for k in range(6):
                a = k * math.pi / 3.0 + 0.5
                prims.append(("dot", px + r * math.cos(a), py + r * math.sin(a), 0.5, colour))
        return prims
    colour = fade(SHIP_COLOURS[who], FADES[min(3, int(t * 4))])
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
                           (outer, bar_top + bar_height)], fade(colour, FADES[2]), 1))
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
        prims.extend(starfield_primitives(size))
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
