"""whfast: Wisdom-Holman splitting with Kepler drifts (engine/integrators/wisdom_holman.py).

Held to REBOUND's WHFast step for step (same algorithm, same step), to the closed-form Kepler
solution (a pure two-body problem is exact at any step), and to its convergence order."""
import math

import numpy as np
import pytest

import engine
from engine import Simulation, analytic, forces
from engine.integrators import wisdom_holman
from validation import problems

SOLAR_DT = 50.0  # days: about 87 steps per Jupiter orbit


def solar(corrector=0, kernel="standard", dt=SOLAR_DT):
    sim = problems.make_sim(problems.outer_solar_system(), "whfast", dt)
    sim.corrector = corrector
    sim.kernel = kernel
    return sim


def rebound_solar(corrector, kernel, steps, dt=SOLAR_DT, coordinates=None):
    p = problems.outer_solar_system()
    # imported here, not at module level: the tests that never use REBOUND run without it
    rebound = pytest.importorskip("rebound")
    r = rebound.Simulation()
    r.G = p.G
    for m, x, v in zip(p.mass, p.pos, p.vel):
        r.add(m=m, x=x[0], y=x[1], z=x[2], vx=v[0], vy=v[1], vz=v[2])
    r.integrator = "whfast"
    r.dt = dt
    r.integrator.corrector = corrector
    r.integrator.kernel = "default" if kernel == "standard" else kernel
    r.integrator.safe_mode = 0
    if coordinates is not None:
        r.integrator.coordinates = coordinates
    if kernel == "lazy":
        r.gravity = "jacobi"  # REBOUND's lazy kernel kicks with the Jacobi interaction term
    r.steps(steps)
    r.synchronize()
    return np.array([[q.x, q.y, q.z] for q in r.particles])


@pytest.mark.parametrize("corrector", wisdom_holman.CORRECTORS)
@pytest.mark.parametrize("kernel", ["standard", "lazy"])
def test_same_algorithm_same_step_as_rebound(corrector, kernel):
    """1000 steps of the outer solar system: the largest position difference measured, over
    the largest coordinate, was 1.9e-14 to 9.7e-14 with the standard kernel and 4.0e-13 to
    4.8e-13 with the lazy one (REBOUND computes the Jacobi interaction term its own way)."""
    sim = solar(corrector, kernel)
    sim.step(1000)
    theirs = rebound_solar(corrector, kernel, 1000)
    scale = np.abs(theirs).max()
    assert np.abs(sim.pos - theirs).max() / scale < (1e-12 if kernel == "standard" else 5e-12)
    # the corrector and kernel are really applied: the answer moves far more than that
    plain = solar()
    plain.step(1000)
    if corrector or kernel == "lazy":
        assert np.abs(plain.pos - sim.pos).max() / scale > 1e-9


def kepler_orbit(e, mu=1.0):
    """Periapsis state of an orbit of eccentricity e and a = 1."""
    q = 1.0 - e
    return np.array([q, 0.0, 0.0]), np.array([0.0, math.sqrt(mu * (1 + e) / q), 0.0])


@pytest.mark.parametrize("dt_over_period", [0.013, 0.37, 2.9])
def test_two_body_is_exact_at_any_step_about_an_attractor(dt_over_period):
    r0, v0 = kepler_orbit(0.9)
    sim = Simulation(dim=3, integrator="whfast", dt=dt_over_period * 2 * math.pi)
    sim.add(mass=1e-3, pos=r0, vel=v0)
    sim.add_force(forces.PointMass(mu=1.0, pos=(0.0, 0.0, 0.0)))
    sim.step(50)
    r, v = analytic.kepler(r0, v0, 1.0, sim.t)
    # round-off of 50 chained Kepler solves at e = 0.9, which depends on the processor the
    # drift is compiled for (its multiply-adds): from periapsis, at dt = 2.9 P, 1.2e-11 to
    # 2.1e-11 in position and 2.9e-10 to 4.8e-10 in velocity (|v| = 4.4 there) for generic
    # x86-64, Haswell and AVX-512 code; over 24 starting phases of the orbit at dt = 0.37 P
    # and 2.9 P, up to 1.7e-10 and 2.3e-9. A wrong period or drift is off by far more
    np.testing.assert_allclose(sim.pos[0], r, rtol=0, atol=3e-10)
    np.testing.assert_allclose(sim.vel[0], v, rtol=0, atol=4e-9)


