"""engine.Batch: M systems in one compiled call, each bit-identical to a Simulation of its own."""
import math

import numba
import numpy as np
import pytest

import engine
from engine import Batch, Simulation, SimulationError, forces
from engine.forces import pairwise

M = 5
SLOTS = 66  # the game's size: two ships and 64 torpedo slots


def _scene(seed=1, systems=M, slots=SLOTS, dim=2):
    """Per-system initial conditions and parameters that differ between the systems."""
    rng = np.random.default_rng(seed)
    return {
        "pos": rng.uniform(-0.4, 0.4, (systems, slots, dim)),
        "vel": rng.normal(0.0, 1e-2, (systems, slots, dim)),
        "mass": rng.uniform(0.5, 1.5, (systems, slots)),
        "charge": rng.choice([-1.0, 1.0], (systems, slots)),
        "test": np.arange(slots) >= 2,
        "star": rng.uniform(-0.1, 0.1, (systems, dim)),
        "thrust": rng.normal(0.0, 1e-2, (systems, 2, dim)),
    }


def _terms(scene, m=None):
    """The force terms of the scene (for system m of a Simulation: its own values set)."""
    star = forces.PointMass(mu=1e-2, softening=0.05,
                            pos=scene["star"][m] if m is not None else np.zeros(scene["star"].shape[1]))
    return [star, forces.NBodyGravity(G=1e-3, softening=0.05), forces.Drag(linear=0.01),
            forces.Coulomb(k=1e-4, softening=0.05), forces.Thrust()]


def _batch(integrator, scene, box=None, dt=0.05, **kwargs):
    systems, slots, dim = scene["pos"].shape
    batch = Batch(systems=systems, dim=dim, integrator=integrator, dt=dt, capacity=slots, box=box,
                  **kwargs)
    batch.add_many(mass=scene["mass"], pos=scene["pos"], vel=scene["vel"], charge=scene["charge"],
                   test=scene["test"])
    terms = [batch.add_force(t) for t in _terms(scene)]
    batch.set_parameter(terms[0], "pos", scene["star"])
    force = np.zeros((systems, slots, dim))
    force[:, :2] = scene["thrust"]
    batch.set_parameter(terms[-1], "force", force)
    return batch, terms


def _alone(integrator, scene, m, box=None, dt=0.05, **kwargs):
    slots, dim = scene["pos"].shape[1:]
    sim = Simulation(dim=dim, integrator=integrator, dt=dt, capacity=slots, box=box, **kwargs)
    sim.add_many(mass=scene["mass"][m], pos=scene["pos"][m], vel=scene["vel"][m],
                 charge=scene["charge"][m], test=scene["test"])
    terms = [sim.add_force(t) for t in _terms(scene, m)]
    for ship in range(2):
        terms[-1].set(ship, scene["thrust"][m, ship])
    return sim


@pytest.mark.parametrize("integrator", engine.integrators.GENERAL)
@pytest.mark.parametrize("box", [None, 1.0])
def test_each_system_is_bit_identical_to_a_simulation_of_its_own(integrator, box):
    scene = _scene()
    batch, _ = _batch(integrator, scene, box=box)
    batch.step(40)
    for m in range(M):
        sim = _alone(integrator, scene, m, box=box)
        sim.step(40)
        assert np.array_equal(batch.pos[m], sim.pos), (integrator, m)
        assert np.array_equal(batch.vel[m], sim.vel), (integrator, m)
        assert batch.t[m] == sim.t and batch.steps[m] == sim.steps
        assert batch.energy()[m] == sim.energy()
        assert batch.kinetic_energy()[m] == sim.kinetic_energy()
        np.testing.assert_array_equal(batch.momentum()[m], sim.momentum())
    if box:
        assert np.all(np.abs(batch.pos) <= 0.5)  # wrapped onto the torus
    # the systems really differ (per-system masses, star positions and thrust)
    assert not np.array_equal(batch.pos[0], batch.pos[1])


