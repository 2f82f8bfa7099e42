"""ias15: the 15th-order Gauss-Radau predictor-corrector (engine/integrators/ias15.py).

Held to REBOUND's IAS15 step for step (same algorithm, same step; fixed and adaptive), to
Brouwer's law for its energy error on a Kepler orbit, to the Pythagorean three-body problem, to
the closed form of linear drag (a velocity-dependent force), and to the engine's conventions
(landing on t_end, non-finite steps, pinned particles, the warm-start memory).

The kernel is called directly: ``advance(t, h, steps, state, model, work, vdep, t_end, tol,
memory)``; it moves ``sim.pos``/``sim.vel`` in place and does not update ``sim.t``.
"""
import decimal
import math

import numpy as np
import pytest

from engine import Simulation, forces
from engine.forces.pairwise import workspace
from engine.integrators import ias15
from engine.integrators.common import OK, STEP_COLLAPSED, TIME_OVERFLOW
from validation import problems

NAN = math.nan
SOLAR_DT = 50.0  # days: about 87 steps per Jupiter orbit


def kernel(sim):
    state, model = sim.kernel_arguments()
    return state, model, workspace(state.n), ias15.new_memory(sim.dim, state.n)


def solar(dt=SOLAR_DT):
    return problems.make_sim(problems.outer_solar_system(), "rk45", dt)


def rebound_sim(problem, dt, epsilon):
    # imported here, not at module level: the tests that never use REBOUND run without it
    rebound = pytest.importorskip("rebound")
    r = rebound.Simulation()
    r.G = problem.G
    for m, x, v in zip(problem.mass, problem.pos, problem.vel):
        p = np.zeros(3)
        w = np.zeros(3)
        p[:problem.dim] = x
        w[:problem.dim] = v
        r.add(m=float(m), x=p[0], y=p[1], z=p[2], vx=w[0], vy=w[1], vz=w[2])
    r.integrator = "ias15"
    r.integrator.epsilon = epsilon
    r.dt = dt
    return r


def rebound_state(r, dim=3):
    x = np.array([[q.x, q.y, q.z] for q in r.particles])[:, :dim]
    v = np.array([[q.vx, q.vy, q.vz] for q in r.particles])[:, :dim]
    return x, v


def relative_difference(a, b):
    """Largest difference per body over that body's largest coordinate, worst body."""
    return float((np.abs(a - b).max(axis=1) / np.abs(b).max(axis=1)).max())


# -- constants ------------------------------------------------------------------------------------
def test_gauss_radau_constants():
    """The spacings are the Radau nodes (roots of P7 + P8 on [-1, 1], mapped to [0, 1]), and
    the two coefficient tables derived from them are inverse to each other."""
    x = 2.0 * ias15._H[1:] - 1.0
    leg = np.polynomial.legendre
    residual = leg.legval(x, [0] * 7 + [1]) + leg.legval(x, [0] * 8 + [1])
    assert np.abs(residual).max() < 1e-14
    assert ias15._H[0] == 0.0 and np.all(np.diff(ias15._H) > 0.0)
    for n in range(1, 8):
        for j in range(n):
            assert ias15._RINV[n, j] * (ias15._H[n] - ias15._H[j]) == pytest.approx(1.0, rel=3e-16)
    assert np.abs(ias15._C @ ias15._D - np.eye(7)).max() < 1e-15
    # Everhart's c and d tables, spot values (as tabulated by Rein & Spiegel 2015)
    assert ias15._C[1, 0] == -ias15._H[1] and ias15._D[1, 0] == ias15._H[1]
    assert ias15._C[6, 5] == pytest.approx(-2.7558127197720458314421588, rel=1e-15)
    assert ias15._D[6, 0] == pytest.approx(0.0000000317188154017613665, rel=1e-15)
    with decimal.localcontext() as ctx:
        ctx.prec = 40
        for a in (5040e-9, 1e-300, 3.0, 7e10, 1e300):
            exact = float(decimal.Decimal(a) ** (decimal.Decimal(1) / 7))
            assert ias15.root7(a) == pytest.approx(exact, rel=2.3e-16)