@pytest.mark.parametrize("corrector", [0, 17])
def test_two_body_is_exact_at_any_step_in_jacobi_coordinates(corrector):
    """Two comparable masses (no dominance needed for two): the relative orbit is Kepler's
    with mu = G (m0 + m1), the centre of mass moves in a straight line."""
    m0, m1 = 1.0, 0.6
    r0, v0 = kepler_orbit(0.9, mu=m0 + m1)
    sim = Simulation(dim=3, integrator="whfast", dt=1.3, corrector=corrector)
    sim.add(mass=m0, pos=(0.1, 0.2, 0.0), vel=(0.01, 0.0, 0.02))
    sim.add(mass=m1, pos=(0.1, 0.2, 0.0) + r0, vel=(0.01, 0.0, 0.02) + v0)
    sim.add_force(forces.NBodyGravity())
    com0 = sim.center_of_mass()
    sim.step(40)
    r, v = analytic.kepler(r0, v0, m0 + m1, sim.t)
    # round-off of 40 chained Kepler solves and Jacobi transforms (measured up to 5e-11)
    np.testing.assert_allclose(sim.pos[1] - sim.pos[0], r, rtol=0, atol=2e-10)
    np.testing.assert_allclose(sim.vel[1] - sim.vel[0], v, rtol=0, atol=2e-10)
    com = sim.center_of_mass()
    np.testing.assert_allclose(com[0], com0[0] + sim.t * com0[1], rtol=1e-13, atol=1e-13)


def perturbed(dt, corrector=0, t_end=60.0):
    """A star, a planet of mass 1e-3 at a = 1 and a test particle at a = 1.6 (e = 0.1)."""
    sim = Simulation(dim=2, integrator="whfast", dt=dt, corrector=corrector)
    sim.add(mass=1.0, pos=(0.0, 0.0))
    sim.add(mass=1e-3, pos=(1.0, 0.0), vel=(0.0, 1.0005))
    sim.add(mass=0.0, pos=(-1.44, 0.0), vel=(0.0, -math.sqrt(1.0 * 1.1 / 1.44)), test=True)
    sim.add_force(forces.NBodyGravity())
    sim.integrate(t_end)
    return sim.pos.copy()


def test_second_order_convergence_and_the_corrector_on_a_perturbed_kepler_problem():
    reference = perturbed(2 * math.pi / 2000, corrector=17)
    steps = [2 * math.pi / k for k in (40, 80, 160)]
    errors = [np.abs(perturbed(h) - reference).max() for h in steps]
    slopes = np.diff(np.log(errors)) / np.diff(np.log(steps))
    assert np.all(np.abs(slopes - 2.0) < 0.25), slopes
    # the corrector takes away the O(eps h^2) error: what remains is O(eps^2 h^2)
    corrected = np.abs(perturbed(steps[0], corrector=11) - reference).max()
    assert corrected < errors[0] / 20, (corrected, errors[0])  # measured 41x


def test_energy_error_of_the_outer_solar_system_is_bounded_and_the_corrector_shrinks_it():
    sim = solar()
    e0 = sim.energy()
    worst = 0.0
    for _ in range(40):
        sim.step(50)  # 2000 steps, 1e5 days
        worst = max(worst, abs(sim.energy() / e0 - 1.0))
    assert worst < 1e-6
    corrected = solar(corrector=17)
    corrected.step(2000)
    assert abs(corrected.energy() / e0 - 1.0) < worst / 100


def test_other_terms_enter_in_the_kick():
    """A test particle about a star with weak linear drag, against rk45 at a tight tolerance:
    second order in h (the drag is in the kick, taken at the kick's midpoint velocity)."""
    def run(integrator, dt, tol=1e-9):
        sim = Simulation(dim=2, integrator=integrator, dt=dt, tolerance=tol)
        sim.add(mass=1.0, pos=(1.0, 0.0), vel=(0.0, 1.1))
        sim.add_force(forces.PointMass(mu=1.0))
        sim.add_force(forces.Drag(linear=1e-3))
        sim.integrate(20.0)
        return sim.pos[0].copy()
    reference = run("rk45", 1e-3, 1e-13)
    e1 = np.abs(run("whfast", 0.02) - reference).max()
    e2 = np.abs(run("whfast", 0.01) - reference).max()
    assert 3.0 < e1 / e2 < 5.0
    assert e1 < 1e-6