def test_rk45_adapts_each_systems_step_on_its_own():
    scene = _scene(seed=4)
    scene["vel"][1] *= 20.0  # a faster system needs smaller steps
    batch, _ = _batch("rk45", scene, tolerance=1e-10)
    batch.step(30)
    assert batch.dts[0] != batch.dts[1] and batch.t[0] != batch.t[1]
    for m in (0, 1):
        sim = _alone("rk45", scene, m, tolerance=1e-10)
        sim.step(30)
        assert np.array_equal(batch.pos[m], sim.pos) and batch.t[m] == sim.t
        assert batch.dts[m] == sim.dt


def test_the_result_does_not_depend_on_the_thread_count():
    scene = _scene(seed=2, systems=16)
    runs = []
    threads = numba.get_num_threads()
    try:
        for count in sorted({1, numba.config.NUMBA_NUM_THREADS}):
            numba.set_num_threads(count)
            batch, _ = _batch("pefrl", scene, box=1.0)
            batch.step(25)
            runs.append((batch.pos.copy(), batch.vel.copy(), batch.energy()))
    finally:
        numba.set_num_threads(threads)
    for pos, vel, energy in runs[1:]:
        assert np.array_equal(pos, runs[0][0]) and np.array_equal(vel, runs[0][1])
        assert np.array_equal(energy, runs[0][2])


def test_large_systems_take_the_vectorised_pair_kernel_and_stay_identical():
    n = pairwise.THREADS_MIN + 8  # a Simulation of this size runs the pair sum on every core
    rng = np.random.default_rng(9)
    pos = rng.normal(size=(2, n, 3))
    mass = rng.uniform(0.5, 2.0, (2, n))
    batch = Batch(systems=2, dim=3, integrator="leapfrog", dt=1e-3, capacity=n)
    batch.add_many(mass=mass, pos=pos)
    batch.add_force(forces.NBodyGravity(softening=0.05))
    batch.step(5)
    for m in range(2):
        sim = Simulation(dim=3, integrator="leapfrog", dt=1e-3, capacity=n)
        sim.add_many(mass=mass[m], pos=pos[m])
        sim.add_force(forces.NBodyGravity(softening=0.05))
        sim.step(5)
        assert np.array_equal(batch.pos[m], sim.pos)


def test_parameters_are_set_per_system_by_name_and_survive_a_term_change():
    scene = _scene(seed=3)
    batch, terms = _batch("verlet", scene)
    star, drag = terms[0], terms[2]
    np.testing.assert_array_equal(batch.parameter(star, "pos"), scene["star"])
    drag.linear = 0.5  # an attribute sets the parameter for every system ...
    np.testing.assert_array_equal(batch.parameter(drag, "linear"), np.full(M, 0.5))
    # ... and leaves the per-system ones alone
    np.testing.assert_array_equal(batch.parameter(star, "pos"), scene["star"])
    batch.set_parameter(drag, "linear", np.arange(M) * 0.1)
    batch.step(3)
    for m in (0, 3):
        sim = _alone("verlet", scene, m)
        sim.forces[2].linear = m * 0.1
        sim.step(3)
        assert np.array_equal(batch.pos[m], sim.pos)
    with pytest.raises(ValueError, match="no parameter 'position'.*mu, softening_squared, pos"):
        batch.set_parameter(star, "position", (0.0, 0.0))
    with pytest.raises(ValueError, match=r"pos must have shape"):
        batch.set_parameter(star, "pos", np.zeros((M + 1, 2)))
    with pytest.raises(ValueError, match="pos must be finite, got nan"):
        batch.set_parameter(star, "pos", (math.nan, 0.0))
    with pytest.raises(ValueError, match="is not declared in this batch"):
        batch.parameter(forces.Drag(), "linear")


def test_every_layout_declares_what_its_term_packs():
    from engine.forces import registry
    for entry in registry.entries():
        assert entry.layout, entry.name


