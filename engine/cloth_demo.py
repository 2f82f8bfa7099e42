"""``python -m engine cloth``: a cloth and a rope hanging from pins, in the wind, to a GIF.

The lecture's mass-spring systems (ropes, cloth), its forces (gravity near a planet, wind
pressure on triangles, Hooke springs, attrition) and the step limit of a stiff network, in one
scene: a square cloth hangs in a vertical plane from its two pinned top corners and billows in
a gusting wind (``forces.Wind`` on ``forces.grid_triangles``); beside it a rope, pinned at
one end, is released horizontally and swings down beside it. The wind acts on the cloth's triangles
only, so the rope swings in still air.

The step is ``SAFETY`` x ``sim.stable_dt()`` (verlet), rounded down so that every frame of the
GIF is a whole number of steps: the cloth stretches as it falls onto its pins and the wind
pushes it, which makes the network slightly stiffer than at the start, where the step is
computed. The frames are drawn with Pillow (the optional ``[viz]`` extra) in a fixed
perspective, the cloth's triangles painted back to front and shaded by their facing to a
light, and the GIF is written atomically (``engine.atomic``) to a path checked before
anything is computed.

    python -m engine cloth --out cloth.gif --frames 90

``--tear`` makes the cloth's springs plastic and breakable (``Springs(yield_strain=0.1,
break_strain=0.3, flow_rate=3)``, ``engine.forces.spring_yield``) and the gale stronger: the
sail stretches and keeps its dents where the gusts pushed it past yield, and tears where they
pushed faster than it could flow; a torn triangle is not drawn.

    python -m engine cloth --tear --out sail.gif
"""
import argparse
import math
import time

import numpy as np

from . import forces
from .atomic import OutputPathError, atomic_write, check_output_path
from .simulation import Simulation

VIZ_HINT = "pip install -e '.[viz]'"
SAFETY = 0.5
G = 9.8

# looks
BACKGROUND = (236, 240, 245)
FLOOR = (205, 211, 220)
CLOTH = ((196, 58, 49), (238, 196, 72))  # the two colours of its stripes
ROPE = (60, 50, 44)
PIN = (30, 30, 30)
TEXT = (70, 70, 80)
LIGHT = np.array([0.45, -0.75, 0.5]) / np.linalg.norm([0.45, -0.75, 0.5])


def require_pillow():
    """``(Image, ImageDraw)`` from Pillow, or an ImportError saying how to get it."""
    try:
        from PIL import Image, ImageDraw
    except ImportError as exc:
        raise ImportError("the cloth demo draws with Pillow, part of the optional [viz] extra: "
                          f"{VIZ_HINT}") from exc
    return Image, ImageDraw


#: the torn sail's springs (``--tear``)
TEAR = {"yield_strain": 0.05, "break_strain": 0.2, "flow_rate": 3.0}


def build_scene(grid=16, rope_segments=20, wind=5.0, tear=False):
    """The simulation (verlet, 3-D, z up) with its cloth and rope; returns
    ``(sim, cloth_indices, rope_indices, wind_term)``. The step is not set yet. ``tear``:
    the cloth's springs yield and break (``TEAR``)."""
    sim = Simulation(dim=3, integrator="verlet", dt=1e-3)
    # a 1 m x 1 m cloth in the x-z plane, top edge at z = 0, bend springs for some body
    cloth, _ = forces.cloth(sim, corner=(0.0, 0.0, 0.0), edge_u=(1.0, 0.0, 0.0),
                            edge_v=(0.0, 0.0, -1.0), nu=grid, nv=grid, mass=2.5 / grid ** 2,
                            k=150.0, damping=0.02, bend=True, **(TEAR if tear else {}))
    sim.pin(int(cloth[0, 0]))
    sim.pin(int(cloth[-1, 0]))
    if tear:  # a sail laced to its spar along the whole top edge
        for i in cloth[:, 0]:
            sim.pin(int(i))
    # a rope beside it, pinned at one end and released horizontally, towards the viewer: it
    # swings down and across, clear of the cloth
    rope, _ = forces.rope(sim, start=(1.6, 0.0, 0.0), end=(2.05, -0.6, 0.0),
                          segments=rope_segments, mass=0.01, k=400.0, damping=0.08)
    sim.pin(int(rope[0]))
    sim.add_force(forces.UniformGravity(g=(0.0, 0.0, -G)))
    sim.add_force(forces.Drag(linear=0.004))
    gust = sim.add_force(forces.Wind(w=_wind(0.0, wind), triangles=forces.grid_triangles(cloth)))
    return sim, cloth, rope, gust


