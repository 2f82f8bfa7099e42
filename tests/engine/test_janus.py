"""JANUS (engine.integrators.janus): bit-wise reversal, order, energy, REBOUND, statuses.

The kernel is called directly, on the ``engine.state`` tuples of a Simulation, with the
lattice exponents chosen once by ``lattice_exponents`` and kept fixed, as the Simulation does.
"""
import math

import numpy as np
import pytest

import engine
from engine.forces.pairwise import workspace
from engine.integrators import janus, splitting
from validation import problems

NAN = float("nan")


def _kepler(e, dim=2, vz=0.0):
    """A test particle about a fixed mu = 1 attractor at the origin, from pericentre (a = 1)."""
    sim = engine.Simulation(dim=dim, integrator="leapfrog", dt=1.0, G=1.0)
    v = math.sqrt((1.0 + e) / (1.0 - e))
    sim.add(mass=1.0, pos=(1.0 - e, 0.0, 0.0)[:dim], vel=(0.0, v, vz)[:dim])
    sim.add_force(engine.forces.PointMass(mu=1.0, pos=(0.0,) * dim))
    return sim


def _problem(key):
    if key == "outer_solar_system":
        return problems.make_sim(problems.outer_solar_system(), "leapfrog", 50.0), 50.0, 400
    # t = 15 at h = 1e-4: every order still resolves the close encounters (energy error
    # <= 1e-4), the next one (t ~ 16) would need smaller steps
    return problems.make_sim(problems.pythagorean(), "leapfrog", 1e-4), 1e-4, 150000


def _run(sim, h, steps, order, kx, kv, t=0.0, step=janus.advance):
    state, model = sim.kernel_arguments()
    return step(t, h, steps, state, model, workspace(state.n), False, NAN, order, kx, kv)


def _lattice(sim, **kw):
    state, _ = sim.kernel_arguments()
    return janus.lattice_exponents(state.pos, state.vel, state.n, box=state.box,
                                   active=state.active, pinned=state.pinned, **kw)


def _snapshot(sim):
    state, _ = sim.kernel_arguments()
    return state.pos[:, :state.n].copy(), state.vel[:, :state.n].copy()


def _same(sim, snap):
    pos, vel = _snapshot(sim)
    return np.array_equal(pos, snap[0]) and np.array_equal(vel, snap[1])


# -- the schemes ---------------------------------------------------------------------------------

@pytest.mark.parametrize("order", janus.ORDERS)
def test_scheme_coefficients(order):
    """Symmetric, consistent, and the odd power sums that symmetric compositions of a
    symmetric second-order method need to vanish up to the order do vanish."""
    g = np.array(janus.stage_coefficients(order))
    assert len(g) == {2: 1, 4: 5, 6: 9, 8: 15}[order] == janus.FORCE_EVALUATIONS[order]
    assert np.array_equal(g, g[::-1])
    assert abs(g.sum() - 1.0) < 4e-16 * len(g)
    for p in range(3, order, 2):
        assert abs(np.sum(g ** p)) < 1e-14, p
    if order == 4:  # Suzuki's p = 1 / (4 - 4^(1/3))
        assert g[0] == pytest.approx(1.0 / (4.0 - 4.0 ** (1.0 / 3.0)), rel=1e-15)


# -- the lattice ---------------------------------------------------------------------------------

def test_lattice_exponents_headroom_rule():
    sim, _, _ = _problem("outer_solar_system")
    state, _ = sim.kernel_arguments()
    kx, kv = _lattice(sim)
    xmax = np.max(np.abs(state.pos[:, :state.n]))
    vmax = np.max(np.abs(state.vel[:, :state.n]))
    # the largest value lands 10 bits below the lattice limit 2**53
    assert 2.0 ** 42 <= xmax * 2.0 ** kx < 2.0 ** 43
    assert 2.0 ** 42 <= vmax * 2.0 ** kv < 2.0 ** 43
    assert janus.lattice_exponents(state.pos, state.vel, state.n, headroom=3) == (kx + 7, kv + 7)
    # a start from rest takes the velocity scale from the positions
    pyth, _, _ = _problem("pythagorean")
    state, _ = pyth.kernel_arguments()
    kx, kv = _lattice(pyth)
    assert kv == kx and 2.0 ** 42 <= 3.0 * 2.0 ** kx < 2.0 ** 43
    # a periodic box becomes a whole number of lattice units in [2**52, 2**53)
    for box in (10.0, 0.1, 3.0e7):
        kx, _ = janus.lattice_exponents(state.pos, state.vel, state.n, box=box)
        side = box * 2.0 ** kx
        assert side == math.floor(side) and 2.0 ** 52 <= side < 2.0 ** 53
    with pytest.raises(ValueError):
        janus.lattice_exponents(np.array([[np.nan]]), np.zeros((1, 1)), 1)


