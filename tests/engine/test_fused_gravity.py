"""The fused small-N gravity executor computes exactly what the general splitting executor does.

A zero ``UniformGravity`` term adds +0.0 to every acceleration, which changes no bit, but makes
the scene two terms, so the general executor runs it: the pair of runs compares the two paths.
"""
import numpy as np
import pytest

from engine import Simulation, SimulationError, forces
from engine.forces import pairwise
from engine.integrators import fused_gravity, splitting


def _system(dim, n, seed, softening, integrator, dt, general, inactive=()):
    rng = np.random.default_rng(seed)
    sim = Simulation(dim=dim, integrator=integrator, dt=dt)
    sim.add_many(mass=rng.uniform(0.5, 2.0, n), pos=rng.normal(size=(n, dim)) * 2.0,
                 vel=rng.normal(size=(n, dim)) * 0.3)
    for i in inactive:
        sim.deactivate(i)
    sim.add_force(forces.NBodyGravity(G=0.8, softening=softening))
    if general:
        sim.add_force(forces.UniformGravity(np.zeros(dim)))
    return sim


def _uses_fused(sim):
    state, model = sim.kernel_arguments()
    return bool(fused_gravity.applies(state, model))


@pytest.mark.parametrize("integrator", sorted(splitting.SCHEMES))
@pytest.mark.parametrize("dim", [2, 3])
def test_fused_path_is_bit_identical_to_the_general_one(integrator, dim):
    runs = []
    for general in (False, True):
        sim = _system(dim, 7, seed=dim, softening=0.05, integrator=integrator, dt=1e-3,
                      general=general, inactive=(2,))
        assert _uses_fused(sim) is not general
        # 3 calls crossing block boundaries, and a call shorter than a block
        for steps in (fused_gravity.BLOCK * 2 + 5, 1, 37):
            sim.step(steps)
        runs.append(sim)
    fused, general = runs
    assert fused.pos.tobytes() == general.pos.tobytes()
    assert fused.vel.tobytes() == general.vel.tobytes()
    assert fused.t == general.t and fused.steps == general.steps
    # and the bodies really moved (the comparison is not of two untouched states)
    start = _system(dim, 7, seed=dim, softening=0.05, integrator=integrator, dt=1e-3,
                    general=False, inactive=(2,))
    assert np.abs(fused.pos - start.pos).max() > 1e-3
    assert fused.pos[2].tobytes() == start.pos[2].tobytes()  # the inactive body stayed put


def test_fused_path_is_taken_only_for_its_case():
    assert _uses_fused(_system(3, 5, 1, 0.0, "leapfrog", 1e-3, general=False))
    assert not _uses_fused(_system(3, 5, 1, 0.0, "leapfrog", 1e-3, general=True))
    assert not _uses_fused(_system(3, pairwise.PARALLEL_MIN, 1, 0.0, "leapfrog", 1e-3,
                                   general=False))
    sim = Simulation(dim=3)
    sim.add_many(mass=1.0, pos=np.eye(3), test=[False, False, True])
    sim.add_force(forces.NBodyGravity())
    assert not _uses_fused(sim)
    sim = Simulation(dim=3, box=10.0)
    sim.add_many(mass=1.0, pos=np.eye(3))
    sim.add_force(forces.NBodyGravity())
    assert not _uses_fused(sim)
    sim = Simulation(dim=3)
    sim.add_many(mass=1.0, pos=np.eye(3), pinned=[True, False, False])
    sim.add_force(forces.NBodyGravity())
    assert not _uses_fused(sim)


@pytest.mark.parametrize("collide_at", [3, fused_gravity.BLOCK + 9])
def test_fused_blow_up_stops_where_the_general_path_stops(collide_at):
    """Two unsoftened bodies sent head-on to meet exactly at a step: both paths raise at the
    same step, name the same body and keep the same last finite state, bit for bit."""
    results = []
    for general in (False, True):
        sim = Simulation(dim=3, integrator="symplectic_euler", dt=0.25)
        # so light that their pull changes no bit of v = 1: every position is exact in binary
        # and they coincide after collide_at steps; the next force evaluation is 0 * inf = NaN
        x0 = 0.25 * collide_at
        sim.add_many(mass=[1e-300, 1e-300, 1e-300], pos=[[-x0, 0, 0], [x0, 0, 0], [0, 5, 0]],
                     vel=[[1, 0, 0], [-1, 0, 0], [0, 0, 0]])
        sim.add_force(forces.NBodyGravity())
        if general:
            sim.add_force(forces.UniformGravity((0.0, 0.0, 0.0)))
        assert _uses_fused(sim) is not general
        with pytest.raises(SimulationError) as info:
            sim.step(10 * fused_gravity.BLOCK)
        results.append((info.value.step, info.value.time, info.value.particle,
                        sim.pos.tobytes(), sim.vel.tobytes(), sim.steps, sim.t))
        assert np.isfinite(sim.pos).all() and np.isfinite(sim.vel).all()
    assert results[0] == results[1]
    assert results[0][0] == collide_at
