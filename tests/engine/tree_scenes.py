"""Scenes and measures for the tests of the Barnes-Hut tree (tests/engine/test_tree.py).

A scene is an ``engine.initial_conditions.Bodies``; its reference is the engine's own direct
sum (``method="direct"``) on the same bodies. The error of a tree evaluation is taken per
particle, |a_tree - a_direct| / |a_direct|, and summarised by its median and 99th percentile
(Hernquist 1987, ApJS 64, 715, measures a tree code's accuracy this way).
"""
import numpy as np

from engine import Simulation, forces
from engine import initial_conditions as ic

#: the gravitating scenes of the accuracy tests, by name
SCENES = ("plummer", "cube", "disk", "clumps")


def scene(name, n, dim, seed=1):
    """n bodies of the named scene (total mass 1, G = 1 units)."""
    if name == "plummer":
        return ic.plummer(n, dim, seed=seed)
    if name == "cube":
        return ic.uniform_cube(n, dim, seed=seed)
    if name == "disk":
        # a slab in 3-D: a disk of zero thickness would be the 2-D scene again
        return ic.cold_disk(n, dim, seed=seed, thickness=0.05)
    if name == "clumps":
        return ic.two_clumps(n, dim, seed=seed)
    raise ValueError(f"no scene named {name!r}")


def permuted(bodies, order):
    """The same bodies, listed in ``order``."""
    return ic.Bodies(bodies.mass[order], bodies.pos[order], bodies.vel[order],
                     bodies.charge[order])


def simulation(bodies, *terms, integrator="leapfrog", dt=1e-3, **options):
    """A Simulation of ``bodies`` (G = 1) acted on by ``terms``."""
    sim = Simulation(dim=bodies.dim, integrator=integrator, dt=dt, G=1.0, **options)
    ic.add_to(sim, bodies)
    for term in terms:
        sim.add_force(term)
    return sim


def accelerations(bodies, *terms):
    """The (n, dim) accelerations ``terms`` give ``bodies``."""
    return simulation(bodies, *terms).accelerations()


def relative_errors(a, reference):
    """|a - reference| / |reference| per particle (rows)."""
    return np.linalg.norm(a - reference, axis=1) / np.linalg.norm(reference, axis=1)


def summary(errors):
    """(median, 99th percentile) of per-particle errors."""
    return float(np.median(errors)), float(np.percentile(errors, 99))


class ExactEnergy:
    """The energy of a simulation's state by the direct sum (every pair, exactly), so that a
    tree run's energy error is not mixed with the tree's error in its own potential."""

    def __init__(self, sim, softening):
        self.sim = sim
        self.twin = Simulation(dim=sim.dim, G=sim.G)
        self.twin.add_many(mass=sim.mass, pos=sim.pos, vel=sim.vel, test=sim.test)
        self.twin.add_force(forces.NBodyGravity(softening=softening))

    def __call__(self):
        self.twin.pos[:] = self.sim.pos
        self.twin.vel[:] = self.sim.vel
        return self.twin.energy()