def _wind(t, strength):
    """The gusting wind pressure at time t: mostly along +y, through the cloth."""
    gust = 1.0 + 0.45 * math.sin(2.0 * math.pi * t / 1.9) + 0.25 * math.sin(2.0 * math.pi * t / 0.7)
    turn = 0.35 * math.sin(2.0 * math.pi * t / 3.1)
    return (strength * gust * turn, strength * gust, 0.0)


class Camera:
    """A fixed perspective view of the scene (z up): points to pixels and depths."""

    def __init__(self, width, height, target=(1.05, 0.15, -0.6), direction=(0.55, -1.0, 0.3),
                 distance=3.3, fov=40.0):
        self.width, self.height = width, height
        d = np.asarray(direction, dtype=float)
        self.forward = -d / np.linalg.norm(d)  # from the eye towards the target
        self.eye = np.asarray(target, dtype=float) - distance * self.forward
        right = np.cross(self.forward, (0.0, 0.0, 1.0))
        self.right = right / np.linalg.norm(right)
        self.up = np.cross(self.right, self.forward)
        self.focal = 0.5 * height / math.tan(math.radians(fov) / 2.0)

    def project(self, points):
        """``(x_pixels, y_pixels, depth)`` of points of shape (..., 3)."""
        rel = np.asarray(points) - self.eye
        depth = rel @ self.forward
        x = self.width / 2.0 + self.focal * (rel @ self.right) / depth
        y = self.height / 2.0 - self.focal * (rel @ self.up) / depth
        return x, y, depth


def cloth_springs(sim):
    """The cloth's springs: the scene's first ``Springs`` term (the rope's is the second)."""
    return next(f for f in sim.forces if isinstance(f, forces.Springs))


def intact(sim, tri):
    """Which triangles have all three edges' springs whole (a torn one is not drawn)."""
    springs = cloth_springs(sim)
    if not springs.broken.any():
        return np.ones(tri.shape[0], dtype=bool)
    broken = {(min(a, b), max(a, b)) for a, b in springs.pairs[springs.broken].tolist()}
    return np.array([not any((min(a, b), max(a, b)) in broken
                             for a, b in ((t[0], t[1]), (t[1], t[2]), (t[0], t[2])))
                     for t in tri.tolist()])


def draw_frame(sim, cloth, rope, camera, label, Image, ImageDraw):
    """One RGB frame of the scene as it is now."""
    img = Image.new("RGB", (camera.width, camera.height), BACKGROUND)
    draw = ImageDraw.Draw(img)
    floor = np.array([(-0.4, -0.7, -1.45), (2.5, -0.7, -1.45), (2.5, 1.0, -1.45), (-0.4, 1.0, -1.45)])
    fx, fy, _ = camera.project(floor)
    draw.polygon(list(zip(fx, fy)), fill=FLOOR)
    pos = sim.pos
    x, y, depth = camera.project(pos)
    # the cloth: two triangles per cell, farthest first, shaded by |n . light|
    tri = forces.grid_triangles(cloth)
    p0, p1, p2 = pos[tri[:, 0]], pos[tri[:, 1]], pos[tri[:, 2]]
    normal = np.cross(p1 - p0, p2 - p0)
    normal /= np.maximum(np.linalg.norm(normal, axis=1), 1e-12)[:, None]
    shade = 0.45 + 0.55 * np.abs(normal @ LIGHT)
    cells = cloth.shape[0] - 1
    stripe = (np.arange(tri.shape[0]) % (cells * cells)) // cells % 2  # stripes along u
    # the rope's segments are painted in the same back-to-front order as the triangles
    segments = np.column_stack((rope[:-1], rope[1:]))
    far = np.concatenate((depth[tri].mean(axis=1), depth[segments].mean(axis=1)))
    whole = intact(sim, tri)
    for item in np.argsort(-far, kind="stable"):
        if item < tri.shape[0]:
            if not whole[item]:
                continue
            colour = tuple(int(c * shade[item]) for c in CLOTH[stripe[item]])
            corners = [(x[v], y[v]) for v in tri[item]]
            draw.polygon(corners, fill=colour, outline=colour)
        else:
            a, b = segments[item - tri.shape[0]]
            draw.line([(x[a], y[a]), (x[b], y[b])], fill=ROPE, width=3)
    for i in np.flatnonzero(sim.pinned):  # the pins on top
        draw.ellipse([x[i] - 4, y[i] - 4, x[i] + 4, y[i] + 4], fill=PIN)
    draw.text((10, 8), label, fill=TEXT)
    return img


