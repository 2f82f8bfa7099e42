"""``python -m engine galaxies``: two disk galaxies collide, drawn to an animated GIF.

Two equal disk galaxies (``engine.initial_conditions.galaxy_pair``: an exponential disk and a
Plummer bulge each, mass 1/2, disk scale length 1/2, cut at radius 3; G = 1) start 8 apart
on a nearly parabolic orbit (eccentricity 0.95) of pericentre 2, the first prograde, the
second tilted by 60 degrees: the kind of encounter Toomre & Toomre (1972, ApJ 178, 623)
showed to draw out long tidal tails and a bridge. As point masses the pair reaches its
pericentre at t = 14.5; the disks turn once in 2 pi R / v_c = 11 at R = 1, so by t = 40
the tails have had two turns to grow.

The disks are given a velocity dispersion of 0.3 v_c per component (``galaxy_pair``'s
``dispersion``), not its cold default 0.05: without a dark halo a disk that cold has Toomre's
(1964, ApJ 139, 1217) Q = sigma_R kappa / (3.36 G Sigma) of about 0.2 at R = 1 and breaks into
clumps within a turn; 0.3 v_c makes Q 1.0 at R = 0.5, 1.1 at R = 1 and 1.6 at R = 1.5 (in
the spherical approximation of v_c that ``disk_galaxy`` uses), and the disks stay smooth
(they grow bars, as halo-less disks do: Ostriker & Peebles 1973, ApJ 186, 467) until the
encounter.

Gravity is the tree's fast multipole walk (``forces.NBodyGravity(method="fmm")``) with a Plummer
softening of 0.05 (twice the disks' sech^2 scale height); the integrator is leapfrog.
The step, 0.05, is 1/15 of the period of the densest orbits, at the centre of a softened
bulge (a Plummer sphere of mass 0.1 and scale 0.1 has the central frequency
sqrt(G M / (b^2 + eps^2)^(3/2)) = 8.5, period 0.74). Measured with 4000 bodies to t = 20,
the energy then stays within 2.3e-4 of its start, and within 2.0e-4 with half the step (the
tree's force error sets that floor); a step of 0.1 drifts 4.6e-3. The default 100 frames of 8 steps
reach t = 39.6: the approach, the passage, the tails drawn out and spreading.

Each frame projects the bodies on the sky of an orthographic camera (face-on to the orbit's
x-y plane by default, or tilted about the x axis), counts them per pixel with
``numpy.bincount``, one histogram per galaxy, and maps the counts to brightness by
log(1 + c) / log(1 + c_sat), where c_sat is the count a pixel would hold at the surface
density of a disk's centre (a fraction 0.4 / (2 pi h^2) = 0.25 of the bodies per unit area):
disk centres and bulges saturate, the faint tails stay visible. The two galaxies' colours add.
Frames are drawn with Pillow (the optional ``[viz]`` extra) and written atomically
(``engine.atomic``) to a path checked before anything is computed; an output path ending in
``.png`` receives the last frame only, as a still image.

    python -m engine galaxies --out galaxies.gif              # 2 x 10^5 bodies: many minutes
    python -m engine galaxies --bodies 20000 --out small.gif  # a couple of minutes
"""
import argparse
import math
import os
import time

import numpy as np
from tqdm import tqdm

from . import forces
from . import initial_conditions as ic
from ._validate import finite_float, int_in_range, positive_float, step_count
from .atomic import OutputPathError, atomic_write, check_output_path
from .forces.tree_terms import check_theta
from .simulation import Simulation

VIZ_HINT = "pip install -e '.[viz]'"

# the scene
BODIES = 200_000
FRAMES = 100
STEPS_PER_FRAME = 8
DT = 0.05
SOFTENING = 0.05
THETA = 0.6
SEED = 0
DISPERSION = 0.3
# the picture
SIZE = 480
FPS = 20
VIEW = 9.0  # half the width of the picture, in code lengths
#: bodies per unit area (a fraction of all bodies) at which a pixel's brightness saturates:
#: the centre of one disk, 0.4 of the bodies with Sigma(0) = M_d / (2 pi h^2), h = 0.5
SATURATION_DENSITY = 0.4 / (2.0 * math.pi * 0.25)
BACKGROUND = (4, 5, 12)
COLOURS = ((255, 164, 72), (96, 168, 255))  # the first galaxy warm, the second cool
TEXT = (220, 220, 220)
PALETTE_LEVELS = 15  # brightness levels per galaxy in the GIF's shared palette (15 x 15 + text)


