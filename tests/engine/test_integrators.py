"""Integrators: order of convergence, energy behaviour, reversibility, landing on t, rk45."""
import math

import numpy as np
import pytest

import engine
from engine import Simulation, analytic, forces

from .conftest import kepler_initial, kepler_sim
from .controls_energy import energy_drift_figures, kepler_energy_errors

T_END = 2.0  # not a whole period: symplectic Euler's O(h) offset would cancel at pericentre


def kepler_error(integrator, steps, e=0.5):
    sim = kepler_sim(e, integrator, T_END / steps)
    sim.step(steps)
    r0, v0 = kepler_initial(e)
    r, v = analytic.kepler(r0, v0, 1.0, T_END)
    assert sim.t == pytest.approx(T_END, rel=1e-12)
    return float(np.max(np.abs(np.r_[sim.pos[0] - r, sim.vel[0] - v])))


@pytest.mark.parametrize("integrator, order, steps", [
    ("euler", 1, (4000, 8000, 16000)),
    ("symplectic_euler", 1, (4000, 8000, 16000)),
    ("leapfrog", 2, (400, 800, 1600)),
    ("verlet", 2, (400, 800, 1600)),
    ("rk4", 4, (100, 200, 400)),
    ("yoshida4", 4, (100, 200, 400)),
    ("pefrl", 4, (50, 100, 200)),
])
def test_empirical_order_of_convergence_on_kepler(integrator, order, steps):
    errors = [kepler_error(integrator, s) for s in steps]
    slopes = [math.log2(errors[i] / errors[i + 1]) for i in range(len(errors) - 1)]
    for slope in slopes:
        assert slope == pytest.approx(order, abs=0.15), (errors, slopes)
    assert engine.ORDERS[integrator] == order


def _energy_errors(integrator, orbits, steps_per_orbit, e=0.5, samples=None):
    period = 2 * math.pi
    sim = kepler_sim(e, integrator, period / steps_per_orbit)
    e0 = sim.energy()
    out = []
    for _ in range(orbits):
        sim.step(steps_per_orbit)
        out.append(abs(sim.energy() - e0) / abs(e0))
    return np.array(out)


# Measured on the development machine, 1000 orbits of e = 0.5 at 200 steps an orbit, the energy
# error at every step: the largest |dE/E0| of the first 10 orbits, late/early - 1 (the last 10
# orbits' against the first 10's) and the fitted slope per orbit of each orbit's largest error.
# The bounds: late/early - 1 and the slope at about 4 times these, both signs.
ENERGY_FIGURES = {
    # integrator: (early, late/early - 1 measured, its bound, slope measured, its bound)
    "symplectic_euler": (5.2290e-2, -2.6e-4, 1e-3, -1.23e-9, 5e-9),
    "leapfrog": (6.3171e-4, -1.9e-8, 1e-7, 2.0e-15, 1e-14),
    "verlet": (2.6894e-3, 1.5e-8, 1e-7, -8.5e-13, 4e-12),
    "yoshida4": (2.0170e-5, -1.9e-8, 1e-7, -1.5e-16, 1e-15),
    "pefrl": (7.8592e-7, 2.5e-4, 1e-3, 2.0e-13, 1e-12),
}


def check_energy_bounded(integrator, figures):
    """AssertionError unless ``figures`` (``energy_drift_figures``) show a bounded energy error
    of the size measured for ``integrator``: no growth from the first 10 orbits to the last 10
    and no secular slope, each within its bound."""
    early, growth, slope = figures
    size, _, growth_bound, _, slope_bound = ENERGY_FIGURES[integrator]
    assert early == pytest.approx(size, rel=0.02), figures
    assert abs(growth) < growth_bound, figures
    assert abs(slope) < slope_bound, figures


@pytest.mark.parametrize("integrator", list(ENERGY_FIGURES))
def test_symplectic_energy_error_bounded_over_1000_orbits(integrator):
    check_energy_bounded(integrator,
                         energy_drift_figures(kepler_energy_errors(integrator, 1000, 200)))


@pytest.mark.parametrize("integrator", ["symplectic_euler", "leapfrog", "verlet"])
def test_energy_bounded_check_fails_on_an_energy_pump(integrator):
    """Positive control: the same run with 1e-10 of the kinetic energy pumped in a step (about
    4e-8 of |E| an orbit, as a splitting executor scaling the velocities by 1 + 1e-10 a step
    would) fails the check. Measured: late/early - 1 = 7.7e-5, 6.3e-2, 1.5e-2 and slope = 2.9e-8,
    4.0e-8, 4.0e-8 (symplectic Euler, leapfrog, verlet); the slope alone catches all three."""
    figures = energy_drift_figures(kepler_energy_errors(integrator, 1000, 200, pump=1e-10))
    with pytest.raises(AssertionError):
        check_energy_bounded(integrator, figures)
    assert figures[2] > 2e-8, figures  # the secular slope is the pump's