def test_a_star_in_a_periodic_space():
    """Spacewar's arrangement: the attractor acts from its nearest image, and the drift stays
    on the torus; an orbit well inside the box is the open-space orbit to round-off."""
    def run(box):
        sim = Simulation(dim=2, integrator="whfast", dt=0.05, box=box)
        sim.add(mass=1.0, pos=(0.1, 0.0), vel=(0.0, 3.0))
        sim.add_force(forces.PointMass(mu=1.0))
        sim.step(200)
        return sim.pos[0].copy()
    np.testing.assert_allclose(run(4.0), run(None), rtol=0, atol=1e-13)
    sim = Simulation(dim=2, integrator="whfast", dt=0.05, box=1.0)
    sim.add(mass=1.0, pos=(0.3, 0.0), vel=(0.0, 9.0))  # escapes, crosses the edges
    sim.add_force(forces.PointMass(mu=1.0))
    sim.step(100)
    assert np.all(sim.pos >= -0.5) and np.all(sim.pos < 0.5)


# -- scenes whfast does not take: refused before anything changes ----------------------------------

def _state(sim):
    return sim.pos.copy(), sim.vel.copy(), sim.t, sim.steps


def _refused(sim, match):
    before = _state(sim)
    with pytest.raises(ValueError, match=match):
        sim.step(3)
    after = _state(sim)
    assert all(np.array_equal(a, b) for a, b in zip(before, after))


def test_a_scene_without_a_dominant_mass_is_refused_with_the_reason():
    sim = problems.make_sim(problems.pythagorean(), "whfast", 1e-3)
    _refused(sim, r"whfast needs a dominant mass: the heaviest body \(particle 2, mass 5.0\) "
                  "carries less than 10 times the other bodies' 7.0")
    sim = Simulation(dim=2, integrator="whfast")
    sim.add(mass=1.0, pos=(0.0, 0.0))
    sim.add_force(forces.UniformGravity(g=(0.0, -1.0)))
    _refused(sim, "whfast needs a dominant mass to drift about: declare a PointMass")


def test_softened_or_doubled_attractors_and_pinned_bodies_are_refused():
    sim = Simulation(dim=2, integrator="whfast")
    sim.add(mass=1.0, pos=(1.0, 0.0), vel=(0.0, 1.0))
    sim.add_force(forces.PointMass(mu=1.0, softening=0.1))
    _refused(sim, "its softening must be 0, got 0.1")
    sim = Simulation(dim=2, integrator="whfast")
    sim.add(mass=1.0, pos=(1.0, 0.0), vel=(0.0, 1.0))
    sim.add_force(forces.PointMass(mu=1.0))
    sim.add_force(forces.PointMass(mu=1.0, pos=(3.0, 0.0)))
    _refused(sim, "whfast drifts about one attractor; this scene declares 2 PointMass terms")
    sim = Simulation(dim=2, integrator="whfast")
    sim.add(mass=1.0, pos=(0.0, 0.0), pinned=True)
    sim.add(mass=1e-3, pos=(1.0, 0.0), vel=(0.0, 1.0))
    sim.add_force(forces.NBodyGravity())
    _refused(sim, "particle 0 is pinned")
    sim = Simulation(dim=2, integrator="whfast", box=10.0)
    sim.add(mass=1.0, pos=(0.0, 0.0))
    sim.add(mass=1e-3, pos=(1.0, 0.0), vel=(0.0, 1.0))
    sim.add_force(forces.NBodyGravity())
    _refused(sim, "needs open space, got box=10.0")


def test_options_are_checked():
    with pytest.raises(ValueError, match=r"corrector must be one of \(0, 3, 5, 7, 11, 17\), got 4"):
        Simulation(integrator="whfast", corrector=4)
    with pytest.raises(ValueError, match="kernel must be one of 'standard', 'lazy', got 'fast'"):
        Simulation(integrator="whfast", kernel="fast")
    with pytest.raises(ValueError, match="integrator 'whfast' is not available in a Batch"):
        engine.Batch(systems=2, integrator="whfast")