def test_zero_steps_put_the_state_on_the_lattice_and_calls_compose():
    """The float state is the lattice state: a call of zero steps rounds it onto the lattice
    (and changes nothing the second time), and N steps in one call are N/2 + N/2 in two."""
    sim, h, _ = _problem("outer_solar_system")
    kx, kv = _lattice(sim)
    state, _ = sim.kernel_arguments()
    assert not janus.on_lattice(state.pos, state.vel, state.n, kx, kv)
    assert _run(sim, h, 0, 6, kx, kv) == (0.0, h, 0, janus.OK)
    assert janus.on_lattice(state.pos, state.vel, state.n, kx, kv)
    snap = _snapshot(sim)
    _run(sim, h, 0, 6, kx, kv)
    assert _same(sim, snap)
    other, _, _ = _problem("outer_solar_system")
    _run(other, h, 0, 6, kx, kv)
    t, _, done, status = _run(sim, h, 60, 6, kx, kv)
    assert (done, status) == (60, janus.OK) and t == 60 * h
    _run(other, h, 30, 6, kx, kv)
    _run(other, h, 30, 6, kx, kv, t=30 * h)
    assert _same(other, _snapshot(sim))
    assert janus.on_lattice(state.pos, state.vel, state.n, kx, kv)


# -- 1. bit-wise reversal ------------------------------------------------------------------------

@pytest.mark.parametrize("key", ["outer_solar_system", "pythagorean"])
@pytest.mark.parametrize("order", janus.ORDERS)
def test_reversal_is_bitwise(key, order):
    sim, h, steps = _problem(key)
    kx, kv = _lattice(sim)
    _run(sim, h, 0, order, kx, kv)
    start = _snapshot(sim)
    t, _, done, status = _run(sim, h, steps, order, kx, kv)
    assert (done, status) == (steps, janus.OK)
    assert not np.array_equal(_snapshot(sim)[0], start[0])
    _, _, done, status = _run(sim, -h, steps, order, kx, kv, t=t)
    assert (done, status) == (steps, janus.OK)
    assert _same(sim, start)


def test_pythagorean_amplifies_one_lattice_unit():
    """The control: one lattice unit changed at the turning point is not undone but grows
    about a million times on the way back (so a non-reversible step would be seen; measured
    5e5 to 5e6 for orders 2 to 8), and the engine's floating-point leapfrog does not come
    back bit for bit (2e-10 off)."""
    sim, h, steps = _problem("pythagorean")
    kx, kv = _lattice(sim)
    _run(sim, h, 0, 4, kx, kv)
    start = _snapshot(sim)
    t, _, _, _ = _run(sim, h, steps, 4, kx, kv)
    state, _ = sim.kernel_arguments()
    state.pos[0, 0] += 2.0 ** -kx
    _run(sim, -h, steps, 4, kx, kv, t=t)
    assert np.max(np.abs(_snapshot(sim)[0] - start[0])) * 2.0 ** kx > 1e5

    sim, h, steps = _problem("pythagorean")
    start = _snapshot(sim)
    state, model = sim.kernel_arguments()
    c, d = splitting.coefficients("leapfrog")
    splitting.advance(0.0, h, steps, state, model, workspace(3), False, NAN, c, d)
    splitting.advance(t, -h, steps, state, model, workspace(3), False, NAN, c, d)
    assert not _same(sim, start)


# -- 2. convergence order ------------------------------------------------------------------------

@pytest.mark.parametrize("order, counts", [(2, (100, 200, 400)), (4, (50, 100, 200)),
                                           (6, (60, 120, 240)), (8, (40, 60, 90, 135))])