def test_explicit_euler_energy_grows():
    err = _energy_errors("euler", 100, 20000)
    assert np.all(np.diff(err) > 0)  # every orbit gains energy
    assert err[9] > 5 * err[0] and err[99] > 5 * err[9]


def test_rk4_energy_drifts_linearly():
    err = _energy_errors("rk4", 400, 100)
    # RK4 dissipates: the error at 400 orbits is about 4 times that at 100
    assert 3.0 < err[399] / err[99] < 5.0


@pytest.mark.parametrize("integrator", ["leapfrog", "verlet", "yoshida4", "pefrl"])
def test_time_reversibility(integrator):
    sim = kepler_sim(0.7, integrator, 0.01)
    start = np.r_[sim.pos[0], sim.vel[0]]
    sim.step(5000)
    assert np.max(np.abs(np.r_[sim.pos[0], sim.vel[0]] - start)) > 0.1
    sim.dt = -sim.dt
    sim.step(5000)
    # back to the start up to round-off (about 1e-12 per step of drift, over 10^4 steps)
    np.testing.assert_allclose(np.r_[sim.pos[0], sim.vel[0]], start, rtol=0, atol=1e-10)
    assert abs(sim.t) < 1e-12


# |position error| after 1000 steps of dt = -0.001 (e = 0.3; the adaptive ones to their own
# t), measured on the development machine; bounded at 3 times that. The backward run is also the
# forward run's mirror image (y -> -y, exactly: the orbit starts on the x axis), bit for bit.
BACKWARD_ERRORS = {
    "euler": 1.73e-3, "symplectic_euler": 1.23e-3, "leapfrog": 5.09e-7, "verlet": 4.87e-7,
    "rk4": 1.22e-13, "yoshida4": 3.80e-12, "pefrl": 4.96e-14, "rk45": 2.37e-6,
    "whfast": 4.75e-16, "saba": 5.77e-15, "ias15": 2.45e-14, "janus": 6.02e-12,
}


def first_difference(a, b):
    """Index of the first element where arrays ``a`` and ``b`` differ, or None."""
    differ = np.flatnonzero(np.asarray(a).ravel() != np.asarray(b).ravel())
    return int(differ[0]) if differ.size else None


@pytest.mark.parametrize("integrator", engine.INTEGRATORS)
def test_every_integrator_runs_backwards(integrator):
    assert set(BACKWARD_ERRORS) == set(engine.INTEGRATORS)
    sim = kepler_sim(0.3, integrator, -0.001)
    sim.step(1000)
    adaptive = integrator in engine.ADAPTIVE_INTEGRATORS
    assert sim.t == pytest.approx(-1.0, rel=1e-9) if not adaptive else sim.t < -1.0
    r0, v0 = kepler_initial(0.3)
    r, _ = analytic.kepler(r0, v0, 1.0, sim.t)
    error = np.max(np.abs(sim.pos[0] - r))
    assert error < 3 * BACKWARD_ERRORS[integrator], error
    forward = kepler_sim(0.3, integrator, 0.001)
    forward.step(1000)
    mirror = np.array([1.0, -1.0])
    assert sim.t == -forward.t
    for got, want in ((sim.pos[0], forward.pos[0] * mirror),
                      (sim.vel[0], -forward.vel[0] * mirror)):
        assert first_difference(got, want) is None, (first_difference(got, want), got, want)


@pytest.mark.parametrize("integrator", engine.INTEGRATORS)
def test_integrate_lands_exactly_on_t(integrator):
    sim = kepler_sim(0.5, integrator, 0.03)
    sim.integrate(1.0)
    assert sim.t == 1.0
    sim.integrate(0.25)  # and back
    assert sim.t == 0.25
    r0, v0 = kepler_initial(0.5)
    r, _ = analytic.kepler(r0, v0, 1.0, 0.25)
    tol = {"euler": 0.1, "symplectic_euler": 0.05, "leapfrog": 1e-3, "verlet": 1e-3}.get(integrator, 1e-4)
    np.testing.assert_allclose(sim.pos[0], r, atol=tol)


def test_integrate_partial_last_step_is_consistent():
    # integrate(t) with a partial last step equals whole steps when dt divides t
    a = kepler_sim(0.5, "leapfrog", 0.1)
    a.integrate(1.05)
    b = kepler_sim(0.5, "leapfrog", 0.1)
    b.step(10)
    b.dt = 0.05
    b.step(1)
    np.testing.assert_allclose(a.pos, b.pos, rtol=1e-13)
    assert a.dt == 0.1  # the user's step is unchanged by integrate