def _dragged(steps):
    sim = Simulation(dim=2, integrator="whfast", dt=0.1)
    sim.add(mass=1.0, pos=(1.0, 0.0), vel=(0.0, 1.0))
    sim.add_force(forces.PointMass(mu=1.0))
    sim.add_force(forces.Drag(quadratic=50.0))  # h c |v| / m = 5: the kick overshoots, grows
    if steps:
        sim.step(steps)
    return sim


def test_a_blow_up_keeps_the_last_finite_state():
    sim = _dragged(0)
    with pytest.raises(engine.SimulationError) as info:
        sim.step(50)
    k = info.value.step
    assert 0 < k < 50 and sim.steps == k
    assert np.all(np.isfinite(sim.pos)) and np.all(np.isfinite(sim.vel))
    assert sim.t == _dragged(k).t
    # (the state of step k is recovered by drifting back the half drift the failed step began
    # with: equal to a run of k steps to round-off, not bit for bit)
    # a failing first step changes nothing
    sim = Simulation(dim=2, integrator="whfast", dt=0.1)
    sim.add(mass=1.0, pos=(0.0, 0.0))
    sim.add(mass=1.0, pos=(0.0, 0.0))
    sim.add_force(forces.NBodyGravity())
    before = _state(sim)
    with pytest.raises(engine.SimulationError):
        sim.step(5)
    assert all(np.array_equal(a, b) for a, b in zip(before, _state(sim)))


# -- democratic heliocentric coordinates -----------------------------------------------------------
def solar_democratic(dt=SOLAR_DT, extra=None):
    sim = problems.make_sim(problems.outer_solar_system(), "whfast", dt)
    sim.coordinates = "democratic_heliocentric"
    if extra is not None:
        sim.add_force(extra)
    return sim


def test_democratic_heliocentric_is_rebounds_step_for_step():
    """1000 steps of the outer solar system in democratic heliocentric coordinates: REBOUND's
    WHFast with coordinates = "democraticheliocentric" (measured 4.2e-14 of the largest
    coordinate), while Jacobi coordinates differ from it by 3e-7."""
    sim = solar_democratic()
    sim.step(1000)
    theirs = rebound_solar(0, "standard", 1000, coordinates="democraticheliocentric")
    scale = np.abs(theirs).max()
    assert np.abs(sim.pos - theirs).max() / scale < 1e-12
    jacobi = solar()
    jacobi.step(1000)
    assert np.abs(jacobi.pos - theirs).max() / scale > 1e-9


def test_democratic_heliocentric_with_other_terms_takes_the_general_kick():
    """A term besides gravity (here a drag of zero strength) sends the kick through the force
    table: the same motion as the pure-gravity kick, to round-off of the centre's pull taken
    out again (measured 1.5e-14 over 500 steps)."""
    plain = solar_democratic()
    plain.step(500)
    general = solar_democratic(extra=forces.Drag(linear=0.0))
    general.step(500)
    scale = np.abs(plain.pos).max()
    assert np.abs(general.pos - plain.pos).max() / scale < 1e-11
    assert not np.array_equal(general.pos, plain.pos)  # it did take the other path


def test_democratic_heliocentric_converges_at_second_order_and_conserves_energy():
    def run(dt):
        sim = Simulation(dim=2, integrator="whfast", dt=dt, coordinates="democratic_heliocentric")
        sim.add(mass=1.0, pos=(0.0, 0.0))
        sim.add(mass=1e-3, pos=(1.0, 0.0), vel=(0.0, 1.0005))
        sim.add(mass=0.0, pos=(-1.44, 0.0), vel=(0.0, -math.sqrt(1.1 / 1.44)), test=True)
        sim.add_force(forces.NBodyGravity())
        e0 = sim.energy()
        sim.integrate(60.0)
        return sim.pos.copy(), abs(sim.energy() / e0 - 1.0)

    reference = perturbed(2 * math.pi / 2000, corrector=17)
    steps = [2 * math.pi / k for k in (40, 80, 160)]
    runs = [run(h) for h in steps]
    errors = [np.abs(pos - reference).max() for pos, _ in runs]
    slopes = np.diff(np.log(errors)) / np.diff(np.log(steps))
    assert np.all(np.abs(slopes - 2.0) < 0.3), slopes
    assert max(energy for _, energy in runs) < 1e-5