def test_convergence_order(order, counts):
    """One period of a Kepler orbit (e = 0.5): the error is the distance from the start.
    The lattice has 3 bits of headroom (the orbit reaches 3 times its pericentre distance);
    its contribution, measured against a lattice 4 times finer (1 bit of headroom), is below
    1% of every error (it is about 1e-12; the smallest error is 1e-10)."""
    errors = []
    for n in counts:
        ends = []
        for headroom in (3, 1):
            sim = _kepler(0.5)
            kx, kv = _lattice(sim, headroom=headroom)
            _run(sim, 0.0, 0, order, kx, kv)
            start = _snapshot(sim)[0]
            _, _, done, status = _run(sim, 2.0 * math.pi / n, n, order, kx, kv)
            assert (done, status) == (n, janus.OK)
            ends.append(_snapshot(sim)[0] - start)
        errors.append(np.linalg.norm(ends[0]))
        assert np.linalg.norm(ends[0] - ends[1]) < 0.01 * errors[-1]
    slope = np.polyfit(np.log(counts), np.log(errors), 1)[0]
    assert abs(-slope - order) < 0.3, (slope, errors)


# -- 3. energy -----------------------------------------------------------------------------------

def test_energy_error_is_bounded_order_2():
    """300 orbits of an e = 0.5 Kepler orbit at 100 steps per orbit, sampled every 7 steps:
    the energy error oscillates (at the h**2 level) without growing."""
    sim = _kepler(0.5)
    kx, kv = _lattice(sim)
    _run(sim, 0.0, 0, 2, kx, kv)
    e0 = sim.energy()
    h = 2.0 * math.pi / 100
    t = 0.0
    times, errors = [], []
    while t < 300 * 2.0 * math.pi:
        t, _, done, status = _run(sim, h, 7, 2, kx, kv, t=t)
        assert status == janus.OK
        times.append(t)
        errors.append(sim.energy() - e0)
    times, errors = np.array(times), np.array(errors)
    tenth = len(errors) // 10
    first, last = np.max(np.abs(errors[:tenth])), np.max(np.abs(errors[-tenth:]))
    assert 1e-4 < first < 1e-2
    assert abs(last - first) < 0.05 * first
    drift = np.polyfit(times, errors, 1)[0] * times[-1]
    assert abs(drift) < 0.01 * first


# -- 4. REBOUND ----------------------------------------------------------------------------------

try:
    import rebound
except ImportError:  # pragma: no cover
    rebound = None
needs_rebound = pytest.mark.skipif(rebound is None, reason="REBOUND is not installed")


def _rebound_janus(sim, order, kx, kv, h):
    state, _ = sim.kernel_arguments()
    rs = rebound.Simulation()
    for i in range(state.n):
        rs.add(m=state.mass[i], x=state.pos[0, i], y=state.pos[1, i], z=state.pos[2, i],
               vx=state.vel[0, i], vy=state.vel[1, i], vz=state.vel[2, i])
    rs.integrator = "janus"
    rs.integrator.order = order
    rs.integrator.scale_pos = 2.0 ** -kx
    rs.integrator.scale_vel = 2.0 ** -kv
    rs.dt = h
    return rs


def _rebound_state(rs):
    ps = rs.particles
    pos = np.array([[p.x, p.y, p.z] for p in ps]).T
    vel = np.array([[p.vx, p.vy, p.vz] for p in ps]).T
    return pos, vel


def _point_mass(simp):
    """The engine's PointMass(mu=1, pos=0) acceleration, operation for operation."""
    p = simp.contents.particles[0]
    dx, dy, dz = p.x - 0.0, p.y - 0.0, p.z - 0.0
    r2 = dx * dx + dy * dy + dz * dz + 0.0
    s = 1.0 / (r2 * math.sqrt(r2))
    p.ax, p.ay, p.az = -(s * dx), -(s * dy), -(s * dz)


