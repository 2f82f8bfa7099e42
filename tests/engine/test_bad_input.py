"""Bad input raises a clear error naming the field and value, before anything changes;
a numerical blow-up raises SimulationError and keeps the last finite state."""
import math

import numpy as np
import pytest

import engine
from engine import Simulation, SimulationError, forces


def snapshot(sim):
    return (sim.pos.copy(), sim.vel.copy(), sim.mass.copy(), sim.t, sim.n, sim.steps, sim.dt,
            len(sim.forces))


def assert_unchanged(sim, snap):
    after = snapshot(sim)
    for a, b in zip(snap, after):
        np.testing.assert_array_equal(a, b)


@pytest.fixture
def sim():
    s = Simulation(dim=2, integrator="leapfrog", dt=0.1)
    s.add(mass=1.0, pos=(1.0, 0.0), vel=(0.0, 1.0))
    s.add(mass=2.0, pos=(-1.0, 0.0))
    return s


@pytest.mark.parametrize("kwargs, field", [
    (dict(pos=(math.nan, 0.0)), "pos"),
    (dict(pos=(math.inf, 0.0)), "pos"),
    (dict(vel=(0.0, -math.inf)), "vel"),
    (dict(vel=(0.0, math.nan)), "vel"),
    (dict(mass=-1.0), "mass"),
    (dict(mass=math.nan), "mass"),
    (dict(pos=(1.0, 2.0, 3.0)), "pos"),
    (dict(pos=(1.0,)), "pos"),
    (dict(vel=(1.0, 2.0, 3.0)), "vel"),
    (dict(radius=-0.5), "radius"),
    (dict(charge=math.inf), "charge"),
])
def test_bad_particle_is_refused_before_any_change(sim, kwargs, field):
    snap = snapshot(sim)
    with pytest.raises((ValueError, TypeError)) as info:
        sim.add(**kwargs)
    message = str(info.value)
    assert field in message
    value = next(iter(kwargs.values()))
    shown = value if not isinstance(value, tuple) else value[0]
    assert repr(shown) in message or str(shown) in message
    assert_unchanged(sim, snap)


def test_bad_batch_is_refused_whole(sim):
    snap = snapshot(sim)
    with pytest.raises(ValueError, match=r"mass.*-3.0.*particle 2"):
        sim.add_many(mass=[1.0, 1.0, -3.0], pos=np.zeros((3, 2)))
    assert_unchanged(sim, snap)


def test_non_numeric_is_a_type_error(sim):
    with pytest.raises(TypeError, match="pos"):
        sim.add(pos=("a", "b"))


@pytest.mark.parametrize("dt", [0.0, math.nan, math.inf, -math.inf])
def test_bad_dt(dt):
    with pytest.raises(ValueError, match="dt"):
        Simulation(dt=dt)


def test_bad_dt_setter_leaves_dt(sim):
    with pytest.raises(ValueError, match=r"dt.*0\.0"):
        sim.dt = 0.0
    assert sim.dt == 0.1


def test_unknown_integrator_lists_the_known_ones():
    with pytest.raises(ValueError, match=r"integrator must be one of .*leapfrog.*got 'rk5'"):
        Simulation(integrator="rk5")


def test_unknown_integrator_setter(sim):
    with pytest.raises(ValueError, match="integrator"):
        sim.integrator = "midpoint"
    assert sim.integrator == "leapfrog"


@pytest.mark.parametrize("tolerance", [0.0, -1e-9, math.nan])
def test_bad_tolerance(tolerance):
    with pytest.raises(ValueError, match="tolerance"):
        Simulation(integrator="rk45", tolerance=tolerance)


@pytest.mark.parametrize("dim", [1, 4, True, "2"])
def test_bad_dim(dim):
    with pytest.raises(ValueError, match="dim"):
        Simulation(dim=dim)


@pytest.mark.parametrize("make, field", [
    (lambda: forces.NBodyGravity(softening=-0.1), "softening"),
    (lambda: forces.NBodyGravity(G=math.nan), "G"),
    (lambda: forces.Coulomb(softening=-1.0), "softening"),
    (lambda: forces.Coulomb(k=math.inf), "k"),
    (lambda: forces.PointMass(mu=0.0), "mu"),
    (lambda: forces.PointMass(softening=-1.0), "softening"),
    (lambda: forces.PointMass(pos=(0.0, math.nan)), "pos"),
    (lambda: forces.UniformGravity(g=(0.0, 1.0, 2.0, 3.0)), "g"),
    (lambda: forces.Springs([(0, 1)], k=-1.0), "k"),
    (lambda: forces.Springs([(0, 1)], rest_length=-1.0), "rest_length"),
    (lambda: forces.Springs([(0, 1)], damping=-0.1), "damping"),
    (lambda: forces.Springs([(0, 1), (1, 2)], k=[1.0, 2.0, 3.0]), "k"),
    (lambda: forces.Springs([(0, 0)]), "itself"),
    (lambda: forces.Springs([(0, 1, 2)]), "pairs"),
    (lambda: forces.Drag(linear=-1.0), "linear"),
    (lambda: forces.Drag(quadratic=math.nan), "quadratic"),
    (lambda: forces.Buoyancy(density=-1.0), "density"),
    (lambda: forces.Buoyancy(up=5), "up"),
    (lambda: forces.Blast(center=(0, 0), strength=1.0, scale=0.0), "scale"),
    (lambda: forces.Blast(center=(0, 0), strength=1.0, duration=0.0), "duration"),
    (lambda: forces.Wind(w=(1.0, 0.0), triangles=[(0, 1, 2)]), "w"),
])
def test_bad_force_parameters(make, field):
    with pytest.raises(ValueError, match=field):
        make()


