"""Section 3: scaling of the time per step with N (direct sum) and with N_test (test particles
around four massive bodies), with fitted log-log slopes."""
import math

import numpy as np

from .direct_sum import engine_nbody
from .timing import time_per_step

NAME = "scaling"
KEYS = ("scaling",)
NEEDS = ()


def run(quick):
    return {"scaling": bench_scaling(2048 if quick else 16384)}


def bench_scaling(max_n):
    from engine import Simulation, forces

    sizes = [2 ** k for k in range(1, int(math.log2(max_n)) + 1)]
    direct, tests = [], []
    for n in sizes:
        direct.append(time_per_step(engine_nbody(n)))
        rng = np.random.default_rng(n)
        sim = Simulation(dim=3, integrator="leapfrog", dt=1e-3, capacity=n + 4)
        sim.add_many(mass=1.0, pos=rng.normal(size=(4, 3)) * 3)
        sim.add_many(mass=0.0, pos=rng.normal(size=(n, 3)) * 10, test=True)
        sim.add_force(forces.NBodyGravity(softening=0.01))
        sim.step(1)
        tests.append(time_per_step(sim))

    def slope(ns, ts, smallest):
        keep = [i for i, n in enumerate(ns) if n >= smallest]
        return float(np.polyfit(np.log(np.array(ns)[keep]), np.log(np.array(ts)[keep]), 1)[0])

    return {"n": sizes, "direct_seconds_per_step": direct, "test_seconds_per_step": tests,
            "direct_slope_large_n": slope(sizes, direct, 1024),
            "test_particle_slope_large_n": slope(sizes, tests, 1024)}


def text(r):
    lines = []
    s = r["scaling"]
    lines.append("\n3. scaling (seconds per leapfrog step)")
    lines.append(f"{'N':>7}{'direct':>12}{'N_test':>12}")
    for n, a, b in zip(s["n"], s["direct_seconds_per_step"], s["test_seconds_per_step"]):
        lines.append(f"{n:>7}{a:>12.2e}{b:>12.2e}")
    lines.append(f"fitted slopes (N >= 1024): direct {s['direct_slope_large_n']:.2f}, "
                 f"test particles {s['test_particle_slope_large_n']:.2f}")
    return lines


def markdown(r):
    out = []
    s = r["scaling"]
    out += ["## 3. Scaling", "", "| N | direct sum s/step | N test particles around 4 bodies s/step |",
            "|---|---|---|"]
    for n, a, b in zip(s["n"], s["direct_seconds_per_step"], s["test_seconds_per_step"]):
        out.append(f"| {n} | {a:.2e} | {b:.2e} |")
    out += ["", f"Fitted log-log slopes for N >= 1024: direct sum {s['direct_slope_large_n']:.2f}, "
                f"test particles {s['test_particle_slope_large_n']:.2f}.", ""]
    return out


def targets(r):
    rows = []
    s = r["scaling"]
    rows.append(("scaling slope about 2 (direct) and about 1 (test particles)",
                 f"{s['direct_slope_large_n']:.2f} and {s['test_particle_slope_large_n']:.2f}",
                 abs(s["direct_slope_large_n"] - 2) < 0.25
                 and abs(s["test_particle_slope_large_n"] - 1) < 0.25))
    return rows
