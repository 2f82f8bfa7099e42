"""``python -m validation theta-table``: the table of docs/engine.md, theta against error and
cost for both of the tree's walks.

For each walk (``method="tree"``, Barnes-Hut; ``"fmm"``, the fast multipole walk) and each
theta of ``THETAS``: on a Plummer sphere (gravity, ``engine.initial_conditions.plummer``) the
median and 99th percentile of the relative force error against the exact sum
(``tree_bench.exact_field``, over ``TARGETS`` bodies at random) and the time of one
evaluation (``sim.accelerations()``, the fastest of three); on a neutral two-species plasma in
a uniform cube (Coulomb, ``ic.plasma``) the same errors at orders 2, 1 and 0, against the
engine's direct sum, and the time at order 2. Softening 1e-3, 3-D, float64, every thread.
"""
import argparse
import sys
import time

from . import tree_bench as tb

THETAS = (0.3, 0.5, 0.6, 0.7, 0.9)
WALKS = ("tree", "fmm")
TARGETS = 1000
SOFTENING = 1e-3
HEADER = ("| walk | theta | Plummer sphere (gravity): median / 99th percentile | time | neutral "
          "plasma (Coulomb, uniform cube), order 2 | order 1 | order 0 | time (order 2) |")


def _simulation(bodies, term):
    from engine import Simulation
    from engine import initial_conditions as ic

    sim = Simulation(dim=bodies.dim, integrator="leapfrog", dt=1e-3, capacity=bodies.n)
    ic.add_to(sim, bodies)
    sim.add_force(term)
    return sim


def _fastest(sim, repeats=3):
    """(accelerations, the fastest of ``repeats`` timed evaluations after a first)."""
    acc = sim.accelerations()
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        acc = sim.accelerations()
        best = min(best, time.perf_counter() - start)
    return acc, best


def _cell(stats):
    return f"{stats['median']:.1e} / {stats['p99']:.1e}"


def measure(n, thetas=THETAS, walks=WALKS, seed=0):
    """Rows {walk, theta, gravity: {median, p99}, gravity_s, plasma: {order: stats},
    plasma_s}, and the direct sum's seconds for the plasma."""
    from engine import forces
    from engine import initial_conditions as ic

    targets = tb.pick_targets(n, TARGETS)
    sphere = ic.plummer(n, 3, seed=seed)
    exact_gravity = tb.exact_field(sphere.pos, sphere.mass, targets, softening=SOFTENING)
    plasma = ic.plasma(n, 3, seed=seed, neutral=True)
    start = time.perf_counter()
    exact_plasma = _simulation(plasma, forces.Coulomb(softening=SOFTENING)).accelerations()
    direct_s = time.perf_counter() - start
    exact_plasma = exact_plasma[targets]
    rows = []
    for walk in walks:
        for theta in thetas:
            acc, gravity_s = _fastest(_simulation(sphere, forces.NBodyGravity(
                softening=SOFTENING, method=walk, theta=theta)))
            row = {"walk": walk, "theta": theta, "gravity_s": gravity_s, "plasma": {},
                   "gravity": tb.error_stats(tb.relative_errors(acc[targets], exact_gravity))}
            for order in (2, 1, 0):
                acc, seconds = _fastest(_simulation(plasma, forces.Coulomb(
                    softening=SOFTENING, method=walk, theta=theta, order=order)))
                row["plasma"][order] = tb.error_stats(tb.relative_errors(acc[targets],
                                                                         exact_plasma))
                if order == 2:
                    row["plasma_s"] = seconds
            rows.append(row)
    return {"n": n, "rows": rows, "direct_plasma_s": direct_s}


def markdown(table):
    """The table's lines."""
    lines = [HEADER, "|---|---|---|---|---|---|---|---|"]
    for r in table["rows"]:
        lines.append(f"| {r['walk']} | {r['theta']} | {_cell(r['gravity'])} | "
                     f"{r['gravity_s']:.3g} s | "
                     + " | ".join(_cell(r["plasma"][order]) for order in (2, 1, 0))
                     + f" | {r['plasma_s']:.3g} s |")
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m validation theta-table",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("--n", type=int, default=100_000, help="bodies (default 10^5)")
    args = parser.parse_args(argv)
    if args.n < 2:
        parser.error(f"--n must be at least 2, got {args.n}")
    table = measure(args.n)
    print(f"N = {table['n']}; the direct sum (plasma) took {table['direct_plasma_s']:.3g} s")
    print("\n".join(markdown(table)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