def require_pillow():
    """``(Image, ImageDraw)`` from Pillow, or an ImportError saying how to get it."""
    try:
        from PIL import Image, ImageDraw
    except ImportError as exc:
        raise ImportError("the galaxies demo draws with Pillow, part of the optional [viz] "
                          f"extra: {VIZ_HINT}") from exc
    return Image, ImageDraw


def build_scene(bodies=BODIES, seed=SEED, dt=DT, softening=SOFTENING, theta=THETA,
                dispersion=DISPERSION):
    """The 3-D leapfrog simulation of the two galaxies with tree gravity; returns
    ``(sim, first)``: the first galaxy's bodies are indices ``[0, first)``, the second's the
    rest."""
    pair = ic.galaxy_pair(bodies, dim=3, seed=seed, dispersion=dispersion)
    sim = Simulation(dim=3, integrator="leapfrog", dt=dt, capacity=bodies)
    ic.add_to(sim, pair)
    sim.add_force(forces.NBodyGravity(softening=softening, method="fmm", theta=theta))
    return sim, bodies // 2


def project(pos, tilt=0.0):
    """Sky coordinates ``(x, y)`` of positions (n, 3) seen by an orthographic camera looking
    down the z axis, turned by ``tilt`` radians about the x axis (0: face-on to x-y; pi/2: the
    x-z plane, edge-on)."""
    pos = np.asarray(pos, dtype=float)
    if tilt == 0.0 or pos.shape[1] == 2:
        return pos[:, 0], pos[:, 1]
    return pos[:, 0], math.cos(tilt) * pos[:, 1] + math.sin(tilt) * pos[:, 2]


def pixel_counts(x, y, first, width, height, half_width):
    """Bodies per pixel, one (height, width) int histogram per galaxy: shape (2, height, width).

    The picture spans [-half_width, half_width] in x and half_width * height / width either
    side of 0 in y (square pixels), y up; row 0 is the top. Bodies outside are dropped. Bodies
    ``[0, first)`` count in the first histogram, the rest in the second."""
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    pixel = 2.0 * half_width / width
    col = np.floor((x + half_width) / pixel)
    row = np.floor((0.5 * height * pixel - y) / pixel)
    inside = (col >= 0) & (col < width) & (row >= 0) & (row < height)
    flat = (row * width + col)[inside].astype(np.int64)
    galaxy = (np.arange(x.shape[0]) >= first)[inside].astype(np.int64)
    counts = np.bincount(galaxy * (width * height) + flat, minlength=2 * width * height)
    return counts.reshape(2, height, width)


def saturation_count(n, width, half_width):
    """The count at which a pixel is fully bright: ``SATURATION_DENSITY`` n bodies per unit
    area times a pixel's area, at least 1."""
    pixel = 2.0 * half_width / width
    return max(1.0, SATURATION_DENSITY * n * pixel * pixel)


def brightness(counts, saturation):
    """log(1 + c) / log(1 + saturation), clipped to [0, 1]: 0 for an empty pixel, 1 from the
    saturation count on."""
    return np.minimum(np.log1p(counts) / math.log1p(saturation), 1.0)


def colourise(level):
    """RGB (height, width, 3) uint8 from the brightness levels (2, height, width): the
    background plus each galaxy's colour times its level, added and clipped."""
    rgb = np.asarray(BACKGROUND, dtype=float) + np.tensordot(level, np.asarray(COLOURS, float),
                                                             axes=(0, 0))
    return np.clip(np.rint(rgb), 0, 255).astype(np.uint8)


def draw_frame(pos, first, width, height, half_width, label, Image, ImageDraw, tilt=0.0):
    """One RGB frame: the bodies at ``pos`` (n, 3) as log-scaled densities, galaxy by colour,
    with ``label`` written at the top left."""
    x, y = project(pos, tilt)
    counts = pixel_counts(x, y, first, width, height, half_width)
    level = brightness(counts, saturation_count(len(x), width, half_width))
    img = Image.fromarray(colourise(level), "RGB")
    ImageDraw.Draw(img).text((8, 6), label, fill=TEXT)
    return img


def palette_image(Image):
    """A palette ("P") image holding the colours frames are made of: each galaxy's colour at
    ``PALETTE_LEVELS`` levels, every sum of the two, and the text. One palette for every
    frame: no flicker between frames and no per-frame colour search."""
    steps = np.linspace(0.0, 1.0, PALETTE_LEVELS)
    grid = np.stack(np.meshgrid(steps, steps, indexing="ij")).reshape(2, -1, 1)
    colours = colourise(grid).reshape(-1, 3)
    colours = np.vstack((colours, np.asarray(TEXT, dtype=np.uint8)[None, :]))
    flat = np.zeros(768, dtype=np.uint8)
    flat[:colours.size] = colours.ravel()
    pal = Image.new("P", (1, 1))
    pal.putpalette(flat.tolist())
    return pal


