"""Pinned particles: held where they are whatever acts on them, still exerting their forces,
and immovable in the diagnostics (``Simulation.pin``, ``Batch.pin``)."""
import math

import numpy as np
import pytest

import engine
from engine import Batch, Simulation, forces


def hanging_rope(integrator, dt=2e-4, segments=10, **kw):
    """A horizontal rope pinned at its left end, under gravity (it swings down and hangs)."""
    sim = Simulation(dim=2, integrator=integrator, dt=dt, **kw)
    idx, springs = forces.rope(sim, (0.0, 0.0), (1.0, 0.0), segments, mass=0.01, k=100.0)
    sim.pin(int(idx[0]))
    sim.add_force(forces.UniformGravity(g=(0.0, -9.8)))
    return sim, idx, springs


@pytest.mark.parametrize("integrator", engine.integrators.ANY_SCENE)
def test_a_rope_hangs_from_its_pinned_end_with_every_integrator(integrator):
    sim, idx, springs = hanging_rope(integrator, tolerance=1e-8)
    anchor = sim.pos[0].copy()
    if integrator in engine.ADAPTIVE_INTEGRATORS:
        sim.integrate(0.2)
    else:
        sim.step(1000)  # t = 0.2: the free end has fallen about g t^2 / 2
    assert sim.pos[0].tobytes() == anchor.tobytes()  # bit-identical, not merely close
    assert sim.vel[0].tobytes() == np.zeros(2).tobytes()
    # still attached: the first spring is near its rest length, and the rope has swung down
    first = np.linalg.norm(sim.pos[1] - sim.pos[0])
    assert abs(first - springs.rest_length[0]) < 0.1 * springs.rest_length[0]
    assert sim.pos[-1, 1] < -0.1
    assert np.all(np.isfinite(sim.pos))


def test_a_deactivated_anchor_lets_the_rope_fall_a_pinned_one_holds_it():
    """The issue's point: deactivating the first particle is not a pin."""
    pinned, _, _ = hanging_rope("verlet")
    freed, _, _ = hanging_rope("verlet")
    freed.unpin(0)
    freed.deactivate(0)
    pinned.step(1000)
    freed.step(1000)
    # without its anchor the rope's first free particle falls as the rest do
    assert np.linalg.norm(pinned.pos[1] - pinned.pos[0]) < 0.12
    assert freed.pos[1, 1] < -0.15


def test_pinned_at_add_and_pin_zero_the_velocity():
    sim = Simulation(dim=2, integrator="leapfrog", dt=0.01)
    a = sim.add(mass=1.0, pos=(0.0, 0.0), vel=(3.0, 4.0), pinned=True)
    b = sim.add(mass=1.0, pos=(1.0, 0.0), vel=(0.0, 2.0))
    assert list(sim.pinned) == [True, False]
    np.testing.assert_array_equal(sim.vel[a], [0.0, 0.0])
    sim.pin(b)
    np.testing.assert_array_equal(sim.vel[b], [0.0, 0.0])
    with pytest.raises(ValueError):
        sim.pinned[0] = False  # read-only: use unpin()
    idx = sim.add_many(mass=[1.0, 1.0], pos=[(2.0, 0.0), (3.0, 0.0)],
                       vel=[(1.0, 1.0), (1.0, 1.0)], pinned=[True, False])
    assert list(sim.pinned[idx]) == [True, False]
    np.testing.assert_array_equal(sim.vel[idx[0]], [0.0, 0.0])
    np.testing.assert_array_equal(sim.vel[idx[1]], [1.0, 1.0])


@pytest.mark.parametrize("extra", [0, 12], ids=["scalar pair loop", "vectorised pair kernel"])
def test_a_pinned_mass_attracts_as_a_point_mass_does(extra):
    """A pinned heavy body under NBodyGravity pulls the others exactly as a PointMass of
    mu = G M at its place (to round-off), and is not moved by their pull.

    ``extra`` test particles on other orbits take the simulation past the size at which the
    vectorised pair kernel replaces the scalar loop."""
    G, M, eps = 1.0, 5.0, 0.0
    rng = np.random.default_rng(3)
    radii = np.concatenate(([1.0], rng.uniform(0.8, 2.0, extra)))
    angles = rng.uniform(0.0, 2.0 * math.pi, radii.size)
    pos = np.column_stack((radii * np.cos(angles), radii * np.sin(angles)))
    speed = np.sqrt(G * M / radii) * 0.9  # eccentric orbits
    vel = np.column_stack((-speed * np.sin(angles), speed * np.cos(angles)))

    nbody = Simulation(dim=2, integrator="leapfrog", dt=1e-3, G=G)
    star = nbody.add(mass=M, pos=(0.0, 0.0), pinned=True)
    # light, and a source itself in the small case (its pull on the star is held by the pin);
    # with the others, a test particle as they are (they would feel it, not the PointMass)
    planet = nbody.add(mass=1e-3, pos=pos[0], vel=vel[0], test=bool(extra))
    others = nbody.add_many(mass=1.0, pos=pos[1:], vel=vel[1:], test=True) if extra else []
    nbody.add_force(forces.NBodyGravity(softening=eps))

    field = Simulation(dim=2, integrator="leapfrog", dt=1e-3, G=G)
    field.add(mass=1e-3, pos=pos[0], vel=vel[0])
    if extra:
        field.add_many(mass=1.0, pos=pos[1:], vel=vel[1:])
    field.add_force(forces.PointMass(mu=G * M, pos=(0.0, 0.0), softening=eps))

    nbody.step(3000)
    field.step(3000)
    np.testing.assert_array_equal(nbody.pos[star], [0.0, 0.0])
    moving = np.concatenate(([planet], others)).astype(int)
    np.testing.assert_allclose(nbody.pos[moving], field.pos, rtol=0, atol=1e-10)
    np.testing.assert_allclose(nbody.vel[moving], field.vel, rtol=0, atol=1e-10)
    # and they really orbit: the planet has gone round a good part of its orbit
    assert np.linalg.norm(nbody.pos[planet] - pos[0]) > 0.5