def test_rk45_error_follows_tolerance():
    r0, v0 = kepler_initial(0.9)
    t_end = 10 * 2 * math.pi
    r, _ = analytic.kepler(r0, v0, 1.0, t_end)
    tolerances = np.array([1e-6, 1e-8, 1e-10, 1e-12])
    errors, steps = [], []
    for tol in tolerances:
        sim = kepler_sim(0.9, "rk45", 0.01, tolerance=tol)
        sim.integrate(t_end)
        errors.append(np.max(np.abs(sim.pos[0] - r)))
        steps.append(sim.steps)
    errors = np.array(errors)
    assert np.all(np.diff(errors) < 0) and np.all(np.diff(steps) > 0)
    # global error proportional to the tolerance: fitted slope about 1 in log-log
    slope = np.polyfit(np.log10(tolerances), np.log10(errors), 1)[0]
    assert 0.8 < slope < 1.2, (errors, slope)
    # over 10 eccentric orbits the global error stays within 1e5 x the local tolerance
    assert np.all(errors < 1e5 * tolerances)


def test_rk45_rejects_and_adapts_at_pericentre():
    sim = kepler_sim(0.99, "rk45", 1.0, tolerance=1e-9)  # a huge first step must be rejected
    sim.integrate(2 * math.pi)
    r0, v0 = kepler_initial(0.99)
    np.testing.assert_allclose(sim.pos[0], r0, atol=1e-5)
    assert sim.steps > 50
    # the rejected attempts are counted: more than one first evaluation and 6 per accepted step
    assert sim.force_evaluations > 1 + 6 * sim.steps


def test_force_evaluations_are_counted():
    sim = kepler_sim(0.5, "rk45", 1e-3, tolerance=1e-8)
    sim.step(10)  # a small first step that grows: nothing rejected
    assert sim.force_evaluations == 1 + 6 * 10
    sim = kepler_sim(0.5, "leapfrog", 1e-3)
    sim.step(10)
    sim.step(5)
    assert sim.force_evaluations == 15
    sim = kepler_sim(0.5, "ias15", 1e-3)
    sim.step(10)
    # per step one evaluation at its start, then 7 per predictor-corrector iteration (at
    # least 2 iterations)
    assert sim.force_evaluations >= 10 * (1 + 14) and (sim.force_evaluations - 10) % 7 == 0


def test_rk45_step_counts_accepted_steps_and_adapts_dt():
    sim = kepler_sim(0.5, "rk45", 1e-3, tolerance=1e-8)
    sim.step(10)
    assert sim.steps == 10
    assert sim.dt > 1e-3  # grew from the first step


def test_force_evaluations_table():
    assert engine.integrators.FORCE_EVALUATIONS == {
        "euler": 1, "symplectic_euler": 1, "leapfrog": 1, "verlet": 1, "rk4": 4,
        "yoshida4": 3, "pefrl": 4, "rk45": 6, "whfast": 1, "saba": 8, "ias15": 22, "janus": 9}


def test_verlet_equals_leapfrog_shifted_by_half_a_kick():
    # KDK and DKD are the same scheme up to where the step starts: both are 2nd order and
    # their positions agree to O(dt^2) at all times
    a = kepler_sim(0.5, "verlet", 1e-3)
    b = kepler_sim(0.5, "leapfrog", 1e-3)
    a.step(1000)
    b.step(1000)
    np.testing.assert_allclose(a.pos, b.pos, atol=1e-5)


def _damped_oscillator_error(integrator, dt, t_end=3.0):
    sim = Simulation(dim=2, integrator=integrator, dt=dt)
    sim.add(mass=1.0, pos=(1.0, 0.0))
    anchor = sim.add(mass=1e15, pos=(0.0, 0.0))
    sim.add_force(forces.Springs([(0, anchor)], k=4.0, rest_length=0.0, damping=0.4))
    sim.integrate(t_end)
    x, _ = analytic.harmonic_oscillator(1.0, 0.0, 2.0, t_end, zeta=0.1)
    return abs(sim.pos[0, 0] - float(x))


@pytest.mark.parametrize("integrator, order", [
    ("verlet", 1), ("leapfrog", 1), ("yoshida4", 1), ("rk4", 4), ("euler", 1)])
def test_velocity_dependent_forces_converge(integrator, order):
    # a damped oscillator: the damping force is re-evaluated with the current velocities, so
    # every method converges; splitting methods drop to first order in the damping term
    e1 = _damped_oscillator_error(integrator, 2e-3)
    e2 = _damped_oscillator_error(integrator, 1e-3)
    # measured slopes: verlet 1.009, leapfrog 1.003, yoshida4 0.998, rk4 3.947 (its error at
    # 1e-3 is 3.9e-14, near round-off), euler 1.004
    assert math.log2(e1 / e2) == pytest.approx(order, abs=0.1), (e1, e2)
    assert e2 < {"rk4": 1e-11, "euler": 1e-2}.get(integrator, 1e-3)