@needs_rebound
@pytest.mark.parametrize("order", janus.ORDERS)
def test_rebound_same_bits_with_the_same_forces(order):
    """REBOUND's janus with scale_pos = 2**-kx, scale_vel = 2**-kv, the same order and an
    additional force giving the engine's accelerations bit for bit: the truncating variant
    agrees bit for bit over 300 steps (3 orbits); the rounding one (ours) does not."""
    h, steps = 2.0 * math.pi / 100, 300
    sim = _kepler(0.5, dim=3, vz=0.1)
    kx, kv = _lattice(sim)
    _run(sim, h, 0, order, kx, kv, step=janus.advance_truncating)
    rs = _rebound_janus(sim, order, kx, kv, h)
    rs.gravity = "none"
    rs.additional_forces = _point_mass
    rounding = _kepler(0.5, dim=3, vz=0.1)
    _run(rounding, h, 0, order, kx, kv)
    rs.steps(steps)
    _run(sim, h, steps, order, kx, kv, step=janus.advance_truncating)
    _run(rounding, h, steps, order, kx, kv)
    assert _same(sim, _rebound_state(rs))
    assert not _same(rounding, _rebound_state(rs))


@needs_rebound
@pytest.mark.parametrize("order", janus.ORDERS)
def test_rebound_gravity_agrees(order):
    """The outer solar system with each code's own gravity (REBOUND: G / r**3 with r = sqrt(r2),
    the engine: 1 / (r2 sqrt(r2))): 200 steps of 50 days agree to a lattice unit (measured:
    bit for bit); an acceleration's last bit flips a truncation only when it sits within
    about 2**-20 of a lattice unit boundary."""
    prob = problems.outer_solar_system()
    sim = problems.make_sim(prob, "leapfrog", 50.0)
    kx, kv = _lattice(sim)
    _run(sim, 50.0, 0, order, kx, kv, step=janus.advance_truncating)
    rs = _rebound_janus(sim, order, kx, kv, 50.0)
    rs.G = problems.G_SOLAR
    rs.steps(200)
    _run(sim, 50.0, 200, order, kx, kv, step=janus.advance_truncating)
    pos, vel = _snapshot(sim)
    rpos, rvel = _rebound_state(rs)
    assert np.max(np.abs(pos - rpos)) * 2.0 ** kx <= 1.0
    assert np.max(np.abs(vel - rvel)) * 2.0 ** kv <= 1.0


# -- 5. statuses, pinned particles, periodic space -----------------------------------------------

def test_fused_and_general_paths_give_the_same_bits():
    sim, h, _ = _problem("outer_solar_system")
    other, _, _ = _problem("outer_solar_system")
    kx, kv = _lattice(sim)
    _run(sim, h, 100, 8, kx, kv)
    state, model = other.kernel_arguments()
    janus.run_lattice(0.0, h, 100, state, model, workspace(state.n), 8, kx, kv, False, False)
    assert _same(other, _snapshot(sim))


def test_lattice_overflow_mid_run_keeps_the_last_good_state():
    """e = 0.9 from pericentre with 2 bits of headroom: the apocentre is 19 times further out, past
    the lattice; the call stops at the step that would leave it, with the state before it."""
    h = 2.0 * math.pi / 200
    sim = _kepler(0.9)
    kx, kv = _lattice(sim, headroom=2)
    t, _, done, status = _run(sim, h, 200, 4, kx, kv)
    assert status == janus.LATTICE_OVERFLOW and 0 < done < 100 and t == done * h
    again = _kepler(0.9)
    _run(again, h, done, 4, kx, kv)
    assert _same(sim, _snapshot(again))
    assert _run(again, h, 1, 4, kx, kv, t=t) == (t, h, 0, janus.LATTICE_OVERFLOW)


def test_refusals_leave_the_state_untouched():
    sim, h, _ = _problem("outer_solar_system")
    kx, kv = _lattice(sim)
    start = _snapshot(sim)
    assert _run(sim, h, 5, 8, kx + 11, kv) == (0.0, h, 0, janus.LATTICE_OVERFLOW)
    assert _run(sim, h, 5, 8, kx, kv + 11) == (0.0, h, 0, janus.LATTICE_OVERFLOW)
    assert _run(sim, h, 5, 3, kx, kv) == (0.0, h, 0, janus.BAD_ORDER)
    assert _run(sim, h, 5, 8, 2000, kv) == (0.0, h, 0, janus.BAD_LATTICE)
    assert _same(sim, start)
    assert _run(sim, h, 5, 8, kx + 10, kv)[3] == janus.OK