def run(out, frames=90, fps=25, width=480, height=360, grid=16, wind=5.0, safety=SAFETY,
        log=print, tear=False):
    """Simulate and write the GIF to ``out``; return a summary dict.

    The output path is checked before anything else, then Pillow is imported: a bad path or
    a missing Pillow fails before any work."""
    out = check_output_path(out, "gif")
    Image, ImageDraw = require_pillow()
    sim, cloth, rope, gust = build_scene(grid=grid, wind=wind, tear=tear)
    stable = sim.stable_dt()
    frame_time = 1.0 / fps
    per_frame = max(1, math.ceil(frame_time / (safety * stable)))
    sim.dt = frame_time / per_frame
    log(f"cloth {grid} x {grid} and a rope of {len(rope) - 1} springs, verlet: stable_dt "
        f"{stable * 1e3:.3f} ms, step {sim.dt * 1e3:.3f} ms ({sim.dt / stable:.2f} of it), "
        f"{per_frame} steps a frame")
    camera = Camera(width, height)
    images = []
    start = time.perf_counter()
    for k in range(frames):
        if k:
            gust.w = _wind(sim.t, wind)
            sim.step(per_frame)
        label = f"t = {sim.t:4.2f} s   dt = {sim.dt * 1e3:.2f} ms = {sim.dt / stable:.2f} stable_dt"
        images.append(draw_frame(sim, cloth, rope, camera, label, Image, ImageDraw))
    palette = images[0].quantize(colors=128, method=0)  # one palette: no flicker between frames
    frames_p = [im.quantize(palette=palette, dither=0) for im in images]

    def write(f):
        frames_p[0].save(f, format="GIF", save_all=True, append_images=frames_p[1:],
                         duration=int(round(1000 * frame_time)), loop=0)

    atomic_write(out, write, "wb")
    seconds = time.perf_counter() - start
    broken = int(cloth_springs(sim).broken.sum())
    log(f"wrote {out}: {frames} frames, {sim.t:.2f} s simulated in {sim.steps} steps "
        f"({seconds:.1f} s)" + (f"; {broken} springs broke, {sim.energy_ledger:.3g} J taken by "
                                "yielding and breaking" if tear else ""))
    return {"out": out, "frames": frames, "steps": sim.steps, "t": sim.t, "dt": sim.dt,
            "stable_dt": stable, "broken": broken, "energy_ledger": sim.energy_ledger}


def positive_int(text):
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be an int >= 1, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be an int >= 1, got {text!r}")
    return value


def _fraction(text):
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number in (0, 1], got {text!r}") from None
    if not 0.0 < value <= 1.0:
        raise argparse.ArgumentTypeError(f"must be a number in (0, 1], got {text!r}")
    return value


def _nonnegative(text):
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number >= 0, got {text!r}") from None
    if not (math.isfinite(value) and value >= 0.0):
        raise argparse.ArgumentTypeError(f"must be a finite number >= 0, got {text!r}")
    return value


def add_arguments(parser):
    parser.add_argument("--out", default="cloth.gif", help="the GIF to write (default cloth.gif)")
    parser.add_argument("--frames", type=positive_int, default=90, help="frames (default 90)")
    parser.add_argument("--fps", type=positive_int, default=25,
                        help="frames per simulated second, and the GIF's speed (default 25)")
    parser.add_argument("--width", type=positive_int, default=480)
    parser.add_argument("--height", type=positive_int, default=360)
    parser.add_argument("--grid", type=positive_int, default=16,
                        help="particles along each side of the cloth (default 16)")
    parser.add_argument("--wind", type=_nonnegative, default=None,
                        help="mean wind pressure (default 5; 46, a gale, with --tear)")
    parser.add_argument("--tear", action="store_true",
                        help="springs that yield and break, in a gale: the sail dents and tears")
    parser.add_argument("--safety", type=_fraction, default=SAFETY,
                        help=f"the step as a fraction of sim.stable_dt() (default {SAFETY})")


def main(args, parser):
    """Run the demo from parsed ``args``; bad paths, a missing Pillow and a grid below 2 are
    reported through ``parser.error`` (exit status 2) before any work."""
    if args.grid < 2:
        parser.error(f"--grid must be >= 2, got {args.grid}")
    if args.fps > 50:
        parser.error(f"--fps must be at most 50 (GIF frame times are whole hundredths of a "
                     f"second), got {args.fps}")
    try:
        wind = args.wind if args.wind is not None else (46.0 if args.tear else 5.0)
        return run(args.out, frames=args.frames, fps=args.fps, width=args.width,
                   height=args.height, grid=args.grid, wind=wind, safety=args.safety,
                   tear=args.tear)
    except (OutputPathError, ImportError) as exc:
        parser.error(str(exc))


__all__ = ["run", "build_scene", "draw_frame", "Camera", "add_arguments", "main", "intact",
           "cloth_springs", "TEAR"]