def test_a_system_that_blows_up_keeps_its_last_finite_state_and_is_named():
    pos = np.array([[[0.0, 0.0], [1.0, 0.0]], [[0.0, 0.0], [0.0, 0.0]], [[0.0, 0.0], [2.0, 0.0]]])
    batch = Batch(systems=3, dim=2, integrator="leapfrog", dt=0.01, capacity=2)
    batch.add_many(mass=1.0, pos=pos)
    batch.add_force(forces.NBodyGravity())  # system 1: two coincident bodies, no softening
    before = batch.pos[1].copy()
    with pytest.raises(SimulationError, match="system 1 of 3 failed at its step 0") as err:
        batch.step(10)
    assert err.value.step == 0
    np.testing.assert_array_equal(batch.pos[1], before)
    assert list(batch.steps) == [10, 0, 10]  # the others took their steps


@pytest.mark.parametrize("call, message", [
    (lambda: Batch(systems=0), "systems must be an int in"),
    (lambda: Batch(systems=2.0), "systems must be an int in"),
    (lambda: Batch(systems=2, dim=4), "dim must be 2 or 3"),
    (lambda: Batch(systems=2, integrator="rk5"), "integrator must be one of"),
    (lambda: Batch(systems=2, dt=0.0), "dt must be non-zero"),
    (lambda: Batch(systems=2, box=-1.0), "box must be >= 0"),
])
def test_bad_construction_is_refused_naming_the_field(call, message):
    with pytest.raises((ValueError, TypeError), match=message):
        call()


def test_bad_particles_are_refused_before_anything_is_added():
    batch = Batch(systems=3, dim=2)
    with pytest.raises(ValueError, match=r"pos must have shape \(systems=3, k, dim=2\)"):
        batch.add_many(mass=1.0, pos=np.zeros((2, 4, 2)))
    with pytest.raises(ValueError, match=r"mass must be finite and >= 0.0, got -1.0 \(system 2"):
        batch.add_many(mass=[[1.0], [1.0], [-1.0]], pos=np.zeros((3, 1, 2)))
    with pytest.raises(ValueError, match="vel must be finite"):
        batch.add_many(mass=1.0, pos=np.zeros((1, 2)), vel=[[math.inf, 0.0]])
    assert batch.n == 0
    batch.add_many(mass=1.0, pos=np.zeros((1, 2)))
    batch.vel[2, 0, 0] = math.nan
    with pytest.raises(ValueError, match="vel of system 2, particle 0 must be finite"):
        batch.step()
    assert batch.steps.tolist() == [0, 0, 0]


def test_a_removed_force_stops_acting_in_every_system():
    batch = Batch(systems=2, dim=2, integrator="symplectic_euler", dt=0.1)
    batch.add_many(mass=1.0, pos=np.zeros((1, 2)), vel=[[1.0, 0.0]])
    drag = batch.add_force(forces.Drag(linear=0.0))
    batch.step()
    batch.remove_force(drag)
    del drag
    batch.add_force(forces.Drag(linear=5.0))
    batch.step()
    np.testing.assert_array_equal(batch.vel[:, 0], [[0.5, 0.0], [0.5, 0.0]])


def test_slots_added_after_a_per_system_thrust_keep_every_systems_thrust():
    batch = Batch(systems=2, dim=2, integrator="symplectic_euler", dt=1.0)
    batch.add_many(mass=1.0, pos=np.zeros((2, 2)))
    thrust = batch.add_force(forces.Thrust())
    batch.set_parameter(thrust, "force", [[[1.0, 0.0], [0.0, 2.0]], [[3.0, 0.0], [0.0, 4.0]]])
    batch.add_many(mass=1.0, pos=np.zeros((1, 2)))  # a third slot in every system
    np.testing.assert_array_equal(batch.parameter(thrust, "force"),
                                  [[[1, 0], [0, 2], [0, 0]], [[3, 0], [0, 4], [0, 0]]])
    batch.step()
    np.testing.assert_array_equal(batch.vel[:, :, :], [[[1, 0], [0, 2], [0, 0]],
                                                        [[3, 0], [0, 4], [0, 0]]])