@pytest.mark.parametrize("fuse", [True, False])
def test_blow_up_reports_the_particle(fuse):
    """Two bodies at the same place: the first kick's accelerations are NaN; the status is
    the first of them and the state is the start of the step."""
    sim = engine.Simulation(dim=3, integrator="leapfrog", dt=0.1, G=1.0)
    sim.add(mass=1.0, pos=(3.0, 0.0, 0.0))
    sim.add(mass=1.0, pos=(0.5, 0.25, 0.0), vel=(0.0, 0.5, 0.0))
    sim.add(mass=1.0, pos=(0.5, 0.25, 0.0), vel=(0.0, 0.5, 0.0))
    sim.add_force(engine.forces.NBodyGravity())
    kx, kv = _lattice(sim)
    _run(sim, 0.1, 0, 2, kx, kv)
    start = _snapshot(sim)
    state, model = sim.kernel_arguments()
    result = janus.run_lattice(0.0, 0.1, 10, state, model, workspace(3), 2, kx, kv, False, fuse)
    assert result == (0.0, 0.1, 0, 1)
    assert _same(sim, start)


def test_pinned_particles_stay_put_and_off_lattice():
    """A pinned attractor at a position off the lattice (and a velocity the engine zeroes) is
    neither rounded nor moved; the two planets move, and reverse bit for bit (general path)."""
    sim = engine.Simulation(dim=3, integrator="leapfrog", dt=0.05, G=1.0)
    sun = (0.1, -0.2, 0.0)
    sim.add(mass=1.0, pos=sun, pinned=True)
    sim.add(mass=1e-3, pos=(1.1, -0.2, 0.0), vel=(0.0, 1.0, 0.05))
    sim.add(mass=1e-3, pos=(-1.5, -0.2, 0.0), vel=(0.0, -0.8, 0.0))
    sim.add_force(engine.forces.NBodyGravity())
    kx, kv = _lattice(sim)
    assert sun[0] * 2.0 ** kx != math.floor(sun[0] * 2.0 ** kx)
    _run(sim, 0.05, 0, 6, kx, kv)
    start = _snapshot(sim)
    t, _, done, status = _run(sim, 0.05, 500, 6, kx, kv)
    assert (done, status) == (500, janus.OK)
    pos, vel = _snapshot(sim)
    assert np.array_equal(pos[:, 0], np.array(sun)) and np.array_equal(vel[:, 0], np.zeros(3))
    assert np.all(np.any(pos[:, 1:] != start[0][:, 1:], axis=0))
    _run(sim, -0.05, 500, 6, kx, kv, t=t)
    assert _same(sim, start)