# -- 1. same algorithm, same step as REBOUND ------------------------------------------------------
def test_fixed_step_matches_rebound_step_for_step():
    """Outer solar system, epsilon 0 in both (fixed 50-day steps), 1000 steps (11.5 Jupiter
    orbits). Largest difference measured, per body over its largest coordinate: positions
    3.7e-14 (Jupiter), velocities 3.1e-14 (2.6e-14 and 2.1e-14 before the kernel's
    multiply-adds were contracted). The same kernel without compensated summation of
    positions and velocities measured 3.9e-13, hence the bound of 1e-13."""
    sim = solar()
    state, model, work, memory = kernel(sim)
    t, h, done, status = ias15.advance(0.0, SOLAR_DT, 1000, state, model, work, False, NAN,
                                       0.0, memory)
    assert (status, done, h) == (OK, 1000, SOLAR_DT)
    assert t == pytest.approx(1000 * SOLAR_DT, rel=1e-15)
    r = rebound_sim(problems.outer_solar_system(), SOLAR_DT, 0.0)
    r.steps(1000)
    x, v = rebound_state(r)
    dx = relative_difference(sim.pos, x)
    dv = relative_difference(sim.vel, v)
    print(f"fixed step vs REBOUND after 1000 steps: positions {dx:.2e}, velocities {dv:.2e}")
    assert dx < 1e-13 and dv < 1e-13
    # one force evaluation at the start of each step plus seven per iteration
    evaluations = memory[ias15.MEMORY_EVALUATIONS]
    iterations = memory[ias15.MEMORY_ITERATIONS]
    assert evaluations == 1000 + 7 * iterations
    assert memory[ias15.MEMORY_CAPPED] == 0


def test_adaptive_steps_match_rebound():
    """epsilon = 1e-9 (the default) from a 50-day first step: the step sizes of the first 100
    steps agree with REBOUND's to 1.9e-11 (measured; 2.4e-11 before the kernel's multiply-adds
    were contracted); that is their sensitivity to round-off,
    not a difference of method: perturbing the initial positions of this integrator alone by
    1e-16 (relative) moves its own step sizes by 1.4e-11 to 1.8e-11. A step-size rule off by
    a constant factor would differ by that factor (with 7!/2 in place of 7! in the rule, the
    steps are 10% shorter and this test fails). Both then land on t = 15000 days, where the
    states agree to 8.5e-15 (positions) and 9.7e-15 (velocities), measured."""
    sim = solar()
    state, model, work, memory = kernel(sim)
    r = rebound_sim(problems.outer_solar_system(), SOLAR_DT, 1e-9)
    t = 0.0
    h = SOLAR_DT
    ours = []
    theirs = []
    for _ in range(100):  # one step per call: the predictor survives in memory
        t_new, h, done, status = ias15.advance(t, h, 1, state, model, work, False, NAN, 1e-9,
                                               memory)
        assert (done, status) == (1, OK)
        ours.append(t_new - t)
        t = t_new
        before = r.t
        r.steps(1)
        theirs.append(r.t - before)
    ours = np.array(ours)
    theirs = np.array(theirs)
    worst = float(np.abs(ours / theirs - 1.0).max())
    print(f"adaptive step sizes vs REBOUND over 100 steps: largest relative difference {worst:.2e}"
          f" (steps from {ours.min():.4g} to {ours.max():.4g} days)")
    assert ours[0] == SOLAR_DT and ours.max() / ours.min() > 2.0  # the steps do adapt
    assert worst < 1e-9
    t_land = 15000.0
    t, h, done, status = ias15.advance(t, h, 10 ** 6, state, model, work, False, t_land, 1e-9,
                                       memory)
    assert (t, status) == (t_land, OK)
    r.integrate(t_land, exact_finish_time=1)
    x, v = rebound_state(r)
    dx = relative_difference(sim.pos, x)
    dv = relative_difference(sim.vel, v)
    print(f"adaptive, both landed on t = {t_land:g}: positions {dx:.2e}, velocities {dv:.2e}")
    assert dx < 1e-12 and dv < 1e-12


