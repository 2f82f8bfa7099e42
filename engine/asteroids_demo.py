"""``python -m engine asteroids``: a belt of asteroids about a star that bounce and merge, to a
GIF; the contact API (``sim.collisions``, ``sim.contacts``) as a game would use it.

A star (a pinned particle for contacts, its pull a ``forces.PointMass``) and a belt of rocks on
crossing, slightly eccentric orbits. Rocks that meet slower than ``MERGE_BELOW`` stick together
(``Collisions(merge_below=...)``: the survivor grows to the summed area), faster ones bounce with
restitution 0.5; a rock that falls onto the star is absorbed by it (a pinned body absorbs what
hits it slowly, and is a wall of infinite mass to the rest). After each frame the drawing reads
``sim.contacts``: the rocks of that frame's bounces flash orange, its merges green. Leapfrog;
every contact is found along the rocks' paths and resolved at the moment they touch
(``engine.collisions``). The frames are drawn with Pillow (the ``[viz]`` extra) and written
atomically to a path checked before anything is computed.

    python -m engine asteroids --out asteroids.gif --rocks 300 --frames 150
"""
import math
import time

import numpy as np

from . import forces
from .atomic import OutputPathError, atomic_write, check_output_path
from .cloth_demo import positive_int, require_pillow
from .collisions import Collisions
from .simulation import Simulation

#: contacts slower than this merge; faster ones bounce (the belt's orbital speed is about 1)
MERGE_BELOW = 0.06
RESTITUTION = 0.5
STEP = 0.004
STAR_RADIUS = 0.08

BACKGROUND = (12, 14, 24)
STAR = (255, 214, 102)
ROCK = (170, 170, 182)
BOUNCE = (255, 140, 40)
MERGE = (90, 230, 120)
TEXT = (210, 214, 225)


def build_scene(rocks=300, seed=1):
    """The belt: the star (particle 0, pinned) and ``rocks`` rocks between radii 0.6 and 1.3
    with eccentricities up to 0.12 and random phases; returns the simulation."""
    rng = np.random.default_rng(seed)
    sim = Simulation(dim=2, integrator="leapfrog", dt=STEP, capacity=rocks + 1)
    sim.add(mass=1.0, pos=(0.0, 0.0), radius=STAR_RADIUS, pinned=True)
    a = rng.uniform(0.6, 1.3, rocks)
    e = rng.uniform(0.0, 0.12, rocks)
    anomaly = rng.uniform(0.0, 2.0 * math.pi, rocks)
    perihelion = rng.uniform(0.0, 2.0 * math.pi, rocks)
    # the position and velocity of each orbit at its true anomaly (mu = 1)
    p = a * (1.0 - e * e)
    r = p / (1.0 + e * np.cos(anomaly))
    angle = anomaly + perihelion
    pos = np.column_stack((r * np.cos(angle), r * np.sin(angle)))
    radial = np.sqrt(1.0 / p) * e * np.sin(anomaly)
    tangential = np.sqrt(1.0 / p) * (1.0 + e * np.cos(anomaly))
    vel = np.column_stack((radial * np.cos(angle) - tangential * np.sin(angle),
                           radial * np.sin(angle) + tangential * np.cos(angle)))
    size = 0.006 + 0.012 * rng.random(rocks) ** 2
    sim.add_many(mass=size ** 2, pos=pos, vel=vel, radius=size)
    sim.add_force(forces.PointMass(mu=1.0, particles=np.arange(1, rocks + 1)))
    sim.collisions = Collisions(resolve="bounce", restitution=RESTITUTION,
                                merge_below=MERGE_BELOW)
    return sim


def draw_frame(sim, flashes, size, label, Image, ImageDraw):
    """One RGB frame: the star, the rocks (those in this frame's contacts in their colour)."""
    img = Image.new("RGB", (size, size), BACKGROUND)
    draw = ImageDraw.Draw(img)
    scale = size / 3.0  # the view spans [-1.5, 1.5]
    centre = size / 2.0
    for i in np.flatnonzero(sim.active):
        x = centre + scale * sim.pos[i, 0]
        y = centre - scale * sim.pos[i, 1]
        r = max(1.0, scale * sim.radius[i])
        colour = STAR if i == 0 else flashes.get(int(i), ROCK)
        draw.ellipse([x - r, y - r, x + r, y + r], fill=colour)
    draw.text((10, 8), label, fill=TEXT)
    return img


def run(out, rocks=300, frames=150, steps_per_frame=25, size=480, seed=1, log=print):
    """Simulate and write the GIF to ``out``; return a summary dict (the contacts counted)."""
    out = check_output_path(out, "gif")
    Image, ImageDraw = require_pillow()
    sim = build_scene(rocks, seed)
    mass0 = sim.mass[sim.active].sum()
    counts = {"bounce": 0, "merge": 0}
    images = []
    start = time.perf_counter()
    for k in range(frames):
        flashes = {}
        if k:
            sim.step(steps_per_frame)
            for c in sim.contacts:
                counts[c.action] = counts.get(c.action, 0) + 1
                colour = MERGE if c.action == "merge" else BOUNCE
                flashes[c.i] = flashes[c.j] = colour
        label = (f"t = {sim.t:5.2f}   rocks {int(sim.active.sum()) - 1}   bounces "
                 f"{counts['bounce']}   merges {counts['merge']}")
        images.append(draw_frame(sim, flashes, size, label, Image, ImageDraw))
    palette = images[-1].quantize(colors=64, method=0)
    frames_p = [im.quantize(palette=palette, dither=0) for im in images]

    def write(f):
        frames_p[0].save(f, format="GIF", save_all=True, append_images=frames_p[1:],
                         duration=40, loop=0)

    atomic_write(out, write, "wb")
    seconds = time.perf_counter() - start
    log(f"wrote {out}: {frames} frames, t = {sim.t:.2f} in {sim.steps} steps ({seconds:.1f} s); "
        f"{counts['bounce']} bounces, {counts['merge']} merges, {int(sim.active.sum()) - 1} of "
        f"{rocks} rocks left; mass kept to "
        f"{abs(sim.mass[sim.active].sum() - mass0) / mass0:.1e}")
    return {"out": out, "frames": frames, "steps": sim.steps, "bounces": counts["bounce"],
            "merges": counts["merge"], "rocks_left": int(sim.active.sum()) - 1,
            "mass": float(sim.mass[sim.active].sum()), "mass0": float(mass0)}


def add_arguments(parser):
    parser.add_argument("--out", default="asteroids.gif",
                        help="the GIF to write (default asteroids.gif)")
    parser.add_argument("--rocks", type=positive_int, default=300, help="rocks (default 300)")
    parser.add_argument("--frames", type=positive_int, default=150,
                        help="frames (default 150)")
    parser.add_argument("--steps", type=positive_int, default=25,
                        help="leapfrog steps a frame (default 25)")
    parser.add_argument("--size", type=positive_int, default=480,
                        help="the square frame's side in pixels (default 480)")
    parser.add_argument("--seed", type=int, default=1)


def main(args, parser):
    """Run the demo from parsed ``args``; a bad path or a missing Pillow is reported through
    ``parser.error`` (exit status 2) before any work."""
    try:
        return run(args.out, rocks=args.rocks, frames=args.frames,
                   steps_per_frame=args.steps, size=args.size, seed=args.seed)
    except (OutputPathError, ImportError) as exc:
        parser.error(str(exc))


__all__ = ["run", "build_scene", "draw_frame", "add_arguments", "main"]
