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
    with pytest.raises(TypeError, match=r"n must be an int >= 0, got 1\.5"):
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


# -- step counts and time in the range the compiled code handles -------------------
@pytest.mark.parametrize("n", [2 ** 63, 2 ** 64, 2 ** 62 + 1, True, 1.0, np.float64(2.0), "3",
                               None])
def test_step_count_outside_what_compiled_code_takes_is_refused(sim, n):
    snap = snapshot(sim)
    # Not an int at all (bool, float, text, None): TypeError; an int out of range: ValueError.
    error = ValueError if isinstance(n, int) and not isinstance(n, bool) else TypeError
    with pytest.raises(error, match=r"n must be") as info:
        sim.step(n)
    assert repr(n) in str(info.value) or str(n) in str(info.value)
    assert_unchanged(sim, snap)
    assert type(sim.steps) is int


def test_numpy_int_step_count_is_fine(sim):
    sim.step(np.int64(3))
    assert sim.steps == 3 and type(sim.steps) is int


@pytest.mark.parametrize("integrator", ["leapfrog", "rk4"])
@pytest.mark.parametrize("t_end", [9.3e18, 1e300, -1e300])
def test_integrate_needing_more_steps_than_a_call_takes_is_refused(integrator, t_end):
    sim = Simulation(dim=2, integrator=integrator, dt=1.0)
    sim.add(vel=(1.0, 0.0))
    snap = snapshot(sim)
    with pytest.raises(ValueError, match=r"t_end=.*steps.*2\*\*62"):
        sim.integrate(t_end)
    assert_unchanged(sim, snap)


@pytest.mark.parametrize("t_end", [math.inf, -math.inf, math.nan])
def test_integrate_to_a_non_finite_time_is_refused(sim, t_end):
    snap = snapshot(sim)
    with pytest.raises(ValueError, match="t_end must be finite"):
        sim.integrate(t_end)
    assert_unchanged(sim, snap)


def test_integrate_across_an_interval_that_overflows_is_refused():
    sim = Simulation(dim=2, dt=1e300)
    sim.add()
    sim.t = -1.7e308
    with pytest.raises(ValueError, match="overflows"):
        sim.integrate(1.7e308)
    assert sim.t == -1.7e308 and sim.steps == 0


def test_fixed_steps_that_would_overflow_the_time_are_refused():
    sim = Simulation(dim=2, dt=1e308)
    sim.add(vel=(1.0, 0.0))
    snap = snapshot(sim)
    with pytest.raises(ValueError, match="past the largest float"):
        sim.step(3)
    assert_unchanged(sim, snap)
    assert math.isfinite(sim.t)


def test_rk45_time_overflow_raises_and_keeps_the_last_finite_state():
    # a free particle has zero error estimate: rk45 grows its step 5x per step until t overflows
    sim = Simulation(dim=2, integrator="rk45", dt=1.0)
    sim.add(vel=(1.0, 0.0))
    with pytest.raises(SimulationError, match="largest float") as info:
        sim.step(1000)
    assert info.value.particle is None
    assert math.isfinite(sim.t) and sim.t == info.value.time
    assert np.all(np.isfinite(sim.pos)) and np.all(np.isfinite(sim.vel))
    assert math.isfinite(sim.dt) and sim.dt != 0.0


# -- numbers given as text or booleans, float indices, capacity -------------------
@pytest.mark.parametrize("make, field, shown", [
    (lambda: Simulation(dt="1"), "dt", "'1'"),
    (lambda: Simulation(dt=True), "dt", "True"),
    (lambda: Simulation(G="1"), "G", "'1'"),
    (lambda: Simulation(tolerance=np.True_), "tolerance", "True"),
    (lambda: Simulation().add(mass=True), "mass", "True"),
    (lambda: Simulation().add(mass="1"), "mass", "'1'"),
    (lambda: Simulation().add(charge=False), "charge", "False"),
    (lambda: Simulation().add(radius="0.5"), "radius", "'0.5'"),
    (lambda: Simulation().add(pos=("1", "2")), "pos", "'1'"),
    (lambda: Simulation().add(vel=(True, 0.0)), "vel", "True"),
    (lambda: Simulation().add(pos=(1j, 0.0)), "pos", "1j"),
    (lambda: forces.UniformGravity(g=("0", "-1")), "g", "'0'"),
    (lambda: forces.Springs([(0, 1)], k="10"), "k", "'10'"),
    (lambda: forces.Drag(linear=True), "linear", "True"),
    (lambda: forces.Springs(pairs=[(0.0, 1.0)]), "pairs", "0.0"),
    (lambda: forces.Springs(pairs=[(True, False)]), "pairs", "True"),
    (lambda: forces.Springs(pairs=[("0", "1")]), "pairs", "'0'"),
    (lambda: forces.Springs(pairs=np.array([[0.0, 1.0]])), "pairs", "0.0"),
    (lambda: forces.Wind(w=(1.0, 0.0, 0.0), triangles=[(0, 1, 2.0)]), "triangles", "0.0"),
    (lambda: forces.PointMass(particles=[0.0, 1.0]), "particles", "0.0"),
    (lambda: forces.PointMass(particles=[True]), "particles", "True"),
    (lambda: Simulation(capacity=math.nan), "capacity", "nan"),
    (lambda: Simulation(capacity=1.5), "capacity", "1.5"),
    (lambda: Simulation(capacity=True), "capacity", "True"),
    (lambda: Simulation(capacity=-1), "capacity", "-1"),
    (lambda: Simulation(capacity="16"), "capacity", "'16'"),
])
def test_text_booleans_float_indices_and_bad_capacity_are_refused(make, field, shown):
    with pytest.raises((TypeError, ValueError)) as info:
        make()
    message = str(info.value)
    assert field in message and shown in message, message