def test_democratic_heliocentric_refuses_what_it_does_not_support():
    for options in ({"corrector": 11}, {"kernel": "lazy"}):
        sim = solar_democratic()
        for name, value in options.items():
            setattr(sim, name, value)
        before = sim.pos.copy()
        with pytest.raises(ValueError, match="democratic heliocentric coordinates take"):
            sim.step(1)
        assert np.array_equal(sim.pos, before) and sim.t == 0.0
    sim = problems.make_sim(problems.outer_solar_system(), "saba", SOLAR_DT)
    sim.coordinates = "democratic_heliocentric"
    with pytest.raises(ValueError, match="integrator='saba'"):
        sim.step(1)
    with pytest.raises(ValueError, match="coordinates must be one of"):
        Simulation(dim=2, coordinates="heliocentric")


def test_settings_changed_between_calls_take_effect_at_the_next_call():
    """A simulation keeps the kernel's converted arguments per setting (the plan's
    ``kernel_tail``): changing the corrector, the kernel or the coordinates between calls must
    still step exactly as a simulation made with the new setting does from the same state, and
    a setting democratic coordinates refuse is refused after calls that were allowed."""
    settings = [("corrector", 0), ("corrector", 11), ("kernel", "lazy"), ("corrector", 0),
                ("kernel", "standard")]
    changed = solar()
    for name, value in settings:
        setattr(changed, name, value)
        fresh = solar(corrector=changed.corrector, kernel=changed.kernel)
        fresh.pos[:] = changed.pos
        fresh.vel[:] = changed.vel
        changed.step(7)
        fresh.step(7)
        assert np.array_equal(changed.pos, fresh.pos) and np.array_equal(changed.vel, fresh.vel)
    sim = solar_democratic()
    sim.step(3)
    before = sim.pos.copy()
    sim.corrector = 11
    with pytest.raises(ValueError, match="democratic heliocentric coordinates take"):
        sim.step(1)
    assert np.array_equal(sim.pos, before)
    sim.corrector = 0
    sim.step(1)
    assert sim.steps == 4


def test_what_the_user_changes_between_calls_is_planned_again():
    """The plan (which body drifts about which mass) is kept between calls while nothing it
    depends on changed: the attractor's mu and position written between calls, a mass written
    into ``sim.mass``, a particle pinned and the simulation's G changed must each act from the
    next call on, exactly as in a simulation made that way from the same state."""
    def attractor_scene(mu, centre):
        sim = Simulation(dim=2, integrator="whfast", dt=0.05)
        sim.add(pos=[1.0, 0.0], vel=[0.0, 1.1])
        sim.add(pos=[-1.5, 0.2], vel=[0.1, -0.8])
        star = forces.PointMass(mu=mu, pos=centre)
        sim.add_force(star)
        return sim, star

    def same_next_call(changed, fresh):
        fresh.pos[:] = changed.pos
        fresh.vel[:] = changed.vel
        changed.step(5)
        fresh.step(5)
        assert np.array_equal(changed.pos, fresh.pos) and np.array_equal(changed.vel, fresh.vel)

    changed, star = attractor_scene(1.0, (0.0, 0.0))
    changed.step(5)
    star.mu = 1.3
    same_next_call(changed, attractor_scene(1.3, (0.0, 0.0))[0])
    star.pos = (0.1, -0.2)
    same_next_call(changed, attractor_scene(1.3, (0.1, -0.2))[0])
    changed.pin(1)
    fresh = attractor_scene(1.3, (0.1, -0.2))[0]
    fresh.pin(1)
    same_next_call(changed, fresh)

    changed = solar()
    changed.step(5)
    changed.mass[1] *= 2.0
    fresh = solar()
    fresh.mass[1] *= 2.0
    same_next_call(changed, fresh)
    changed.G *= 1.01  # the terms packed again with the new G (NBodyGravity's G is sim.G)
    fresh = solar()
    fresh.mass[1] *= 2.0
    fresh.G *= 1.01
    same_next_call(changed, fresh)