def test_the_diagnostics_leave_a_pinned_particle_out():
    sim = Simulation(dim=3, integrator="leapfrog", dt=1e-3)
    anchor = sim.add(mass=10.0, pos=(5.0, 0.0, 0.0), pinned=True)
    a = sim.add(mass=1.0, pos=(1.0, 0.0, 0.0), vel=(0.0, 1.0, 0.0))
    b = sim.add(mass=3.0, pos=(0.0, 2.0, 1.0), vel=(0.5, 0.0, -1.0))
    sim.add_force(forces.NBodyGravity())
    free = [a, b]
    # a velocity written into the pinned slot counts for nothing (the next step clears it)
    sim.vel[anchor] = (7.0, 7.0, 7.0)
    m, x, v = sim.mass[free], sim.pos[free], sim.vel[free]
    assert sim.kinetic_energy() == pytest.approx(0.5 * np.sum(m[:, None] * v ** 2))
    np.testing.assert_allclose(sim.momentum(), (m[:, None] * v).sum(0))
    np.testing.assert_allclose(sim.angular_momentum(), np.cross(x, m[:, None] * v).sum(0))
    cp, cv = sim.center_of_mass()
    np.testing.assert_allclose(cp, (m[:, None] * x).sum(0) / m.sum())
    np.testing.assert_allclose(cv, (m[:, None] * v).sum(0) / m.sum())
    # the potential keeps the pinned particle's interactions
    unpinned = Simulation(dim=3)
    unpinned.add_many(mass=sim.mass, pos=sim.pos)
    unpinned.add_force(forces.NBodyGravity())
    assert sim.potential_energy() == unpinned.potential_energy()
    # the pin does no work, so energy is conserved; it holds the others, so momentum is not
    sim.step(1)
    e0, p0 = sim.energy(), sim.momentum()
    sim.step(2000)
    assert abs(sim.energy() - e0) < 1e-6 * abs(e0)
    assert np.linalg.norm(sim.momentum() - p0) > 1e-3


def test_unpin_lets_it_move_from_rest():
    sim = Simulation(dim=2, integrator="verlet", dt=0.01)
    i = sim.add(mass=1.0, pos=(0.0, 1.0), vel=(1.0, 0.0), pinned=True)
    sim.add_force(forces.UniformGravity(g=(0.0, -1.0)))
    sim.step(10)
    np.testing.assert_array_equal(sim.pos[i], [0.0, 1.0])
    assert sim.kinetic_energy() == 0.0
    sim.unpin(i)
    assert not sim.pinned[i]
    sim.step(10)  # falls from rest: p = p0 + g t^2 / 2 (verlet is exact here)
    np.testing.assert_allclose(sim.pos[i], [0.0, 1.0 - 0.5 * 0.1 ** 2], rtol=0, atol=1e-14)
    np.testing.assert_allclose(sim.vel[i], [0.0, -0.1], rtol=0, atol=1e-14)


@pytest.mark.parametrize("integrator", engine.integrators.ANY_SCENE)
def test_a_velocity_written_into_a_pinned_particle_does_not_move_it(integrator):
    sim, idx, _ = hanging_rope(integrator)
    anchor = sim.pos[0].copy()
    sim.vel[0] = (5.0, -3.0)
    sim.step(3)
    assert sim.pos[0].tobytes() == anchor.tobytes()
    np.testing.assert_array_equal(sim.vel[0], [0.0, 0.0])


def test_an_infinite_mass_is_refused_with_a_hint_to_pin():
    sim, idx, _ = hanging_rope("verlet")
    before = sim.pos.copy()
    sim.mass[3] = math.inf
    with pytest.raises(ValueError, match=r"mass\[3\].*inf.*pin") as err:
        sim.step()
    assert "sim.pin(i)" in str(err.value)
    np.testing.assert_array_equal(sim.pos, before)  # nothing was changed
    assert sim.steps == 0
    sim.mass[3] = 0.01
    sim.pin(3)  # what the message suggests: it holds, and the step runs
    sim.step(10)
    np.testing.assert_array_equal(sim.pos[3], before[3])
    with pytest.raises(ValueError, match="mass"):
        sim.add(mass=math.inf)


