"""Painting a scene (``spacewar.view.scene``) with Pillow: a fixed palette, ``paint_pil``, and
``render_frame`` (one frame to an image). Pillow is the optional ``[viz]`` extra, imported
only when something is painted."""
from spacewar.view.look import (BLACK, CHARGE_COLOURS, DIM_TEXT, FADES, FIRE, FLAME_COLOURS, SKY,
                   SHIP_COLOURS, STAR_CORE, STAR_RAYS, TEXT, TORPEDO_COLOURS, VIZ_HINT)
from spacewar.view.scene import fade, scene


def require_pillow():
    """``(Image, ImageDraw, ImageFont)`` from Pillow, or an ImportError saying how to get it."""
    try:
        from PIL import Image, ImageDraw, ImageFont
    except ImportError as exc:
        raise ImportError("drawing Spacewar! needs Pillow, part of the optional [viz] extra: "
                          f"{VIZ_HINT}") from exc
    return Image, ImageDraw, ImageFont


#: the largest image side in pixels: a frame's buffers (the painted image, the previous
#: frame, the changed-pixel mask and the encoder's copy) take about 8 bytes a pixel, so
#: 4096 keeps them near 128 MiB, where 10^6 would ask for terabytes
MIN_SIZE, MAX_SIZE = 64, 4096


def check_size(size):
    """``size`` if it is an image side this module can paint, else a ValueError naming it."""
    if isinstance(size, bool) or not isinstance(size, int) or not MIN_SIZE <= size <= MAX_SIZE:
        raise ValueError(f"size must be an int in [{MIN_SIZE}, {MAX_SIZE}] (pixels a side; "
                         f"a frame takes about 8 bytes a pixel), got {size!r}")
    return size


# -- Pillow backend -----------------------------------------------------------------------
def _build_palette():
    colours = [BLACK]
    ramps = list(SHIP_COLOURS) + list(TORPEDO_COLOURS)
    for rgb in ramps:
        colours.extend(fade(rgb, f) for f in FADES)
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
PALETTE_BYTES = bytes(c for rgb in PALETTE for c in rgb)
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
    image.putpalette(PALETTE_BYTES)
    return image


def render_frame(snapshot, size=480, effects=None, names=None, rounds=None, footer=(), banner=None):
    """One snapshot (``frame_snapshot(game, m)``, or ``Game.snapshot(m)`` without the gauges)
    as a ``size`` x ``size`` Pillow image in 'P' mode (a fixed 64-colour palette;
    ``.convert("RGB")`` for other uses). The other arguments are those of ``scene``."""
    size = check_size(size)
    image = new_image(size)
    return paint_pil(image, scene(snapshot, size, effects=effects, names=names, rounds=rounds,
                                  footer=footer, banner=banner))