def test_equal_scenes_share_one_plan_and_any_difference_is_planned_on_its_own(monkeypatch):
    """Simulations of the same single-term scene hold one plan (``shared_plan``); a scene that
    differs in anything the plan reads (the attractor's mu or position, a mass, a test, pinned
    or active flag) gets its own, and steps bit for bit as with a plan of its own; a scene of
    two terms is planned per simulation; at most ``SHARED_PLANS`` plans are kept."""
    def scene(mu=1.0, centre=(0.0, 0.0), drag=False, change=None, test=False):
        sim = Simulation(dim=2, integrator="whfast", dt=0.05)
        sim.add(mass=1e-3, pos=[1.0, 0.0], vel=[0.0, 1.1])
        sim.add(mass=0.0, pos=[-1.5, 0.2], vel=[0.1, -0.8], test=test)
        sim.add(mass=2e-3, pos=[0.3, -2.0], vel=[0.7, 0.0])
        sim.add_force(forces.PointMass(mu=mu, pos=centre))
        if drag:
            sim.add_force(forces.Drag(linear=1e-3))
        if change is not None:
            change(sim)
        return sim

    first = scene()
    assert scene().kepler_plan() is first.kepler_plan()
    variants = {"mu": lambda: scene(mu=1.3), "centre": lambda: scene(centre=(0.1, 0.0)),
                "mass": lambda: scene(change=lambda s: s.mass.__setitem__(1, 5e-4)),
                "test": lambda: scene(test=True),
                "pinned": lambda: scene(change=lambda s: s.pin(2)),
                "inactive": lambda: scene(change=lambda s: s.deactivate(0))}
    shared = {}
    for name, make in variants.items():
        sim = make()
        assert sim.kepler_plan() is not first.kepler_plan(), name
        assert make().kepler_plan() is sim.kepler_plan(), name
        sim.step(40)
        shared[name] = (sim.pos.copy(), sim.vel.copy())
    with monkeypatch.context() as m:
        m.setattr(wisdom_holman, "SHARED_MAX_PARTICLES", 0)  # every scene planned on its own
        assert scene().kepler_plan() is not first.kepler_plan()
        for name, make in variants.items():
            sim = make()
            sim.step(40)
            assert np.array_equal(sim.pos, shared[name][0]), name
            assert np.array_equal(sim.vel, shared[name][1]), name
    assert scene(drag=True).kepler_plan() is not scene(drag=True).kepler_plan()
    monkeypatch.setattr(wisdom_holman, "SHARED_PLANS", 2)
    kept = scene(mu=2.0).kepler_plan()
    scene(mu=2.1).kepler_plan()
    assert scene(mu=2.0).kepler_plan() is kept  # used last: kept
    scene(mu=2.2).kepler_plan()
    scene(mu=2.3).kepler_plan()
    assert scene(mu=2.0).kepler_plan() is not kept  # two others used since: dropped


def test_the_plan_orders_the_columns():
    """The Jacobi columns: the heaviest body first, the other massive ones in index order,
    then the moving massless ones (test particles count as massless); inactive particles are
    left out. About an attractor: the moving particles in index order, pinned ones left out,
    and the attractor acting on the particles it lists."""
    sim = Simulation(dim=2, integrator="whfast")
    for mass, test in [(1e-3, False), (0.0, False), (1.0, False), (5e-4, True), (2e-3, False),
                       (3e-3, False)]:
        sim.add(mass=mass, pos=(1.0 + mass, 0.5), vel=(0.0, 1.0), test=test)
    sim.deactivate(5)
    sim.add_force(forces.NBodyGravity())
    plan = sim.kepler_plan()
    assert plan.order.tolist() == [2, 0, 4, 1, 3]
    assert plan.masses[:5].tolist() == [1e-3, 0.0, 1.0, 0.0, 2e-3]
    sim = Simulation(dim=2, integrator="whfast")
    for k in range(4):
        sim.add(mass=1.0, pos=(1.0 + k, 0.0), vel=(0.0, 1.0), pinned=k == 1)
    sim.add_force(forces.PointMass(mu=1.0, particles=[0, 1, 3]))
    plan = sim.kepler_plan()
    assert plan.order.tolist() == [0, 2, 3]
    assert plan.attracted[:4].tolist() == [True, True, False, True]