def label(t, n):
    return f"t = {t:5.1f}   N = {n}"


def _measure_step(sim):
    """Seconds one force evaluation takes (the cost of a leapfrog step), warm: the first call
    may compile. Nothing advances."""
    sim.accelerations()
    start = time.perf_counter()
    sim.accelerations()
    return time.perf_counter() - start


def _duration(seconds):
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"


def _s(count):
    return "" if count == 1 else "s"


def _kind(out):
    """"png" for a still of the last frame (a path ending in .png), else "gif"."""
    return "png" if os.fspath(out).lower().endswith(".png") else "gif"


def _checked(bodies, frames, steps_per_frame, dt, softening, theta, seed, width, height, fps,
             view, tilt):
    """The arguments of :func:`run`, checked (ValueError/TypeError naming the one that is
    wrong), tilt in radians."""
    bodies = int_in_range("bodies", bodies, 4, 2 ** 31)
    if bodies % 2:
        raise ValueError(f"bodies must be even (two galaxies of bodies/2), got {bodies!r}")
    tilt = finite_float("tilt", tilt)
    if abs(tilt) > 90.0:
        raise ValueError(f"tilt must be in [-90, 90] degrees, got {tilt!r}")
    return dict(bodies=bodies, frames=int_in_range("frames", frames, 1, 10 ** 6),
                steps_per_frame=step_count("steps_per_frame", steps_per_frame, 1),
                dt=positive_float("dt", dt), softening=positive_float("softening", softening),
                theta=check_theta("theta", theta), seed=int_in_range("seed", seed, 0, 2 ** 63),
                width=int_in_range("width", width, 16, 8192),
                height=int_in_range("height", height, 16, 8192),
                fps=int_in_range("fps", fps, 1, 50), view=positive_float("view", view),
                tilt=math.radians(tilt))


def run(out, bodies=BODIES, frames=FRAMES, steps_per_frame=STEPS_PER_FRAME, dt=DT,
        softening=SOFTENING, theta=THETA, seed=SEED, width=SIZE, height=SIZE, fps=FPS,
        view=VIEW, tilt=0.0, log=print, progress=True):
    """Simulate and write ``out`` (an animated GIF, or the last frame if it ends in .png);
    return a summary dict. ``tilt`` is the camera's, in degrees; ``fps`` at most 50 (GIF
    frame times are whole hundredths of a second).

    The arguments and the output path are checked before anything else, then Pillow is
    imported: a bad value, a bad path or a missing Pillow fails before any work."""
    a = _checked(bodies, frames, steps_per_frame, dt, softening, theta, seed, width, height,
                 fps, view, tilt)
    bodies, frames, steps_per_frame, dt = a["bodies"], a["frames"], a["steps_per_frame"], a["dt"]
    width, height, view, tilt = a["width"], a["height"], a["view"], a["tilt"]
    kind = _kind(out)
    out = check_output_path(out, kind)
    Image, ImageDraw = require_pillow()

    sim, first = build_scene(bodies, a["seed"], dt, a["softening"], a["theta"])
    steps = (frames - 1) * steps_per_frame
    log(f"two disk galaxies of {first} bodies each, leapfrog dt = {dt:g}, tree theta = "
        f"{a['theta']:g}, softening {a['softening']:g}: {frames} frame{_s(frames)} of "
        f"{steps_per_frame} step{_s(steps_per_frame)}, {steps} step{_s(steps)} to "
        f"t = {steps * dt:g}")
    if steps:
        per_step = _measure_step(sim)
        log(f"a step takes about {per_step:.3g} s here: estimated {_duration(steps * per_step)} "
            "in all (the bar's estimate follows the run)")
    pal = palette_image(Image)
    images = []  # the GIF's frames as palette images (a quarter of the memory of RGB)
    start = time.perf_counter()
    with tqdm(total=frames, desc="galaxies", unit="frame", disable=not progress) as bar:
        for k in range(frames):
            if k:
                sim.step(steps_per_frame)
            if kind == "gif" or k == frames - 1:
                img = draw_frame(sim.pos, first, width, height, view, label(sim.t, bodies),
                                 Image, ImageDraw, tilt)
                images.append(img.quantize(palette=pal, dither=0) if kind == "gif" else img)
            bar.update(1)
    if kind == "gif":
        def write(f):
            images[0].save(f, format="GIF", save_all=True, append_images=images[1:],
                           duration=int(round(1000 / a["fps"])), loop=0)
    else:
        def write(f):
            images[-1].save(f, format="PNG", optimize=True)

    atomic_write(out, write, "wb")
    seconds = time.perf_counter() - start
    log(f"wrote {out}: {len(images)} frame{_s(len(images))}, t = {sim.t:g} "
        f"in {sim.steps} steps ({seconds:.1f} s)")
    return {"out": out, "frames": len(images), "steps": sim.steps, "t": sim.t, "dt": dt,
            "bodies": bodies, "seconds": seconds}


