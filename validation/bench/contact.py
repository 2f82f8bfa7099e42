"""The contact section of ``python -m validation bench``: collision detection and resolution
in a hard-sphere gas, the engine against REBOUND's tree collision search, side by side.

The scene: N equal spheres of radius 0.5 at a volume fraction of 0.1 in a periodic cube,
random positions, normal random velocities, no forces, leapfrog at dt = 0.02 (a sphere moves
about 3% of its radius a step). The engine: ``Collisions(resolve="bounce")`` (its uniform
grid). REBOUND: ``collision = "tree"``, ``collision_resolve = "hardsphere"``, the same box
with one ghost box a side (so pairs across the boundary are found), leapfrog, the same dt.
Both are timed over the same number of steps, one after the other, repeatedly; each ratio is
the median of per-repetition ratios. The contacts a step resolves are counted for both (a
check that they solve the same problem), and the engine's step without collisions is timed
too: what a scene that declares none pays.
"""
import math
import statistics
import sys

import numpy as np

from .timing import timed

NAME = "contact"
KEYS = ("contact",)
NEEDS = ("rebound",)

#: sphere radius, volume fraction, step, by the module doc
RADIUS, PACKING, DT = 0.5, 0.1, 0.02

SIZES = {"quick": (1000, 10_000), "full": (1000, 10_000, 100_000)}


def run(quick):
    return {"contact": measure(SIZES["quick" if quick else "full"], repeats=3,
                               progress=lambda text: print(text, file=sys.stderr))}


def scene(n, seed=1):
    """Positions, velocities and the side of the periodic cube of the module's gas."""
    rng = np.random.default_rng(seed)
    side = (n * (4 / 3 * math.pi * RADIUS ** 3) / PACKING) ** (1 / 3)
    pos = rng.uniform(-side / 2, side / 2, (n, 3))
    vel = rng.normal(size=(n, 3))
    return pos, vel, side


def engine_gas(n, collisions=True, seed=1):
    from engine import Collisions, Simulation

    pos, vel, side = scene(n, seed)
    sim = Simulation(dim=3, integrator="leapfrog", dt=DT, box=side, capacity=n)
    sim.add_many(mass=1.0, pos=pos, vel=vel, radius=RADIUS)
    if collisions:
        sim.collisions = Collisions(resolve="bounce")
    sim.step(2)  # compile / load, and the overlaps of the random start resolved
    return sim


def rebound_gas(n, seed=1):
    import rebound

    pos, vel, side = scene(n, seed)
    sim = rebound.Simulation()
    sim.root_size = side
    sim.N_root_x = sim.N_root_y = sim.N_root_z = 1
    sim.boundary = "periodic"
    sim.N_ghost_x = sim.N_ghost_y = sim.N_ghost_z = 1
    sim.gravity = "none"
    sim.integrator = "leapfrog"
    sim.dt = DT
    sim.collision = "tree"
    sim.collision_resolve = "hardsphere"
    for i in range(n):
        sim.add(m=1.0, r=RADIUS, x=pos[i, 0], y=pos[i, 1], z=pos[i, 2], vx=vel[i, 0],
                vy=vel[i, 1], vz=vel[i, 2])
    sim.steps(2)
    return sim


