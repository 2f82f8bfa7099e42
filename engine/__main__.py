"""``python -m engine``: a short tour of the engine, measured on the spot.

Integrates the Kepler problem (e = 0.6, Hairer, Lubich & Wanner's test) for 100 orbits with
every integrator at the same cost in force evaluations, and prints each one's energy error
and its position error against the closed-form solution (``engine.analytic.kepler``).

``python -m engine cloth [--out cloth.gif] [--frames N] ...``: a pinned cloth in the wind and a
rope beside it, drawn to a GIF (``engine.cloth_demo``; needs the ``[viz]`` extra).

``python -m engine galaxies [--out galaxies.gif] [--bodies N] [--frames F] ...``: two disk
galaxies collide under tree gravity and raise tidal tails, drawn to a GIF
(``engine.galaxies_demo``; needs the ``[viz]`` extra).

``python -m engine asteroids [--out asteroids.gif] [--rocks N] ...``: a belt of asteroids about
a star that bounce and merge, to a GIF (``engine.asteroids_demo``; needs the ``[viz]`` extra).

``python -m engine compile [--jobs N] [--list]``: compile the tour's integrators, every force
kernel and ``Batch``'s executors ahead, one worker process per core (``engine.compile_ahead``).
The tour itself compiles its integrators so on its first run.
"""
import argparse
import math
import time

import numpy as np

from . import (INTEGRATORS, Simulation, analytic, asteroids_demo, cloth_demo, compile_ahead,
               forces, galaxies_demo)
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


def first_runs(*integrators):
    """A short first run of each integrator (its code compiled, or loaded from the cache): the
    tour's tasks of ``engine.compile_ahead``."""
    for name in integrators:
        kepler_run(name, 1, 40)


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m engine", description=__doc__.split("\n\n")[0])
    parser.add_argument("--orbits", type=int, default=100)
    parser.add_argument("--evaluations", type=int, default=400,
                        help="force evaluations per orbit for the fixed-step methods")
    commands = parser.add_subparsers(dest="command",
                                     metavar="{cloth,galaxies,asteroids,compile}",
                                     help="cloth: the cloth-and-rope GIF demo (--tear: a sail "
                                          "that tears); galaxies: two colliding disk galaxies, "
                                          "to a GIF; asteroids: rocks that bounce and merge "
                                          "about a star, to a GIF; compile: the tour's kernels "
                                          "compiled ahead, on every core (without a command: "
                                          "the Kepler tour)")
    cloth = commands.add_parser("cloth", help="a pinned cloth in the wind and a rope, to a GIF",
                                description=cloth_demo.__doc__.split("\n\n")[0])
    cloth_demo.add_arguments(cloth)
    galaxies = commands.add_parser("galaxies", help="two disk galaxies collide, to a GIF",
                                   description=galaxies_demo.__doc__.split("\n\n")[0])
    galaxies_demo.add_arguments(galaxies)
    asteroids = commands.add_parser("asteroids", help="asteroids bounce and merge, to a GIF",
                                    description=asteroids_demo.__doc__.split("\n\n")[0])
    asteroids_demo.add_arguments(asteroids)
    ahead = commands.add_parser("compile", help="compile the engine's kernels ahead, on every core",
                                description=compile_ahead.__doc__.split("\n\n")[0])
    compile_ahead.add_arguments(ahead)
    args = parser.parse_args(argv)
    if args.command == "cloth":
        cloth_demo.main(args, cloth)
        return
    if args.command == "galaxies":
        galaxies_demo.main(args, galaxies)
        return
    if args.command == "asteroids":
        asteroids_demo.main(args, asteroids)
        return
    if args.command == "compile":
        compile_ahead.main(args, compile_ahead.ENGINE)
        return
    # a first run compiles the integrators on every core at once (nothing when warm)
    compiled = compile_ahead.run(compile_ahead.TOUR)
    if compiled:
        print(f"(first run: {len(compiled)} groups of integrators compiled ahead in "
              f"{min(compile_ahead.default_jobs(), len(compiled))} processes, "
              f"{sum(compiled.values()):.0f} s of compiling in all)")
    print(f"Kepler problem, e = 0.6, {args.orbits} orbits, "
          f"{args.evaluations} force evaluations per orbit (rk45: tolerance 1e-10)")
    print(f"{'integrator':<17}{'order':>5}{'steps':>10}{'|dE/E|':>11}{'|r - r_exact|':>15}{'time':>10}")
    for name in INTEGRATORS:
        first_runs(name)  # load the compiled code first: time the integration only
        row = kepler_run(name, args.orbits, args.evaluations)
        print(f"{name:<17}{row['order']:>5}{row['steps']:>10}{row['energy_error']:>11.2e}"
              f"{row['position_error']:>15.2e}{row['seconds'] * 1e3:>8.1f}ms")


if __name__ == "__main__":
    main()