def test_text_time_setter_leaves_time(sim):
    with pytest.raises(TypeError, match=r"t must be a real number, got '1'"):
        sim.t = "1"
    assert sim.t == 0.0
    with pytest.raises(TypeError, match=r"dt .*'0.5'"):
        sim.dt = "0.5"
    assert sim.dt == 0.1


def test_huge_spring_index_is_a_clear_error():
    with pytest.raises(ValueError, match="pairs"):
        forces.Springs(pairs=[(0, 2 ** 70)])


# -- index arrays of force terms are read-only and re-checked when packed ----------
def _index_terms():
    s3 = Simulation(dim=3)
    s3.add_many(mass=1.0, pos=np.eye(3))
    springs = s3.add_force(forces.Springs(pairs=[(0, 1), (1, 2)]))
    wind = s3.add_force(forces.Wind(w=(0.0, 0.0, 1.0), triangles=[(0, 1, 2)]))
    star = s3.add_force(forces.PointMass(pos=(0.0, 0.0, 5.0), particles=[0, 2]))
    return s3, springs, wind, star


@pytest.mark.parametrize("write", [
    lambda sp, w, pm: sp.pairs.__setitem__((0, 1), 10 ** 12),
    lambda sp, w, pm: sp.pairs.reshape(-1).__setitem__(0, -5),
    lambda sp, w, pm: w.triangles.__setitem__((0, 2), 10 ** 12),
    lambda sp, w, pm: pm.particles.__setitem__(0, 10 ** 12),
    lambda sp, w, pm: sp.k.__setitem__(0, -1.0),
    lambda sp, w, pm: sp.rest_length.__setitem__(0, math.nan),
    lambda sp, w, pm: sp.damping.__setitem__(0, -1.0),
])
def test_force_arrays_cannot_be_written_in_place(write):
    s3, springs, wind, star = _index_terms()
    with pytest.raises(ValueError, match="read-only"):
        write(springs, wind, star)
    s3.step(2)  # still a valid model
    assert np.all(np.isfinite(s3.pos))


def test_caller_array_keeps_its_flags():
    pairs = np.array([[0, 1]])
    forces.Springs(pairs=pairs)
    pairs[0, 1] = 2  # the caller's own array is not made read-only (the term holds a copy)
    assert pairs.flags.writeable


@pytest.mark.parametrize("attr, bad", [
    ("pairs", np.array([[0, 10 ** 12]])),
    ("triangles", np.array([[0, 1, 10 ** 12]])),
    ("particles", np.array([-7])),
])
def test_index_arrays_are_rechecked_when_the_model_is_packed(attr, bad):
    s3, springs, wind, star = _index_terms()
    term = {"pairs": springs, "triangles": wind, "particles": star}[attr]
    object.__setattr__(term, attr, bad)  # bypass every public guard
    before = (s3.pos.copy(), s3.vel.copy(), s3.t)
    with pytest.raises(ValueError, match=rf"{attr}\[0\].*out of range"):
        s3.step()
    np.testing.assert_array_equal(s3.pos, before[0])
    np.testing.assert_array_equal(s3.vel, before[1])
    assert s3.t == before[2]


# -- non-finite values written into the state arrays are bad input ------------------
@pytest.mark.parametrize("field, write", [
    ("mass", lambda s: s.mass.__setitem__(0, math.nan)),
    ("mass", lambda s: s.mass.__setitem__(1, math.inf)),
    ("charge", lambda s: s.charge.__setitem__(1, math.nan)),
    ("radius", lambda s: s.radius.__setitem__(0, math.nan)),
    ("radius", lambda s: s.radius.__setitem__(0, -1.0)),
    ("pos", lambda s: s.pos.__setitem__((0, 1), math.nan)),
    ("vel", lambda s: s.vel.__setitem__((1, 0), math.inf)),
])
@pytest.mark.parametrize("integrator", ["leapfrog", "rk45"])
def test_non_finite_written_into_state_is_named_as_that_field(field, write, integrator):
    sim = Simulation(dim=2, integrator=integrator, dt=0.01)
    sim.add(mass=1.0, pos=(1.0, 0.0), vel=(0.0, 1.0), radius=0.1)
    sim.add(mass=2.0, pos=(-1.0, 0.0), radius=0.1, charge=1.0)
    sim.add_force(forces.NBodyGravity())
    sim.add_force(forces.Coulomb())
    write(sim)
    snap = (sim.pos.copy(), sim.vel.copy(), sim.mass.copy(), sim.charge.copy(),
            sim.radius.copy(), sim.t, sim.steps, sim.dt)
    with pytest.raises(ValueError) as info:
        sim.step(5)
    assert not isinstance(info.value, SimulationError)
    message = str(info.value)
    assert field in message and "bad input" in message, message
    after = (sim.pos, sim.vel, sim.mass, sim.charge, sim.radius, sim.t, sim.steps, sim.dt)
    for a, b in zip(snap, after):
        np.testing.assert_array_equal(a, b)
    with pytest.raises(ValueError, match=field):
        sim.integrate(1.0)


def test_absurd_capacity_is_named():
    import pytest as _pytest
    from engine import Simulation as _Simulation

    with _pytest.raises(ValueError, match=r"capacity must be an int in \[0, 2147483648\], got 10{30}"):
        _Simulation(dim=2, capacity=10 ** 30)