def test_batch_pinning_behaves_as_in_a_simulation():
    systems = 3
    batch = Batch(systems=systems, dim=2, integrator="verlet", dt=2e-4)
    x = np.linspace(0.0, 1.0, 11)
    pos = np.column_stack((x, np.zeros_like(x)))
    idx = batch.add_many(mass=0.01, pos=pos, pinned=np.arange(11) == 0)
    pairs = np.column_stack((idx[:-1], idx[1:]))
    batch.add_force(forces.Springs(pairs, k=100.0, rest_length=0.1))
    batch.add_force(forces.UniformGravity(g=(0.0, -9.8)))
    # particle 5 pinned in system 1 only; system 2 gets a velocity written into its anchor
    batch.pin(5, system=1)
    batch.vel[2, 0] = (4.0, 4.0)
    assert batch.pinned[:, 0].all() and list(batch.pinned[:, 5]) == [False, True, False]
    batch.step(1000)
    for m in range(systems):
        assert batch.pos[m, 0].tobytes() == pos[0].tobytes()
    assert batch.pos[1, 5].tobytes() == pos[5].tobytes()
    assert batch.pos[0, 5, 1] < -0.01 and batch.pos[2, 5, 1] < -0.01
    np.testing.assert_array_equal(batch.vel[:, 0], 0.0)
    np.testing.assert_array_equal(batch.pos[0], batch.pos[2])
    # system 1 is bit-identical to the same scene run alone
    sim = Simulation(dim=2, integrator="verlet", dt=2e-4)
    sim.add_many(mass=0.01, pos=pos, pinned=np.arange(11) == 0)
    sim.add_force(forces.Springs(pairs, k=100.0, rest_length=0.1))
    sim.add_force(forces.UniformGravity(g=(0.0, -9.8)))
    sim.pin(5)
    sim.step(1000)
    assert batch.pos[1].tobytes() == sim.pos.tobytes()
    # diagnostics leave the pinned out, per system
    batch.vel[1, 5] = (9.0, 9.0)
    free = ~batch.pinned[1]
    np.testing.assert_allclose(batch.momentum()[1], (0.01 * batch.vel[1][free]).sum(0))
    # unpin in one system: it moves there again
    batch.unpin(5, system=1)
    batch.step(50)
    assert batch.pos[1, 5].tobytes() != pos[5].tobytes()
    assert batch.pos[1, 0].tobytes() == pos[0].tobytes()
    batch.mass[0, 4] = math.inf
    with pytest.raises(ValueError, match="mass"):
        batch.step()


@pytest.mark.parametrize("bad", [-1, 4, 10 ** 6])
def test_an_index_out_of_range_is_a_value_error_naming_it(bad):
    sim = Simulation(dim=2)
    sim.add_many(mass=1.0, pos=np.zeros((4, 2)))
    batch = Batch(systems=2, dim=2)
    batch.add_many(mass=1.0, pos=np.zeros((4, 2)))
    for call in (sim.pin, sim.unpin, batch.pin, batch.unpin):
        with pytest.raises(ValueError, match=rf"got {bad}\b"):
            call(bad)
    with pytest.raises(ValueError, match=r"system .*got 2\b"):
        batch.pin(0, system=2)
    with pytest.raises(ValueError, match=r"system .*got -1\b"):
        batch.unpin(0, system=-1)
    assert not sim.pinned.any() and not batch.pinned.any()


@pytest.mark.parametrize("bad", [1.0, 1.5, "1", True, None, np.float64(2.0)], ids=repr)
def test_an_index_that_is_not_an_int_is_refused_naming_it(bad):
    """Today a ValueError; the engine's rule for text, booleans and None given as numbers is
    a TypeError, so either is accepted here, as long as the message shows the value."""
    sim = Simulation(dim=2)
    sim.add_many(mass=1.0, pos=np.zeros((4, 2)))
    batch = Batch(systems=2, dim=2)
    batch.add_many(mass=1.0, pos=np.zeros((4, 2)))
    calls = [sim.pin, sim.unpin, batch.pin, batch.unpin]
    if bad is not None:  # system=None means every system
        calls.append(lambda v: batch.pin(0, system=v))
    for call in calls:
        with pytest.raises((ValueError, TypeError)) as err:
            call(bad)
        assert repr(bad) in str(err.value)
    assert not sim.pinned.any() and not batch.pinned.any()


def test_pinned_flags_must_be_booleans():
    sim = Simulation(dim=2)
    with pytest.raises(TypeError, match="pinned"):
        sim.add(pos=(0.0, 0.0), pinned="yes")
    with pytest.raises(ValueError, match="pinned"):
        sim.add_many(mass=1.0, pos=np.zeros((3, 2)), pinned=[True, False])
    assert sim.n == 0