def test_spring_indices_checked_when_added(sim):
    snap = snapshot(sim)
    with pytest.raises(ValueError, match=r"pairs\[1\]\[1\] = 5 is out of range.*2 particles"):
        sim.add_force(forces.Springs([(0, 1), (1, 5)]))
    with pytest.raises(ValueError, match="out of range"):
        sim.add_force(forces.Springs([(-1, 1)]))
    assert_unchanged(sim, snap)


def test_force_dimension_checked_when_added(sim):
    with pytest.raises(ValueError, match="PointMass pos must have length 2"):
        sim.add_force(forces.PointMass(pos=(0.0, 0.0, 0.0)))
    with pytest.raises(ValueError, match="dim=3"):
        sim.add_force(forces.Wind(w=(1.0, 0.0, 0.0), triangles=[(0, 1, 0)]))
    assert sim.forces == ()


def test_same_force_twice_and_foreign_objects(sim):
    g = sim.add_force(forces.NBodyGravity())
    with pytest.raises(ValueError, match="already declared"):
        sim.add_force(g)
    with pytest.raises(TypeError, match="force"):
        sim.add_force(lambda pos: pos)


def test_thrust_bad_index_and_vector(sim):
    thrust = forces.Thrust()
    with pytest.raises(ValueError, match="add the Thrust"):
        thrust.set(0, (1.0, 0.0))
    sim.add_force(thrust)
    with pytest.raises(ValueError, match=r"index.*7"):
        thrust.set(7, (1.0, 0.0))
    with pytest.raises(ValueError, match="force must have length 2"):
        thrust.set(0, (1.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="force must be finite"):
        thrust.set(0, (math.nan, 0.0))


def test_bad_step_count_and_target(sim):
    with pytest.raises(ValueError, match=r"n must be an int >= 0, got -1"):
        sim.step(-1)
    with pytest.raises(ValueError, match="n must be"):
        sim.step(1.5)
    with pytest.raises(ValueError, match="t_end"):
        sim.integrate(math.nan)


def test_bad_particle_index(sim):
    with pytest.raises(ValueError, match=r"index.*\[0, 2\).*9"):
        sim.deactivate(9)


def test_state_corrupted_by_hand_is_refused_before_stepping(sim):
    sim.add_force(forces.NBodyGravity())
    sim.pos[1, 0] = math.nan
    with pytest.raises(ValueError, match="particle 1 has a non-finite pos or vel"):
        sim.step()
    assert sim.steps == 0 and sim.t == 0.0


# -- blow-ups --------------------------------------------------------------------------
@pytest.mark.parametrize("integrator", engine.INTEGRATORS)
def test_coincident_particles_without_softening_raise(integrator):
    sim = Simulation(dim=2, integrator=integrator, dt=0.01)
    sim.add(mass=1.0, pos=(0.5, 0.5))  # at rest: a first drift cannot separate them
    sim.add(mass=1.0, pos=(0.5, 0.5))
    sim.add_force(forces.NBodyGravity())
    before = snapshot(sim)
    with pytest.raises(SimulationError) as info:
        sim.step(10)
    err = info.value
    assert err.step == 0 and err.time == 0.0 and err.particle in (0, 1)
    assert "non-finite" in str(err) or "collapsed" in str(err)
    assert_unchanged(sim, before)


def test_coincident_particles_with_softening_are_fine():
    sim = Simulation(dim=2, integrator="leapfrog", dt=0.01)
    sim.add(mass=1.0, pos=(0.5, 0.5))
    sim.add(mass=1.0, pos=(0.5, 0.5))
    sim.add_force(forces.NBodyGravity(softening=0.1))
    sim.step(10)
    assert np.all(np.isfinite(sim.pos))


@pytest.mark.parametrize("integrator", ["euler", "symplectic_euler", "leapfrog", "rk4"])
def test_stiff_spring_beyond_the_step_limit_blows_up_and_keeps_last_finite_state(integrator):
    # omega = sqrt(k (1/m1 + 1/m2)) = 1e3; explicit methods need dt < ~2/omega = 2e-3
    sim = Simulation(dim=2, integrator=integrator, dt=0.05)
    sim.add_many(mass=1.0, pos=[(0.0, 0.0), (1.1, 0.0)])
    sim.add_force(forces.Springs([(0, 1)], k=5e5, rest_length=1.0))
    with pytest.raises(SimulationError) as info:
        sim.step(100_000)
    err = info.value
    assert 0 < err.step < 100_000
    assert sim.steps == err.step and sim.t == pytest.approx(err.time)
    assert sim.t == pytest.approx(err.step * 0.05)
    assert np.all(np.isfinite(sim.pos)) and np.all(np.isfinite(sim.vel))
    assert np.abs(sim.pos).max() > 1e10  # it really was running away
    assert err.particle in (0, 1)


def test_massless_particle_pushed_by_a_force_fails_loudly():
    sim = Simulation(dim=2)
    i = sim.add(mass=0.0)
    thrust = sim.add_force(forces.Thrust())
    sim.step()  # no force, no problem
    thrust.set(i, (1.0, 0.0))
    with pytest.raises(SimulationError, match="particle 0"):
        sim.step()


def test_rk45_impossible_tolerance_reports_collapse():
    sim = Simulation(dim=2, integrator="rk45", dt=0.1, tolerance=1e-300)
    sim.add(mass=1.0, pos=(1.0, 0.0), vel=(0.0, 1.0))
    sim.add_force(forces.PointMass())
    with pytest.raises(SimulationError, match="collapsed"):
        sim.step(5)
    assert np.all(np.isfinite(sim.pos))
