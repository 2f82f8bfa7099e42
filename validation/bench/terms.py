"""Section 4: the cost of the force terms declared (1, 2 and 4 terms on the same particles)."""
import statistics

import numpy as np

from .direct_sum import random_cluster
from .timing import time_per_step

NAME = "terms"
KEYS = ("terms",)
NEEDS = ()


def run(quick):
    return {"terms": bench_terms(repeats=3 if quick else 5)}


def bench_terms(n=128, repeats=5):
    from engine import Simulation, forces

    sets = {
        "1: gravity": lambda: [forces.NBodyGravity(softening=0.01)],
        "2: + drag": lambda: [forces.NBodyGravity(softening=0.01), forces.Drag(linear=0.01)],
        "4: + uniform gravity, Coulomb": lambda: [
            forces.NBodyGravity(softening=0.01), forces.Drag(linear=0.01),
            forces.UniformGravity(g=(0.0, -1.0, 0.0)), forces.Coulomb(k=0.1, softening=0.01)],
    }
    out = {}
    mass, pos, vel = random_cluster(n)
    charge = np.random.default_rng(2).choice([-1.0, 1.0], n)
    for name, make in sets.items():
        sim = Simulation(dim=3, integrator="leapfrog", dt=1e-4)
        sim.add_many(mass=mass, pos=pos, vel=vel, charge=charge)
        for term in make():
            sim.add_force(term)
        sim.step(1)
        out[name] = statistics.median(time_per_step(sim, budget=0.1) for _ in range(repeats))
    base = out["1: gravity"]
    return {"n": n, "seconds_per_step": out,
            "relative_to_gravity_alone": {k: v / base for k, v in out.items()}}


def text(r):
    lines = []
    t = r["terms"]
    lines.append(f"\n4. declared terms (N = {t['n']}, leapfrog)")
    for k, v in t["seconds_per_step"].items():
        lines.append(f"  {k:<34}{v * 1e6:>9.1f} us/step  ({t['relative_to_gravity_alone'][k]:.2f}x)")
    return lines


def markdown(r):
    out = []
    t = r["terms"]
    out += [f"## 4. Only the declared terms are paid for (N = {t['n']}, leapfrog)", "",
            "| declared terms | us/step | relative |", "|---|---|---|"]
    for k, v in t["seconds_per_step"].items():
        out.append(f"| {k} | {v * 1e6:.1f} | {t['relative_to_gravity_alone'][k]:.2f}x |")
    out.append("")
    return out


def targets(r):
    rows = []
    rel = list(r["terms"]["relative_to_gravity_alone"].values())
    rows.append(("step cost follows the declared terms",
                 ", ".join(f"{x:.2f}x" for x in rel) + " for 1, 2, 4 terms",
                 all(b >= a * 0.95 for a, b in zip(rel, rel[1:]))))
    return rows
