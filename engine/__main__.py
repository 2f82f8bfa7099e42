"""``python -m engine``: a short tour of the engine, measured on the spot.

Integrates the Kepler problem (e = 0.6, Hairer, Lubich & Wanner's test) for 100 orbits with
every integrator at the same cost in force evaluations, and prints each one's energy error
and its position error against the closed-form solution (``engine.analytic.kepler``).

``python -m engine cloth [--out cloth.gif] [--frames N] ...``: a pinned cloth in the wind and a
rope beside it, drawn to a GIF (``engine.cloth_demo``; needs the ``[viz]`` extra).
"""
import argparse
import math
import time

import numpy as np

from . import INTEGRATORS, Simulation, analytic, cloth_demo, forces
from .integrators import FORCE_EVALUATIONS, ORDERS


def kepler_run(integrator, orbits, evaluations_per_orbit, e=0.6):
    r0 = np.array([1.0 - e, 0.0])
    v0 = np.array([0.0, math.sqrt((1.0 + e) / (1.0 - e))])
    period = 2.0 * math.pi
    steps = max(1, evaluations_per_orbit // FORCE_EVALUATIONS[integrator])
    sim = Simulation(dim=2, integrator=integrator, dt=period / steps, tolerance=1e-10)
    sim.add(mass=1.0, pos=r0, vel=v0)
    sim.add_force(forces.PointMass(mu=1.0))
    e0 = sim.energy()
    start = time.perf_counter()
    sim.integrate(orbits * period)
    wall = time.perf_counter() - start
    r, _ = analytic.kepler(r0, v0, 1.0, sim.t)
    return {
        "integrator": integrator,
        "order": ORDERS[integrator],
        "steps": sim.steps,
        "energy_error": abs(sim.energy() - e0) / abs(e0),
        "position_error": float(np.linalg.norm(sim.pos[0] - r)),
        "seconds": wall,
    }


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m engine", description=__doc__.split("\n\n")[0])
    parser.add_argument("--orbits", type=int, default=100)
    parser.add_argument("--evaluations", type=int, default=400,
                        help="force evaluations per orbit for the fixed-step methods")
    commands = parser.add_subparsers(dest="command", metavar="{cloth}",
                                     help="cloth: the cloth-and-rope GIF demo (without a "
                                          "command: the Kepler tour)")
    cloth = commands.add_parser("cloth", help="a pinned cloth in the wind and a rope, to a GIF",
                                description=cloth_demo.__doc__.split("\n\n")[0])
    cloth_demo.add_arguments(cloth)
    args = parser.parse_args(argv)
    if args.command == "cloth":
        cloth_demo.main(args, cloth)
        return
    print(f"Kepler problem, e = 0.6, {args.orbits} orbits, "
          f"{args.evaluations} force evaluations per orbit (rk45: tolerance 1e-10)")
    print(f"{'integrator':<17}{'order':>5}{'steps':>10}{'|dE/E|':>11}{'|r - r_exact|':>15}{'time':>10}")
    for name in INTEGRATORS:
        kepler_run(name, 1, 40)  # load the compiled code first: time the integration only
        row = kepler_run(name, args.orbits, args.evaluations)
        print(f"{name:<17}{row['order']:>5}{row['steps']:>10}{row['energy_error']:>11.2e}"
              f"{row['position_error']:>15.2e}{row['seconds'] * 1e3:>8.1f}ms")


if __name__ == "__main__":
    main()