@pytest.mark.parametrize("epsilon", [1e-9, 1e-12])
def test_a_body_starting_at_a_zero_of_its_acceleration_does_not_collapse_the_step(epsilon):
    """The figure-eight starts with body 3 at the centre, where the pulls of bodies 1 and 2
    cancel: to 1e-17, not to zero, once the force's multiply-adds are fused. Counted in the
    step criterion, such a body gives tau = sqrt(2) |a_end| / |jerk| = sqrt(2) dt at any
    step, every attempt asked for a quarter of itself, and ``Simulation.integrate`` raised
    'step size collapsed' near t = 1.6e-17 at epsilon 1e-9 and below, from any first step.
    Skipped as an exact zero is (REBOUND's own start), the run takes REBOUND's steps: over
    one period, 944 steps in both codes at epsilon 1e-9, the same state to 3e-15."""
    prob = problems.figure_eight()
    period = problems.FIGURE_EIGHT_PERIOD
    sim = problems.make_sim(prob, "ias15", 0.01, tolerance=epsilon)
    sim.integrate(period)
    r = rebound_sim(prob, 0.01, epsilon)
    r.integrate(period)
    x, v = rebound_state(r, dim=2)
    assert sim.t == period
    assert abs(sim.steps - r.steps_done) <= 0.02 * r.steps_done
    assert np.abs(sim.pos - x).max() < 1e-12 and np.abs(sim.vel - v).max() < 1e-12
    assert np.abs(sim.pos - prob.pos).max() < 1e-7  # back at the start (8-digit data)


# -- 2. Brouwer's law -----------------------------------------------------------------------------
def _kepler_energy_errors(angle, orbits, e=0.5, eps=1e-9, chunk=50):
    """Relative energy error of a Kepler orbit (mu = 1, a = 1, eccentricity e, rotated by
    ``angle``) sampled every ``chunk`` steps (about one orbit) of free-running IAS15."""
    sim = Simulation(dim=2, integrator="rk45", dt=0.01)
    c, s = math.cos(angle), math.sin(angle)
    r0 = np.array([1.0 - e, 0.0])
    v0 = np.array([0.0, math.sqrt((1.0 + e) / (1.0 - e))])
    rot = np.array([[c, -s], [s, c]])
    sim.add(mass=1.0, pos=rot @ r0, vel=rot @ v0)
    sim.add_force(forces.PointMass(mu=1.0, pos=(0.0, 0.0)))
    state, model, work, memory = kernel(sim)
    x = sim.pos[0]
    v = sim.vel[0]

    def energy():
        return 0.5 * (v @ v) - 1.0 / math.sqrt(x @ x)

    e0 = energy()
    t = 0.0
    h = 0.01
    times = []
    errors = []
    while t < orbits * 2.0 * math.pi:
        t, h, done, status = ias15.advance(t, h, chunk, state, model, work, False, NAN, eps,
                                           memory)
        assert status == OK
        times.append(t)
        errors.append((energy() - e0) / abs(e0))
    return np.array(times) / (2.0 * math.pi), np.array(errors)


