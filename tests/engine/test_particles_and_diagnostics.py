"""Particle storage (add, deactivate, grow, views) and the conserved quantities."""
import math

import numpy as np
import pytest

from engine import Simulation, forces


def test_views_write_through_and_have_public_shapes():
    sim = Simulation(dim=3)
    sim.add_many(mass=[1.0, 2.0], pos=[(1, 2, 3), (4, 5, 6)], vel=[(0, 0, 1), (0, 1, 0)])
    assert sim.pos.shape == (2, 3) and sim.vel.shape == (2, 3) and sim.mass.shape == (2,)
    sim.pos[1] = (7, 8, 9)
    sim.vel[0, 2] = 5.0
    np.testing.assert_array_equal(sim.pos, [(1, 2, 3), (7, 8, 9)])
    assert sim.vel[0, 2] == 5.0
    with pytest.raises(ValueError):
        sim.active[0] = False  # read-only: use deactivate()


def test_capacity_grows_without_losing_state_or_forces():
    def run(capacity):
        sim = Simulation(dim=2, integrator="leapfrog", dt=0.01, capacity=capacity)
        sim.add_force(forces.NBodyGravity(softening=0.1))
        for k in range(50):
            sim.add(mass=1.0, pos=(math.cos(k), math.sin(k)), vel=(0.0, 0.1 * k))
            sim.step(2)
        return sim
    grown, roomy = run(2), run(64)
    assert grown.n == 50 and grown.capacity >= 50 and roomy.capacity == 64
    assert grown.pos.tobytes() == roomy.pos.tobytes()
    assert grown.vel.tobytes() == roomy.vel.tobytes()


def test_torpedoes_appear_and_vanish_between_steps():
    """A deactivated particle freezes and drops out of forces and diagnostics."""
    sim = Simulation(dim=2, integrator="symplectic_euler", dt=0.1)
    ship = sim.add(mass=1.0, pos=(1.0, 0.0), vel=(0.0, 1.0))
    sim.add_force(forces.PointMass(mu=1.0))
    sim.step(5)
    torpedo = sim.add(mass=0.01, pos=sim.pos[ship] + (0.1, 0.0), vel=sim.vel[ship] * 2, test=True)
    sim.step(5)
    frozen = sim.pos[torpedo].copy()
    k_before = sim.kinetic_energy()
    sim.deactivate(torpedo)
    assert sim.kinetic_energy() < k_before
    sim.step(5)
    np.testing.assert_array_equal(sim.pos[torpedo], frozen)
    sim.activate(torpedo)
    sim.step(1)
    assert not np.array_equal(sim.pos[torpedo], frozen)


def test_two_body_conserves_momentum_angular_momentum_and_energy():
    sim = Simulation(dim=3, integrator="yoshida4", dt=1e-3)
    sim.add(mass=3.0, pos=(0.0, 0.0, 0.0), vel=(0.0, -0.1, 0.02))
    sim.add(mass=1.0, pos=(1.0, 0.0, 0.1), vel=(0.0, 1.5, 0.0))
    sim.add_force(forces.NBodyGravity())
    p0, L0, E0 = sim.momentum(), sim.angular_momentum(), sim.energy()
    sim.step(20_000)
    np.testing.assert_allclose(sim.momentum(), p0, atol=1e-13)
    np.testing.assert_allclose(sim.angular_momentum(), L0, rtol=1e-11, atol=1e-13)
    assert sim.energy() == pytest.approx(E0, rel=1e-8)


def test_diagnostics_hand_computed_2d():
    sim = Simulation(dim=2)
    sim.add(mass=2.0, pos=(1.0, 0.0), vel=(0.0, 3.0))
    sim.add(mass=1.0, pos=(0.0, 2.0), vel=(1.0, 0.0))
    assert sim.kinetic_energy() == pytest.approx(0.5 * 2 * 9 + 0.5 * 1 * 1)
    np.testing.assert_allclose(sim.momentum(), (1.0, 6.0))
    # L_z = sum m (x vy - y vx) = 2 * 3 + 1 * (0 - 2)
    assert sim.angular_momentum() == pytest.approx(4.0)
    com, vcom = sim.center_of_mass()
    np.testing.assert_allclose(com, (2 / 3, 2 / 3))
    np.testing.assert_allclose(vcom, (1 / 3, 2.0))


def test_potential_energy_per_term_in_declaration_order():
    sim = Simulation(dim=2)
    sim.add(mass=2.0, pos=(0.0, 3.0))
    sim.add(mass=1.0, pos=(4.0, 0.0))
    sim.add_force(forces.UniformGravity(g=(0.0, -1.0)))
    sim.add_force(forces.Drag(linear=1.0))
    sim.add_force(forces.NBodyGravity())
    np.testing.assert_allclose(sim.potential_energy_terms(), [6.0, 0.0, -2.0 / 5.0])
    assert sim.potential_energy() == pytest.approx(6.0 - 0.4)


def test_remove_force_stops_it_acting():
    sim = Simulation(dim=2, dt=1.0)
    sim.add(mass=1.0)
    g = sim.add_force(forces.UniformGravity(g=(0.0, -1.0)))
    sim.step()
    sim.remove_force(g)
    sim.step()
    np.testing.assert_array_equal(sim.vel[0], (0.0, -1.0))
    with pytest.raises(ValueError, match="not declared"):
        sim.remove_force(g)


def test_determinism_bit_identical():
    def run():
        rng = np.random.default_rng(42)
        sim = Simulation(dim=3, integrator="pefrl", dt=1e-3)
        sim.add_many(mass=rng.uniform(0.1, 1, 20), pos=rng.normal(size=(20, 3)),
                     vel=rng.normal(size=(20, 3)) * 0.1, charge=rng.normal(size=20))
        sim.add_force(forces.NBodyGravity(softening=0.05))
        sim.add_force(forces.Coulomb(k=0.1, softening=0.05))
        sim.step(500)
        return sim.pos.copy(), sim.vel.copy()
    a, b = run(), run()
    assert a[0].tobytes() == b[0].tobytes() and a[1].tobytes() == b[1].tobytes()
