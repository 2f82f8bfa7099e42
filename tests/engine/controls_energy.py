"""Energy-error series of the Kepler problem at every step, and a planted energy pump.

The positive control of the "energy bounded" tests: a test double that adds energy at a fixed
rate per step, as a bug in a splitting executor that scaled the velocities by ``1 + pump``
every step would (1e-10 a step is about 4e-8 of |E| an orbit at 200 steps an orbit, since the
mean kinetic energy of a Kepler orbit equals |E|). The pump lives here, in the tests; the
engine is not touched.
"""
import math

import numpy as np

from engine import Simulation, forces

from .conftest import kepler_sim


def pump_energy(sim, steps, pump, mean_kinetic):
    """Scale every particle's velocity so that its kinetic energy gains
    ``steps * 2 * pump * mean_kinetic`` (per unit mass): on average what scaling the
    velocities by ``1 + pump`` at every one of ``steps`` steps adds."""
    vel = sim.vel
    kinetic = 0.5 * np.einsum("ij,ij->i", vel, vel)
    vel *= np.sqrt(1.0 + steps * 2.0 * pump * mean_kinetic / kinetic)[:, None]


class PumpedSim:
    """A Simulation whose ``step(n)`` also pumps energy in (see ``pump_energy``); anything
    else is the simulation's own."""

    def __init__(self, sim, pump, mean_kinetic):
        self._sim, self._pump, self._mean_kinetic = sim, pump, mean_kinetic

    def __getattr__(self, name):
        return getattr(self._sim, name)

    def step(self, n=1):
        self._sim.step(n)
        pump_energy(self._sim, n, self._pump, self._mean_kinetic)


def kepler_energy_errors(integrator, orbits, steps_per_orbit, e=0.5, pump=0.0):
    """(E - E0) / |E0| after every one of ``orbits * steps_per_orbit`` steps of the Kepler
    problem (a = 1, mu = 1, from pericentre), shape (orbits, steps_per_orbit).

    Stepping one step a call and asking for the energy each time costs about 50 us a step, too
    much for 2e5 steps. So the run is done twice: once in M calls of L steps (M * L steps)
    keeping the state at the start of each block, then all M blocks at once, as M independent
    test particles about the same fixed attractor, one step a call, their energies computed
    together. A test particle's step does not depend on the others, so block k's particle
    retraces the first run's steps bit for bit: without a pump, each block's last state is
    checked to equal the next block's first, exactly (AssertionError, with the first block
    that differs, otherwise). With ``pump`` the energy is pumped in after every call, as
    ``PumpedSim`` does (it then joins only approximately).
    """
    total = orbits * steps_per_orbit
    h = 2.0 * math.pi / steps_per_orbit
    block = math.isqrt(total)
    while total % block:
        block -= 1
    blocks = total // block
    sim = kepler_sim(e, integrator, h)
    e0 = sim.energy()
    mean_kinetic = abs(e0)  # the virial theorem, for the Kepler problem
    starts = np.empty((blocks + 1, 2, 2))
    for k in range(blocks + 1):
        starts[k] = sim.pos[0], sim.vel[0]
        if k < blocks:
            sim.step(block)
            if pump:
                pump_energy(sim, block, pump, mean_kinetic)
    seg = Simulation(dim=2, integrator=integrator, dt=h)
    seg.add_many(mass=np.ones(blocks), pos=starts[:-1, 0], vel=starts[:-1, 1])
    seg.add_force(forces.PointMass(mu=1.0, pos=(0.0, 0.0)))
    out = np.empty((blocks, block))
    for i in range(block):
        seg.step()
        if pump:
            pump_energy(seg, 1, pump, mean_kinetic)
        p, v = seg.pos, seg.vel
        energy = 0.5 * np.einsum("ij,ij->i", v, v) - 1.0 / np.sqrt(np.einsum("ij,ij->i", p, p))
        out[:, i] = (energy - e0) / abs(e0)
    if not pump:
        ends = np.concatenate([seg.pos, seg.vel], axis=1)
        joined = np.all(ends == starts[1:].reshape(blocks, 4), axis=1)
        assert joined.all(), (f"block {int(np.argmin(joined))} of {block} steps does not end where "
                              "the next one starts: a test particle's step depends on the others")
    return out.reshape(orbits, steps_per_orbit)


def energy_drift_figures(errors, window=10):
    """From ``kepler_energy_errors``: (early, late / early - 1, secular slope), where early and
    late are the largest |relative energy error| over the first and the last ``window`` orbits
    and the slope is the least-squares slope per orbit of each orbit's largest error."""
    per_orbit = np.abs(errors).max(axis=1)
    early = per_orbit[:window].max()
    late = per_orbit[-window:].max()
    slope = np.polyfit(np.arange(per_orbit.size), per_orbit, 1)[0]
    return float(early), float(late / early - 1.0), float(slope)