def test_periodic_box_wraps_in_integers():
    """Free motion in a box of side 10: the wrapped integer drift is exactly the unwrapped
    one modulo the box; with softened gravity through the nearest image, reversal across
    wraps is bit for bit; a side that is not a whole number of lattice units is refused."""
    box, h, steps = 10.0, 0.01, 3000
    free = engine.Simulation(dim=2, integrator="leapfrog", dt=h, box=box)
    free.add(mass=1.0, pos=(4.0, -4.5), vel=(3.3, -1.7))
    kx, kv = _lattice(free)
    _run(free, h, 0, 4, kx, kv)
    v = _snapshot(free)[1][:, 0]
    x0 = _snapshot(free)[0][:, 0]
    assert _run(free, h, steps, 4, kx, kv)[3] == janus.OK
    side = int(box * 2 ** kx)
    for k in range(2):
        # the six drifts of an order-4 step, each rounded on its own (v never changes)
        per_step = sum(int(np.rint((c * h) * v[k] * 2.0 ** kx)) for c in _drifts(4))
        q = int(x0[k] * 2 ** kx) + steps * per_step
        q -= side * ((2 * q + side) // (2 * side))
        assert _snapshot(free)[0][k, 0] == q * 2.0 ** -kx
        assert abs(steps * per_step) > 2 * side  # it went round more than twice

    sim = engine.Simulation(dim=2, integrator="leapfrog", dt=h, box=box, G=1.0)
    rng = np.random.default_rng(3)
    sim.add_many(mass=np.ones(6), pos=rng.uniform(-5, 5, (6, 2)), vel=rng.normal(0, 2, (6, 2)))
    sim.add_force(engine.forces.NBodyGravity(softening=0.3))
    kx, kv = _lattice(sim)
    _run(sim, h, 0, 2, kx, kv)
    start = _snapshot(sim)
    t, _, done, status = _run(sim, h, steps, 2, kx, kv)
    assert (done, status) == (steps, janus.OK)
    pos = _snapshot(sim)[0]
    assert np.all(pos >= -box / 2) and np.all(pos < box / 2)
    _run(sim, -h, steps, 2, kx, kv, t=t)
    assert _same(sim, start)

    odd = engine.Simulation(dim=2, integrator="leapfrog", dt=h, box=0.1)
    odd.add(mass=1.0, pos=(0.01, 0.02), vel=(1.0, 0.0))
    snap = _snapshot(odd)
    kx, kv = janus.lattice_exponents(*_snapshot(odd), 1)  # open-space rule: 0.1 2**kx not whole
    assert _run(odd, h, 5, 2, kx, kv) == (0.0, h, 0, janus.BAD_LATTICE)
    assert _same(odd, snap)
    kx, kv = _lattice(odd)
    assert _run(odd, h, 5, 2, kx, kv)[3] == janus.OK


def _drifts(order):
    g = janus.stage_coefficients(order)
    return [0.5 * g[0]] + [0.5 * (g[i - 1] + g[i]) for i in range(1, len(g))] + [0.5 * g[-1]]


def test_velocity_dependent_force_uses_current_velocities():
    """Drag (documented: not exactly reversible, each kick evaluates it with the current
    velocities): the energy lost over one orbit matches rk45's to 1%, and a reversed run
    does not come back bit for bit, only to 1e-2 (measured 1.1e-2 at 200 steps per orbit: a
    kick with velocity-dependent forces is an explicit Euler step in them, first order)."""
    def scene(integrator):
        sim = _kepler(0.5)
        sim.integrator = integrator
        sim.add_force(engine.forces.Drag(linear=0.01))
        return sim
    ref = scene("rk45")
    ref.tolerance = 1e-12
    e0 = ref.energy()
    ref.integrate(2.0 * math.pi)
    lost = e0 - ref.energy()
    assert lost > 0.01

    sim = scene("leapfrog")
    kx, kv = _lattice(sim)
    state, model = sim.kernel_arguments()
    janus.advance(0.0, 0.0, 0, state, model, workspace(1), True, NAN, 4, kx, kv)
    start = _snapshot(sim)
    e0 = sim.energy()
    h = 2.0 * math.pi / 200
    t, _, done, status = janus.advance(0.0, h, 200, state, model, workspace(1), True, NAN, 4,
                                       kx, kv)
    assert (done, status) == (200, janus.OK)
    assert abs((e0 - sim.energy()) - lost) < 0.01 * lost
    janus.advance(t, -h, 200, state, model, workspace(1), True, NAN, 4, kx, kv)
    pos, vel = _snapshot(sim)
    assert not _same(sim, start) and np.max(np.abs(pos - start[0])) < 3e-2


# -- through the Simulation API ------------------------------------------------------------------

def test_simulation_janus_retraces_its_steps_bit_for_bit():
    sim = problems.make_sim(problems.pythagorean(), "janus", 1e-3)
    sim.janus_order = 4
    sim.step(1)  # the first step chooses the lattice and puts the state on it
    sim.dt = -sim.dt
    sim.step(1)
    sim.dt = -sim.dt
    start = (sim.pos.copy(), sim.vel.copy())
    assert sim.janus_lattice is not None
    sim.step(3000)
    assert not np.array_equal(sim.pos, start[0])
    sim.dt = -sim.dt
    sim.step(3000)
    assert np.array_equal(sim.pos, start[0]) and np.array_equal(sim.vel, start[1])


def test_simulation_janus_options_are_checked():
    with pytest.raises(ValueError, match=r"janus_order must be one of \(2, 4, 6, 8\), got 5"):
        engine.Simulation(integrator="janus", janus_order=5)
    sim = engine.Simulation(integrator="janus")
    with pytest.raises(ValueError, match="janus_lattice kx must be an int"):
        sim.janus_lattice = (1.5, 3)
    sim.janus_lattice = (40, 40)
    assert sim.janus_lattice == (40, 40)