# -- the step loops of the common cases -----------------------------------------------------------
def test_a_lone_attractors_loop_stops_at_the_step_that_fails_and_keeps_the_last_finite_state():
    """The loop a lone attractor takes (nothing to kick) ends at the first step whose end is not
    finite: particle 1, outside the attractor's list, moves on a straight line at 1e307 per
    unit time from x = 5e306 (after the first half drift), and passes the largest float
    (1.8e308) during step 18. Seventeen steps count, the time is theirs, the particle is
    named, and the state kept is the last finite one (step 17's, to round-off: it is found by
    drifting back the half drift the failed step began with)."""
    def scene():
        sim = Simulation(dim=2, integrator="whfast", dt=1.0)
        sim.add(mass=1.0, pos=(1.0, 0.0), vel=(0.0, 1.0))
        sim.add(mass=1.0, pos=(0.0, 2.0), vel=(1e307, 0.0))
        sim.add_force(forces.PointMass(mu=1.0, particles=[0]))
        return sim
    sim = scene()
    with pytest.raises(engine.SimulationError) as info:
        sim.step(40)
    assert (info.value.step, info.value.particle, sim.steps, sim.t) == (17, 1, 17, 17.0)
    assert np.all(np.isfinite(sim.pos)) and np.all(np.isfinite(sim.vel))
    clean = Simulation(dim=2, integrator="whfast", dt=1.0)
    clean.add(mass=1.0, pos=(1.0, 0.0), vel=(0.0, 1.0))
    clean.add_force(forces.PointMass(mu=1.0))
    clean.step(17)
    np.testing.assert_allclose(sim.pos[0], clean.pos[0], rtol=0, atol=1e-14)
    np.testing.assert_allclose(sim.vel[0], clean.vel[0], rtol=0, atol=1e-14)
    assert sim.pos[1, 0] == pytest.approx(17e307, rel=1e-15) and sim.pos[1, 1] == 2.0


@pytest.mark.parametrize("dt, done", [(1.0, 17), (0.125, 143)])
def test_a_mutual_gravity_loop_stops_at_the_step_that_fails_and_keeps_the_last_finite_state(
        dt, done):
    """The loop of mutual gravity alone saves its state every ``CHECKPOINT_STEPS`` (64) steps
    and, when a step fails, takes the steps since the last save again to find the state that
    step began from. A massless body at 1e307 per unit time (G = 0, so its drift is a straight
    line and nothing else overflows) passes the largest float (1.8e308) half a step after
    t = 17.5: with dt = 1 that is step 18 (found from the first save), with dt = 1/8 step 144
    (found from the save at step 128, fifteen steps taken again). The steps before it count,
    the body is named, and the state kept is theirs: the runaway body at 1e307 t exactly
    (one step more or less would be off by 1e307 dt), the other two as a clean run's."""
    def scene(runaway):
        sim = Simulation(dim=2, integrator="whfast", dt=dt)
        sim.add(mass=1.0, pos=(0.0, 0.0))
        sim.add(mass=1e-3, pos=(1.0, 0.0), vel=(0.0, 1.0))
        if runaway:
            sim.add(mass=0.0, pos=(0.0, 2.0), vel=(1e307, 0.0))
        sim.add_force(forces.NBodyGravity(G=0.0))
        return sim
    sim = scene(True)
    with pytest.raises(engine.SimulationError) as info:
        sim.step(400)
    assert (info.value.step, info.value.particle, sim.steps) == (done, 2, done)
    assert sim.t == done * dt
    assert np.all(np.isfinite(sim.pos)) and np.all(np.isfinite(sim.vel))
    assert sim.pos[2, 0] == pytest.approx(1e307 * (done * dt), rel=1e-13)
    clean = scene(False)
    clean.step(done)
    np.testing.assert_allclose(sim.pos[:2], clean.pos, rtol=0, atol=1e-14)
    np.testing.assert_array_equal(sim.vel[:2], clean.vel)


def test_a_drift_that_overflows_raises_instead_of_hanging():
    """A massless body at 1e150 per unit time, stepped by 1e157: its Kepler drift's z = beta X^2
    overflows to infinity, which the Stumpff functions' quartering loop used to quarter for
    ever (the call never returned). Now the step fails as any non-finite step does: a
    SimulationError, and a failing first step changes nothing."""
    sim = Simulation(dim=2, integrator="whfast", dt=1e157)
    sim.add(mass=1.0, pos=(0.0, 0.0))
    sim.add(mass=1e-3, pos=(1.0, 0.0), vel=(0.0, 1.0))
    sim.add(mass=0.0, pos=(0.0, 2.0), vel=(1e150, 0.0))
    sim.add_force(forces.NBodyGravity())
    before = _state(sim)
    with pytest.raises(engine.SimulationError):
        sim.step(5)
    assert all(np.array_equal(a, b) for a, b in zip(before, _state(sim)))