# ---------------------------------------------------------------- command line

def _int_at_least(minimum, even=False):
    what = f"an {'even ' if even else ''}int >= {minimum}"

    def parse(text):
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be {what}, got {text!r}") from None
        if value < minimum or (even and value % 2):
            raise argparse.ArgumentTypeError(f"must be {what}, got {text!r}")
        return value
    return parse


def _float_in(low, high, low_open=True, high_open=False):
    what = f"a number in {'(' if low_open else '['}{low:g}, " \
           f"{'inf' if high == math.inf else f'{high:g}'}{')' if high_open else ']'}"

    def parse(text):
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be {what}, got {text!r}") from None
        ok = (math.isfinite(value) and (value > low if low_open else value >= low)
              and (value < high if high_open else value <= high))
        if not ok:
            raise argparse.ArgumentTypeError(f"must be {what}, got {text!r}")
        return value
    return parse


def add_arguments(parser):
    parser.add_argument("--out", default="galaxies.gif",
                        help="the GIF to write (default galaxies.gif); a path ending in .png "
                             "gets the last frame only")
    parser.add_argument("--bodies", type=_int_at_least(4, even=True), default=BODIES,
                        help=f"bodies in all, half in each galaxy (default {BODIES})")
    parser.add_argument("--frames", type=_int_at_least(1), default=FRAMES,
                        help=f"frames (default {FRAMES})")
    parser.add_argument("--steps-per-frame", type=_int_at_least(1), default=STEPS_PER_FRAME,
                        help=f"leapfrog steps between frames (default {STEPS_PER_FRAME})")
    parser.add_argument("--dt", type=_float_in(0.0, math.inf, high_open=True), default=DT,
                        help=f"the step (default {DT}; G = 1)")
    parser.add_argument("--theta", type=_float_in(0.0, 2.0, low_open=False, high_open=True),
                        default=THETA, help=f"the tree's opening angle (default {THETA})")
    parser.add_argument("--softening", type=_float_in(0.0, math.inf, high_open=True),
                        default=SOFTENING, help=f"Plummer softening length (default {SOFTENING})")
    parser.add_argument("--seed", type=_int_at_least(0), default=SEED,
                        help=f"the initial conditions' seed (default {SEED})")
    parser.add_argument("--width", type=_int_at_least(16), default=SIZE)
    parser.add_argument("--height", type=_int_at_least(16), default=SIZE)
    parser.add_argument("--fps", type=_int_at_least(1), default=FPS,
                        help=f"the GIF's frames per second (default {FPS})")
    parser.add_argument("--view", type=_float_in(0.0, math.inf, high_open=True), default=VIEW,
                        help=f"half the picture's width, in code lengths (default {VIEW})")
    parser.add_argument("--tilt", type=_float_in(-90.0, 90.0, low_open=False), default=0.0,
                        help="the camera's tilt about the x axis, degrees (default 0: face-on "
                             "to the orbit)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")


def main(args, parser):
    """Run the demo from parsed ``args``; bad paths and a missing Pillow are reported through
    ``parser.error`` (exit status 2) before any work."""
    if args.fps > 50:
        parser.error(f"--fps must be at most 50 (GIF frame times are whole hundredths of a "
                     f"second), got {args.fps}")
    if args.frames > 10 ** 6:
        parser.error(f"--frames must be at most 10**6, got {args.frames}")
    if args.width > 8192 or args.height > 8192:
        parser.error(f"--width and --height must be at most 8192, got {args.width} x "
                     f"{args.height}")
    try:
        return run(args.out, bodies=args.bodies, frames=args.frames,
                   steps_per_frame=args.steps_per_frame, dt=args.dt, softening=args.softening,
                   theta=args.theta, seed=args.seed, width=args.width, height=args.height,
                   fps=args.fps, view=args.view, tilt=args.tilt, progress=not args.no_progress)
    except (OutputPathError, ImportError) as exc:
        parser.error(str(exc))


__all__ = ["run", "build_scene", "draw_frame", "pixel_counts", "brightness", "colourise",
           "project", "saturation_count", "add_arguments", "main"]