def brouwer_exponent(errors):
    """Growth exponent of the energy error from an ensemble of runs (rows, sampled at common
    intervals): the rms change of the error over a span of L samples, pooled over every start
    and every run, against L (L = 16, 32, ... up to an eighth of the run). A random walk gives
    0.5, a linear drift 1. The round-off of the energy's own evaluation (white noise) adds a
    constant to every mean square, estimated by the lag-1 value and taken off first."""
    n = errors.shape[1]
    lags = 2 ** np.arange(0, int(math.log2(n // 8)) + 1)
    ms = np.array([(np.diff(errors[:, ::lag], axis=1) ** 2).mean() for lag in lags])
    use = lags >= 16
    return 0.5 * np.polyfit(np.log(lags[use] - 1.0), np.log(ms[use] - ms[0]), 1)[0]


def test_energy_error_follows_brouwers_law():
    """16 orientations of an e = 0.5 orbit, 1500 orbits each (about 6-9 s here), epsilon 1e-9.

    Measured: growth exponent 0.47-0.51 for six different sets of orientations; rms relative
    energy error after 1500 orbits 5-7e-15, largest single error 1-2e-14; with the kernel's
    multiply-adds contracted, on these orientations: exponent 0.48-0.52, rms 3.1-3.6e-15,
    largest 8.9-9.8e-15 (two builds that differ only in which products the compiler fused). The estimator does
    see a drift: the same errors plus 4e-17 per orbit give an exponent near 1.
    Over 1e5 orbits (5 runs, 27 s each, outside pytest): rms error 5.4e-14 at 1e5 orbits
    (5.8e-15 at 1e3), largest 1.1e-13, exponent 0.47 (this estimator) and 0.42-0.50 (a fit of
    the ensemble rms against time from 10, 100, 1000 orbits). Again with contracted
    multiply-adds: rms 6.8e-14 at 1e5 orbits (5.8e-15 at 1e3), largest 1.2e-13, exponent 0.50
    (this estimator), 0.43 (the fit from 10 to 1000 orbits) and 0.50 (from 10 to 1e5)."""
    orbits = 1500
    runs = [_kepler_energy_errors(2.0 * math.pi * m / 16 + 0.1, orbits) for m in range(16)]
    n = min(len(errs) for _, errs in runs)
    errors = np.array([errs[:n] for _, errs in runs])
    rms_end = float(np.sqrt((errors[:, -1] ** 2).mean()))
    exponent = brouwer_exponent(errors)
    print(f"Brouwer: exponent {exponent:.3f}, rms error after {orbits} orbits {rms_end:.2e}, "
          f"largest {np.abs(errors).max():.2e}")
    assert rms_end < 1.5e-14
    assert np.abs(errors).max() < 5e-14
    assert abs(exponent - 0.5) < 0.1
    drift = errors + 4e-17 * np.arange(1, n + 1)
    assert brouwer_exponent(drift) > 0.8


# -- 3. Pythagorean three-body problem -----------------------------------------------------------
def _two_body_energy(m1, m2, x1, x2, v1, v2):
    dv = v2 - v1
    return 0.5 * m1 * m2 / (m1 + m2) * (dv @ dv) - m1 * m2 / math.sqrt((x2 - x1) @ (x2 - x1))


def test_pythagorean_problem_m3_escapes():
    """Burrau's problem to t = 70 (Szebehely & Peters 1967): after the close encounters the
    lightest body (m = 3) leaves on an unbound orbit and m = 4, 5 remain a bound binary.
    Measured: relative energy error 1.3e-11 in 5378 steps (REBOUND's IAS15: 3.1e-11 in 5380).
    The encounters amplify round-off, so the error is a draw from a spread: twelve starts moved
    by up to 1.1e-12 gave 6e-13 to 1.2e-10, median 3.4e-11 (before the kernel's multiply-adds
    were contracted: 1e-12 to 2.1e-10, median 3.8e-11, with divided differences that divide
    and with ones that multiply by reciprocals). REBOUND's IAS15 ends
    with the same break-up (positions agree to 5e-3 after the chaotic encounters)."""
    p = problems.pythagorean()
    sim = problems.make_sim(p, "rk45", 0.01)
    state, model, work, memory = kernel(sim)
    e0 = sim.energy()
    assert e0 == pytest.approx(problems.PYTHAGOREAN_ENERGY, rel=1e-15)
    t, h, done, status = ias15.advance(0.0, 0.01, 10 ** 7, state, model, work, False, 70.0,
                                       1e-9, memory)
    assert (t, status) == (70.0, OK)
    assert abs(sim.energy() - e0) / abs(e0) < 3e-10
    m = sim.mass
    x = sim.pos.copy()
    v = sim.vel.copy()
    # the binary: bound; the m = 3 body against the binary's centre of mass: unbound, receding
    assert _two_body_energy(m[1], m[2], x[1], x[2], v[1], v[2]) < 0.0
    mb = m[1] + m[2]
    xb = (m[1] * x[1] + m[2] * x[2]) / mb
    vb = (m[1] * v[1] + m[2] * v[2]) / mb
    assert _two_body_energy(m[0], mb, x[0], xb, v[0], vb) > 0.0
    assert (x[0] - xb) @ (v[0] - vb) > 0.0
    assert np.linalg.norm(x[0] - xb) > 10.0 > np.linalg.norm(x[1] - x[2])
    r = rebound_sim(p, 0.01, 1e-9)
    r.integrate(70.0, exact_finish_time=1)
    xr, _ = rebound_state(r, dim=2)
    # same outcome in REBOUND: the same body far out, the same pair close together
    assert np.linalg.norm(xr[0] - x[0]) < 0.1 and np.linalg.norm(xr[1] - xr[2]) < 1.0


# -- 4. velocity-dependent force ------------------------------------------------------------------
def _drag_error(vdep, t_end=20.0, mass=2.0, c=0.7):
    sim = Simulation(dim=3, integrator="rk45", dt=0.1)
    x0 = np.array([1.0, -2.0, 0.5])
    v0 = np.array([3.0, 1.0, -2.0])
    sim.add(mass=mass, pos=x0, vel=v0)
    sim.add_force(forces.Drag(linear=c))
    state, model, work, memory = kernel(sim)
    t, h, done, status = ias15.advance(0.0, 0.1, 10 ** 6, state, model, work, vdep, t_end,
                                       1e-9, memory)
    assert (t, status) == (t_end, OK)
    k = c / mass
    v = v0 * math.exp(-k * t_end)
    x = x0 + v0 / k * (1.0 - math.exp(-k * t_end))
    return (float(np.abs(sim.vel[0] / v - 1.0).max()),
            float(np.abs(sim.pos[0] - x).max() / np.abs(x).max()))


def test_linear_drag_matches_closed_form():
    """v(t) = v0 exp(-c t / m): after seven e-folds, velocity and position agree with the
    closed form to 2.2e-16 and 1.9e-16 (measured). Without predicting the velocities at the
    nodes (vdep False) the same run is off by order one."""
    dv, dx = _drag_error(True)
    assert dv < 2e-15 and dx < 2e-15
    dv_wrong, _ = _drag_error(False)
    assert dv_wrong > 1e-3


# -- 5. the engine's conventions ------------------------------------------------------------------
def test_lands_exactly_on_t_end_and_keeps_the_step():
    sim = solar()
    state, model, work, memory = kernel(sim)
    t, h, done, status = ias15.advance(0.0, SOLAR_DT, 10 ** 6, state, model, work, False, 1234.5,
                                       1e-9, memory)
    assert (t, status) == (1234.5, OK) and done > 1
    t2, h2, done2, status2 = ias15.advance(t, h, 10, state, model, work, False, 1234.5, 1e-9,
                                           memory)
    assert (t2, h2, done2, status2) == (1234.5, h, 0, OK)  # already there
    # several landings in a row, each exact; the proposed step is not spoilt by the short ones
    for target in (1300.0, 1300.0 + 1e-9, 2000.0):
        t, h, done, status = ias15.advance(t, h, 10 ** 6, state, model, work, False, target,
                                           1e-9, memory)
        assert (t, status) == (target, OK)
    assert h > 50.0
    # fixed step (tol 0): whole steps, then a shorter last one; h is returned unchanged
    sim = solar()
    state, model, work, memory = kernel(sim)
    t, h, done, status = ias15.advance(0.0, SOLAR_DT, 100, state, model, work, False, 1020.0,
                                       0.0, memory)
    assert (t, h, done, status) == (1020.0, SOLAR_DT, 21, OK)


def test_backwards_returns_to_the_start():
    sim = solar()
    x0 = sim.pos.copy()
    state, model, work, memory = kernel(sim)
    t, h, done, status = ias15.advance(0.0, SOLAR_DT, 10 ** 6, state, model, work, False, 2e4,
                                       1e-9, memory)
    assert (t, status) == (2e4, OK)
    t, h, done, status = ias15.advance(t, -h, 10 ** 6, state, model, work, False, 0.0, 1e-9,
                                       memory)
    assert (t, status) == (0.0, OK) and h < 0.0
    back = np.abs(sim.pos - x0).max() / np.abs(x0).max()
    print(f"there and back over 2e4 days: largest position difference {back:.2e} of 30 AU")
    assert back < 1e-12


def test_warm_start_survives_between_calls():
    """100 calls of one step with the memory give exactly the trajectory of one call of 100
    steps (the predictor and the compensated sums are carried over); a fresh memory per call
    is a cold start each time: more force evaluations, and round-off of its own."""
    one = solar()
    state, model, work, memory = kernel(one)
    t_one, h_one, done, status = ias15.advance(0.0, SOLAR_DT, 100, state, model, work, False,
                                               NAN, 1e-9, memory)
    assert (done, status) == (100, OK)
    warm_evaluations = memory[ias15.MEMORY_EVALUATIONS]
    many = solar()
    state, model, work, memory = kernel(many)
    t = 0.0
    h = SOLAR_DT
    for _ in range(100):
        t, h, done, status = ias15.advance(t, h, 1, state, model, work, False, NAN, 1e-9, memory)
    assert (t, h) == (t_one, h_one)
    assert np.array_equal(many.pos, one.pos) and np.array_equal(many.vel, one.vel)
    cold = solar()
    state, model, work, _ = kernel(cold)
    t = 0.0
    h = SOLAR_DT
    cold_evaluations = 0
    for _ in range(100):
        memory = ias15.new_memory(3, state.n)
        t, h, done, status = ias15.advance(t, h, 1, state, model, work, False, NAN, 1e-9, memory)
        cold_evaluations += memory[ias15.MEMORY_EVALUATIONS]
    assert cold_evaluations > 1.5 * warm_evaluations
    assert relative_difference(cold.pos, one.pos) < 1e-9
    # a state changed between calls (here: a velocity) makes the next call start cold
    state, model, work, memory = kernel(one)
    ias15.advance(0.0, SOLAR_DT, 2, state, model, work, False, NAN, 1e-9, memory)
    assert memory[ias15.MEMORY_DT_LAST] != 0.0
    one.vel[1, 0] *= 1.0 + 1e-12
    before = memory[ias15.MEMORY_EVALUATIONS]
    ias15.advance(0.0, SOLAR_DT, 1, state, model, work, False, NAN, 1e-9, memory)
    assert memory[ias15.MEMORY_EVALUATIONS] - before > 15  # cold: several iterations


def test_memory_of_the_wrong_size_is_refused():
    sim = solar()
    state, model, work, _ = kernel(sim)
    assert ias15.memory_shape(3, state.n) == (ias15.HEADER + 32 * 3 * state.n,)
    with pytest.raises(ValueError):
        ias15.advance(0.0, SOLAR_DT, 1, state, model, work, False, NAN, 1e-9,
                      ias15.new_memory(3, state.n + 1))


def test_singular_pair_returns_its_index_and_keeps_the_state():
    sim = Simulation(dim=3, integrator="rk45", dt=0.1)
    sim.add(mass=1.0, pos=(0.0, 0.0, 0.0), vel=(0.0, 0.1, 0.0))
    sim.add(mass=1.0, pos=(1.0, 0.0, 0.0))
    sim.add(mass=1.0, pos=(1.0, 0.0, 0.0))  # on top of particle 1, softening 0
    sim.add_force(forces.NBodyGravity())
    x0 = sim.pos.copy()
    v0 = sim.vel.copy()
    for tol in (1e-9, 0.0):
        state, model, work, memory = kernel(sim)
        t, h, done, status = ias15.advance(0.0, 0.1, 10, state, model, work, False, NAN, tol,
                                           memory)
        assert (t, done, status) == (0.0, 0, 1)
        assert np.array_equal(sim.pos, x0) and np.array_equal(sim.vel, v0)


def test_non_finite_step_keeps_the_last_finite_state():
    """A fixed step so long that the predicted positions overflow: the step fails on the
    particle, after the steps before it, and the state is the one before the failing step.
    With adaptive steps the same wild step is rejected and shortened until it works."""
    sim = problems.make_sim(problems.kepler(0.5), "rk45", 0.1)
    state, model, work, memory = kernel(sim)
    t, h, done, status = ias15.advance(0.0, 0.1, 3, state, model, work, False, NAN, 0.0, memory)
    assert (done, status) == (3, OK)
    x1 = sim.pos.copy()
    v1 = sim.vel.copy()
    t2, h2, done, status = ias15.advance(t, 1e307, 3, state, model, work, False, NAN, 0.0,
                                         memory)
    assert (t2, done, status) == (t, 0, 0)
    assert np.array_equal(sim.pos, x1) and np.array_equal(sim.vel, v1)
    e0 = sim.energy()
    t3, h3, done, status = ias15.advance(t, 1e307, 5, state, model, work, False, NAN, 1e-9,
                                         memory)
    assert (done, status) == (5, OK) and memory[ias15.MEMORY_REJECTED] > 100
    assert t < t3 < 10.0 and abs(sim.energy() / e0 - 1.0) < 1e-14


def test_head_on_collision_stops_before_the_singularity():
    """Two unsoftened bodies falling onto each other from rest: the steps shrink with the
    separation until they no longer advance the time, or a step fails; either way the state
    kept is finite and the time is the collision's (t = pi / 2^(3/2) here) to round-off."""
    sim = Simulation(dim=3, integrator="rk45", dt=0.01)
    sim.add(mass=0.5, pos=(-0.5, 0.0, 0.0))
    sim.add(mass=0.5, pos=(0.5, 0.0, 0.0))
    sim.add_force(forces.NBodyGravity())
    state, model, work, memory = kernel(sim)
    t, h, done, status = ias15.advance(0.0, 0.01, 10 ** 5, state, model, work, False, NAN, 1e-9,
                                       memory)
    print(f"head-on: stopped at t = {t!r} after {done} steps, status {status}, separation "
          f"{sim.pos[1, 0] - sim.pos[0, 0]:.3g}")
    assert status == STEP_COLLAPSED or status >= 0
    assert done < 10 ** 5
    t_collision = math.pi / 2.0 ** 1.5
    assert t == pytest.approx(t_collision, rel=1e-12)
    assert np.all(np.isfinite(sim.pos)) and np.all(np.isfinite(sim.vel))


def test_pinned_and_inactive_particles_do_not_move():
    sim = Simulation(dim=3, integrator="rk45", dt=0.05)
    sim.add(mass=1.0, pos=(0.1, -0.2, 0.3), pinned=True)
    sim.add(mass=1e-3, pos=(1.1, -0.2, 0.3), vel=(0.0, 1.0, 0.0))
    sim.add(mass=1e-3, pos=(0.1, 1.8, 0.3), vel=(-0.7, 0.0, 0.1))
    sim.add(mass=1e-3, pos=(3.0, 3.0, 3.0), vel=(0.5, 0.5, 0.5))
    sim.deactivate(3)
    sim.add_force(forces.NBodyGravity())
    x0 = sim.pos.copy()
    v0 = sim.vel.copy()
    e0 = sim.energy()
    state, model, work, memory = kernel(sim)
    t, h, done, status = ias15.advance(0.0, 0.05, 10 ** 6, state, model, work, False, 10.0, 1e-9,
                                       memory)
    assert (t, status) == (10.0, OK)
    for i in (0, 3):  # bit for bit, velocity included (the inactive one keeps its own)
        assert np.array_equal(sim.pos[i], x0[i]) and np.array_equal(sim.vel[i], v0[i])
    assert np.all(np.abs(sim.pos[1:3] - x0[1:3]).max(axis=1) > 0.5)  # the others orbit
    assert abs(sim.energy() / e0 - 1.0) < 1e-12  # about the fixed mass, conservatively


def test_periodic_box_wraps_at_the_end_of_steps():
    """A free particle (no forces: each step 4 times the last) crosses the edge of the
    torus [-1/2, 1/2)^2 on its way: x 0.4 -> 0.7 = -0.3, y 0 -> -0.65 = 0.35."""
    sim = Simulation(dim=2, integrator="rk45", dt=0.1, box=1.0)
    sim.add(mass=1.0, pos=(0.4, 0.0), vel=(0.3, -0.65))
    state, model, work, memory = kernel(sim)
    t, h, done, status = ias15.advance(0.0, 0.1, 10 ** 6, state, model, work, False, 1.0, 1e-9,
                                       memory)
    assert (t, done, status) == (1.0, 3, OK)
    assert sim.pos[0] == pytest.approx([-0.3, 0.35], abs=1e-15)


def test_iteration_cap_and_time_overflow():
    """Fixed steps of a third of the orbit at pericentre of an e = 0.5 orbit: the
    predictor-corrector does not converge and stops at 12 iterations (19 of 20 steps
    measured), and the run goes on. A step past the largest float is refused."""
    sim = problems.make_sim(problems.kepler(0.5), "rk45", 0.1)
    state, model, work, memory = kernel(sim)
    t, h, done, status = ias15.advance(0.0, 2.0, 20, state, model, work, False, NAN, 0.0, memory)
    assert (t, h, done, status) == (40.0, 2.0, 20, OK)
    stats = ias15.statistics(memory)
    assert stats["capped"] > 10 and stats["iterations"] <= 12 * 20
    assert stats["evaluations"] == 20 + ias15.EVALUATIONS_PER_ITERATION * stats["iterations"]
    x = sim.pos.copy()
    t, h, done, status = ias15.advance(1.7e308, 1e308, 5, state, model, work, False, NAN, 1e-9,
                                       memory)
    assert (t, done, status) == (1.7e308, 0, TIME_OVERFLOW)
    assert np.array_equal(sim.pos, x)


# -- through the Simulation API ------------------------------------------------------------------

def test_simulation_ias15_reproduces_the_pythagorean_escape():
    """Szebehely & Peters 1967: the lightest body (m = 3) is ejected and the other two leave as
    a binary. Through ``Simulation(integrator="ias15")`` to t = 70."""
    sim = problems.make_sim(problems.pythagorean(), "ias15", 1e-3, tolerance=1e-9)
    e0 = sim.energy()
    sim.integrate(70.0)
    assert sim.t == 70.0
    assert abs(sim.energy() / e0 - 1.0) < 1e-9
    binary = (4.0 * sim.pos[1] + 5.0 * sim.pos[2]) / 9.0
    assert np.linalg.norm(sim.pos[0] - binary) > 20.0  # the m = 3 body is far away
    assert np.linalg.norm(sim.pos[1] - sim.pos[2]) < 1.0  # the others are a tight pair
    assert sim.dt != 1e-3  # the step adapted


def test_simulation_ias15_warm_start_survives_between_calls():
    """``step(100)`` twice is ``step(200)`` bit for bit: the predictor's coefficients are
    kept in the simulation between calls."""
    def run(calls):
        sim = problems.make_sim(problems.outer_solar_system(), "ias15", 50.0, tolerance=1e-9)
        for n in calls:
            sim.step(n)
        return sim.pos.copy(), sim.t
    a, ta = run([200])
    b, tb = run([100, 100])
    assert ta == tb and np.array_equal(a, b)