@pytest.mark.parametrize("term, name, value, message", [
    (forces.Drag(linear=0.1), "linear", -1.0, r"Drag.linear must be finite and >= 0.0, got -1.0"),
    (forces.PointMass(mu=1.0), "mu", 0.0, r"PointMass.mu must be finite and > 0.0, got 0.0"),
    (forces.NBodyGravity(), "softening_squared", -4.0, r"softening_squared must be finite and >= 0.0"),
    (forces.Blast(center=(0.0, 0.0), strength=1.0), "scale", 0.0, r"Blast.scale must be finite and > 0.0"),
])
def test_per_system_values_are_checked_as_the_term_checks_them(term, name, value, message):
    batch = Batch(systems=3, dim=2)
    batch.add_many(mass=1.0, pos=np.zeros((2, 2)))
    batch.add_force(term)
    before = batch.parameter(term, name)
    values = np.broadcast_to(before, before.shape).copy()
    values[1] = value
    with pytest.raises(ValueError, match=message + r".*\(system 1\); nothing was changed"):
        batch.set_parameter(term, name, values)
    np.testing.assert_array_equal(batch.parameter(term, name), before)


def test_a_failed_rk45_system_keeps_its_step_as_a_simulation_does():
    pos = [[0.0, 0.0], [1e-9, 0.0]]
    batch = Batch(systems=1, dim=2, integrator="rk45", dt=0.1)
    batch.add_many(mass=1.0, pos=pos)
    batch.add_force(forces.NBodyGravity())
    sim = Simulation(dim=2, integrator="rk45", dt=0.1)
    sim.add_many(mass=1.0, pos=pos)
    sim.add_force(forces.NBodyGravity())
    for run in (batch.step, sim.step):
        with pytest.raises(SimulationError):
            run(1000)
    assert batch.dts[0] == sim.dt and batch.t[0] == sim.t


def test_potential_energies_of_many_terms_add_as_a_simulation_adds_them():
    scene = _scene(seed=8, systems=3)
    batch, _ = _batch("leapfrog", scene)
    extra = [forces.PointMass(mu=0.1 * (k + 1), pos=(0.05 * k, -0.03 * k), softening=0.1)
             for k in range(10)]
    for term in extra:
        batch.add_force(term)
    for m in range(3):
        sim = _alone("leapfrog", scene, m)
        for k in range(10):
            sim.add_force(forces.PointMass(mu=0.1 * (k + 1), pos=(0.05 * k, -0.03 * k),
                                           softening=0.1))
        assert batch.potential_energy()[m] == sim.potential_energy()


def test_inactive_and_pinned_particles_stay_where_they_are_in_a_periodic_space():
    import engine as _engine
    for integrator in _engine.integrators.GENERAL:
        sim = Simulation(dim=2, integrator=integrator, dt=0.01, box=1.0)
        sim.add_many(mass=1.0, pos=[(0.7, 0.0), (0.2, 0.0), (0.0, 0.3)],
                     vel=[(0.0, 0.0), (1.0, 0.0), (0.5, 0.0)])
        sim.add_force(forces.UniformGravity(g=(0.0, -1.0)))
        sim.deactivate(1)
        sim.pin(0)
        sim.step(20)
        assert sim.pos[0, 0] == 0.7 and sim.pos[1, 0] == 0.2, integrator  # parked, not wrapped
        assert -0.5 <= sim.pos[2, 0] < 0.5


def test_a_spring_across_the_edge_of_a_periodic_space_joins_the_nearest_images():
    sim = Simulation(dim=2, box=1.0)
    sim.add_many(mass=1.0, pos=[(0.49, 0.0), (-0.49, 0.0)])
    sim.add_force(forces.Springs([(0, 1)], k=10.0, rest_length=0.02))
    assert sim.potential_energy() == pytest.approx(0.0, abs=1e-24)
    sim.pos[1] = (-0.48, 0.0)  # stretched by 0.01 through the edge
    assert sim.potential_energy() == pytest.approx(0.5 * 10.0 * 0.01 ** 2, rel=1e-9)