def measure(sizes, repeats=3, progress=None):
    """The section's figures at each N: per-step times of the engine with and without
    collisions and of REBOUND, the median ratio, contacts per step, and the fitted exponent of
    the engine's time against N."""
    rows = []
    for n in sizes:
        if progress:
            progress(f"contact: N = {n}")
        ours, theirs, bare = engine_gas(n), rebound_gas(n), engine_gas(n, collisions=False)
        steps = max(2, int(2e5 / n))
        t_ours, t_theirs, t_bare, ratios, contacts = [], [], [], [], 0
        log_before = theirs.collisions_log_n
        for _ in range(repeats):
            a = timed(lambda: ours.step(steps))
            contacts += len(ours.contacts)
            b = timed(lambda: theirs.steps(steps))
            t_ours.append(a / steps)
            t_theirs.append(b / steps)
            t_bare.append(timed(lambda: bare.step(steps)) / steps)
            ratios.append(b / a)
        rows.append({
            "n": n, "steps": steps * repeats,
            "engine_ms_per_step": 1e3 * statistics.median(t_ours),
            "rebound_ms_per_step": 1e3 * statistics.median(t_theirs),
            "speedup_vs_rebound": statistics.median(ratios),
            "engine_without_collisions_ms_per_step": 1e3 * statistics.median(t_bare),
            "engine_contacts_per_step": contacts / (steps * repeats),
            "rebound_contacts_per_step": (theirs.collisions_log_n - log_before)
            / (steps * repeats),
        })
    exponent = None
    if len(rows) > 1:
        exponent = float(np.polyfit(np.log([r["n"] for r in rows]),
                                    np.log([r["engine_ms_per_step"] for r in rows]), 1)[0])
    return {"rows": rows, "exponent": exponent, "radius": RADIUS, "packing": PACKING, "dt": DT}


def targets(r):
    """The contact targets against this run: (target, measured, met) rows."""
    c = r["contact"]
    rows = []
    big = [row for row in c["rows"] if row["n"] >= 10_000]
    if big:
        text = ", ".join(f"{row['speedup_vs_rebound']:.1f}x at N = {row['n']:.0e}" for row in big)
        rows.append(("contact, 3-D gas at volume fraction 0.1: at least as fast as REBOUND's tree "
                     "collision search (goal 3x)", text,
                     all(row["speedup_vs_rebound"] >= 1.0 for row in big)))
    if c["exponent"] is not None:
        first, last = c["rows"][0]["n"], c["rows"][-1]["n"]
        rows.append(("contact: time ~ N^a with a <= 1.15 (N log N)",
                     f"a = {c['exponent']:.2f} (N = {first:.0e} to {last:.0e})",
                     c["exponent"] <= 1.15))
    return rows


def format_contact(r):
    c = r["contact"]
    lines = ["\n12. Contact: a hard-sphere gas (volume fraction 0.1, periodic), engine against "
             "REBOUND's tree collision search",
             f"{'N':>8}{'engine ms/step':>16}{'REBOUND ms/step':>17}{'speed-up':>10}"
             f"{'no collisions ms':>18}{'contacts/step':>15}{'REBOUND':>9}"]
    for row in c["rows"]:
        lines.append(f"{row['n']:>8}{row['engine_ms_per_step']:>16.3f}"
                     f"{row['rebound_ms_per_step']:>17.3f}{row['speedup_vs_rebound']:>9.1f}x"
                     f"{row['engine_without_collisions_ms_per_step']:>18.3f}"
                     f"{row['engine_contacts_per_step']:>15.1f}"
                     f"{row['rebound_contacts_per_step']:>9.1f}")
    if c["exponent"] is not None:
        lines.append(f"engine time ~ N^{c['exponent']:.2f}")
    return "\n".join(lines)


def markdown_contact(r):
    c = r["contact"]
    out = ["## 12. Contact: collisions in a hard-sphere gas", "",
           __doc__.split("\n\n", 1)[1].replace("\n", " ").strip(), "",
           "| N | engine ms/step | REBOUND ms/step | speed-up | engine without collisions "
           "ms/step | contacts/step (engine) | contacts/step (REBOUND) |",
           "|---|---|---|---|---|---|---|"]
    for row in c["rows"]:
        out.append(f"| {row['n']} | {row['engine_ms_per_step']:.3f} | "
                   f"{row['rebound_ms_per_step']:.3f} | {row['speedup_vs_rebound']:.1f}x | "
                   f"{row['engine_without_collisions_ms_per_step']:.3f} | "
                   f"{row['engine_contacts_per_step']:.1f} | "
                   f"{row['rebound_contacts_per_step']:.1f} |")
    if c["exponent"] is not None:
        out += ["", f"Fitted engine time ~ N^a: a = {c['exponent']:.2f}."]
    return out + [""]


def text(r):
    return [format_contact(r)]


def markdown(r):
    return markdown_contact(r)
