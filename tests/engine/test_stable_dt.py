"""``sim.stable_dt()`` (engine.stability): the integrators' limits on omega h, the spring
network's stiffness operator and its top frequency, and the predicted step against the
stability limit measured by running ropes and cloths."""
import math

import numpy as np
import pytest

import engine
from engine import Simulation, SimulationError, forces, stability
from engine.forces.dispatch import accelerations
from engine.forces.pairwise import workspace

FIXED_STEP = [name for name in engine.integrators.GENERAL if name != "rk45"]
MEASURED = ["symplectic_euler", "leapfrog", "verlet", "yoshida4", "pefrl", "rk4"]
G_EARTH = 9.8


# -- the integrators' limits -------------------------------------------------------------------

def test_the_limits_come_out_of_the_coefficients():
    limits = stability.step_limits()
    assert set(limits) == set(engine.INTEGRATORS) - {"ias15"}
    for name in ("symplectic_euler", "leapfrog", "verlet"):
        assert limits[name] == pytest.approx(2.0, abs=1e-12)  # trace G = 2 - z^2
    assert limits["rk4"] == pytest.approx(2.0 * math.sqrt(2.0), abs=1e-12)
    assert limits["yoshida4"] == pytest.approx(1.5734, abs=1e-4)
    assert limits["pefrl"] == pytest.approx(2.9894, abs=1e-4)
    assert limits["rk45"] == pytest.approx(0.9972, abs=1e-4)
    assert limits["euler"] == 0.0
    for name in FIXED_STEP:
        if name == "euler":
            continue
        z = limits[name]
        below = np.abs(np.linalg.eigvals(stability.amplification_matrix(name, z * (1 - 1e-6))))
        above = np.abs(np.linalg.eigvals(stability.amplification_matrix(name, z * (1 + 1e-6))))
        assert below.max() <= 1.0 + 1e-9 and above.max() > 1.0 + 1e-9, name


def test_rk4_on_the_imaginary_axis_is_the_closed_form():
    z = np.linspace(0.1, 3.5, 35)
    g = stability.amplification_matrix("rk4", z)
    radius = np.abs(np.linalg.eigvals(g)).max(axis=-1)
    np.testing.assert_allclose(radius ** 2, 1 - z ** 6 / 72 + z ** 8 / 576, rtol=1e-12)


@pytest.mark.parametrize("integrator", FIXED_STEP)
def test_the_amplification_matrix_is_the_engines_own_step(integrator):
    """One engine step of x'' = -omega^2 x (a zero-rest-length spring to a pinned particle
    is exactly linear) from (1, 0) and (0, 1) in (x, v / omega) gives G's columns."""
    k, m, h = 4.0, 1.0, 0.3
    omega = math.sqrt(k / m)
    columns = []
    for x0, w0 in ((1.0, 0.0), (0.0, 1.0)):
        sim = Simulation(dim=2, integrator=integrator, dt=h)
        sim.add(mass=1.0, pos=(0.0, 0.0), pinned=True)
        sim.add(mass=m, pos=(x0, 0.0), vel=(w0 * omega, 0.0))
        sim.add_force(forces.Springs([(0, 1)], k=k, rest_length=0.0))
        sim.step()
        columns.append((sim.pos[1, 0], sim.vel[1, 0] / omega))
    np.testing.assert_allclose(np.array(columns).T,
                               stability.amplification_matrix(integrator, omega * h),
                               rtol=0, atol=1e-13)


# -- the stiffness operator --------------------------------------------------------------------

def network(dim=3, seed=1):
    """A small irregular network: stretched and compressed springs, a linear one, unequal
    masses, a pinned particle and an inactive one."""
    rng = np.random.default_rng(seed)
    sim = Simulation(dim=dim, integrator="verlet", dt=1e-3)
    n = 9
    sim.add_many(mass=rng.uniform(0.5, 2.0, n), pos=rng.uniform(-1.0, 1.0, (n, dim)))
    pairs = [(i, j) for i in range(n) for j in range(i + 1, n) if (i + 2 * j) % 3 == 0]
    pairs.append((0, 8))
    d = np.linalg.norm(sim.pos[[b for _, b in pairs]] - sim.pos[[a for a, _ in pairs]], axis=1)
    rest = d * rng.uniform(0.7, 1.3, len(pairs))
    rest[-1] = 0.0
    sim.add_force(forces.Springs(pairs, k=rng.uniform(1.0, 10.0, len(pairs)), rest_length=rest))
    sim.pin(2)
    sim.deactivate(5)
    return sim


@pytest.mark.parametrize("dim", [2, 3])
def test_the_operator_is_the_linearised_force(dim):
    """M^-1 K v = -d a / dx . v: the operator against a central difference of the engine's
    own accelerations (geometric term included)."""
    sim = network(dim)
    rng = np.random.default_rng(2)
    moving = sim.active & ~sim.pinned
    v = rng.standard_normal(sim.pos.shape) * moving[:, None]
    sqrt_m = np.sqrt(sim.mass)[:, None]
    predicted = stability.apply_stiffness(sim, v * sqrt_m) / sqrt_m  # M^-1/2 A M^1/2 v

    def acc(x):
        state, model = sim.kernel_arguments()
        state.pos[:, :sim.n] = x.T
        out = np.zeros((dim, sim.n))
        accelerations(0.0, state, model, out, workspace(sim.n))
        return out.T

    x0, eps = sim.pos.copy(), 1e-5
    numeric = -(acc(x0 + eps * v) - acc(x0 - eps * v)) / (2 * eps)
    sim.pos[:] = x0
    numeric[~moving] = 0.0  # pinned: zeroed by the dispatcher; inactive: not moved
    np.testing.assert_allclose(predicted, numeric, rtol=0, atol=1e-7 * np.abs(numeric).max())
    assert np.abs(predicted[~moving]).max() == 0.0


@pytest.mark.parametrize("case", ["network 3-D", "network 2-D", "cloth 6", "cloth 8", "cloth 12",
                                  "rope"])
def test_the_power_iteration_finds_the_top_eigenvalue(case):
    """Against numpy's dense eigenvalues: within the tolerance (the pinned corners of a cloth
    give a pair of top modes closer than that, which the iteration does not separate)."""
    sim = {"network 3-D": lambda: network(3), "network 2-D": lambda: network(2, seed=5),
           "cloth 6": lambda: cloth(6)[0], "cloth 8": lambda: cloth(8)[0],
           "cloth 12": lambda: cloth(12)[0], "rope": lambda: rope("verlet")[0]}[case]()
    a, moving = stability.stiffness_matrix(sim)
    assert list(moving) == list(np.flatnonzero(sim.active & ~sim.pinned))
    np.testing.assert_allclose(a, a.T, rtol=0, atol=1e-12 * np.abs(a).max())
    exact = math.sqrt(np.linalg.eigvalsh(a).max())
    omega, iterations, converged = stability.spring_frequency(sim)
    assert converged and iterations >= stability.MIN_ITERATIONS
    assert omega == pytest.approx(exact, rel=stability.TOLERANCE)
    assert stability.spring_frequency(sim) == (omega, iterations, converged)  # same seed
    tight, more, _ = stability.spring_frequency(sim, tol=1e-8)
    assert more > iterations and tight == pytest.approx(exact, rel=1e-6)


def test_a_compressed_spring_whose_largest_eigenvalue_is_negative():
    """A spring compressed to a tenth of its rest length is unstable across it
    (k (1 - l/r) = -9 k); the top of the spectrum is the axial k / m."""
    sim = Simulation(dim=2, integrator="leapfrog", dt=1e-3)
    sim.add(mass=1.0, pos=(0.0, 0.0), pinned=True)
    sim.add(mass=2.0, pos=(0.1, 0.0))
    sim.add_force(forces.Springs([(0, 1)], k=50.0, rest_length=1.0))
    omega, _, _ = stability.spring_frequency(sim)
    assert omega == pytest.approx(math.sqrt(50.0 / 2.0), rel=stability.TOLERANCE)
    assert sim.stable_dt() == pytest.approx(2.0 / math.sqrt(25.0), rel=stability.TOLERANCE)


def test_pinned_and_inactive_particles_do_not_count():
    # one particle between two walls of pinned particles: omega^2 = (k1 + k2) / m exactly
    sim = Simulation(dim=2, integrator="verlet", dt=1e-3)
    sim.add_many(mass=[5.0, 0.25, 5.0], pos=[(-1.0, 0.0), (0.0, 0.0), (1.0, 0.0)],
                 pinned=[True, False, True])
    sim.add_force(forces.Springs([(0, 1), (1, 2)], k=[3.0, 6.0], rest_length=1.0))
    assert sim.stable_dt() == pytest.approx(2.0 / math.sqrt(9.0 / 0.25), rel=1e-6)
    sim.deactivate(2)  # its spring is gone: k = 3
    assert sim.stable_dt() == pytest.approx(2.0 / math.sqrt(3.0 / 0.25), rel=1e-6)
    sim.pin(1)  # nothing left that moves
    assert sim.stable_dt() == math.inf


def test_nothing_limiting_no_stable_step_and_refusals():
    sim = Simulation(dim=2, integrator="verlet", dt=0.1)
    assert sim.stable_dt() == math.inf  # no particles
    sim.add(mass=1.0)
    sim.add_force(forces.UniformGravity())
    sim.add_force(forces.Drag(linear=0.1))
    assert sim.stable_dt() == math.inf  # no spring, no gravitating pair
    sim.add(mass=1.0, pos=(1.0, 0.0))
    springs = sim.add_force(forces.Springs([(0, 1)], k=8.0, rest_length=1.0))
    assert sim.stable_dt() == pytest.approx(2.0 / 4.0, rel=1e-6)  # omega^2 = 2 k / m
    sim.integrator = "euler"
    assert sim.stable_dt() == 0.0  # amplifies every oscillation at any step
    sim.integrator = "rk45"
    with pytest.raises(ValueError, match="rk45 adapts its own step"):
        sim.stable_dt()
    rk45 = stability.estimate(sim, "rk45")
    assert rk45.dt == pytest.approx(stability.step_limit("rk45") / 4.0, rel=1e-6)
    sim.integrator = "verlet"
    sim.mass[1] = 0.0  # a massless particle on a spring: no step is stable
    assert sim.stable_dt() == 0.0
    sim.mass[1] = 1.0
    sim.pos[1] = sim.pos[0]  # coincident ends and a rest length: no direction
    with pytest.raises(ValueError, match="spring 0 .*coincident"):
        sim.stable_dt()
    sim.remove_force(springs)
    sim.add_force(forces.Springs([(0, 1)], k=8.0, rest_length=0.0))  # linear: fine
    assert sim.stable_dt() == pytest.approx(0.5, rel=1e-6)


def test_gravity_near_close_pairs():
    G, m1, m2, r = 2.0, 3.0, 1.0, 0.5
    sim = Simulation(dim=3, integrator="leapfrog", dt=1e-3, G=G)
    sim.add(mass=m1, pos=(0.0, 0.0, 0.0))
    sim.add(mass=m2, pos=(r, 0.0, 0.0))
    sim.add(mass=1.0, pos=(10.0, 0.0, 0.0))  # far: does not count
    gravity = sim.add_force(forces.NBodyGravity())
    w = math.sqrt(2 * G * (m1 + m2) / r ** 3)
    assert stability.gravity_frequency(sim) == pytest.approx(w, rel=1e-12)
    assert sim.stable_dt() == pytest.approx(2.0 / w, rel=1e-12)
    gravity.softening = 0.3  # G M max(1, |eps^2 - 2 r^2| / s^2) / s^3
    s2 = r ** 2 + 0.09
    assert stability.gravity_frequency(sim) == pytest.approx(
        math.sqrt(G * (m1 + m2) * max(1.0, abs(0.09 - 2 * r ** 2) / s2) / s2 ** 1.5), rel=1e-12)
    gravity.softening = 0.0
    sim.pin(0)  # only the free body moves, in the pinned one's field
    assert stability.gravity_frequency(sim) == pytest.approx(
        math.sqrt(2 * G * m1 / r ** 3), rel=1e-12)
    sim.unpin(0)
    sim.remove_force(gravity)
    sim.add_force(forces.PointMass(mu=4.0, pos=(0.0, 0.0, 0.25)))
    assert stability.gravity_frequency(sim) == pytest.approx(
        math.sqrt(2 * 4.0 / 0.25 ** 3), rel=1e-12)  # the body at 0.25 from the attractor
    # springs and gravity add (Weyl's inequality)
    sim.add_force(forces.Springs([(1, 2)], k=3.0, rest_length=9.5))
    e = stability.estimate(sim)
    assert e.omega == pytest.approx(math.hypot(e.omega_springs, e.omega_gravity), rel=1e-12)
    assert e.omega_springs == pytest.approx(math.sqrt(3.0 / 1.0 + 3.0 / 1.0), rel=1e-4)


# -- measured limits ---------------------------------------------------------------------------

def rope(integrator, dt=1e-3, segments=20, k=500.0, m=0.01):
    """A rope hanging straight down from a pinned top, released at rest length."""
    sim = Simulation(dim=2, integrator=integrator, dt=dt)
    forces.rope(sim, (0.0, 0.0), (0.0, -1.0), segments, mass=m, k=k)
    sim.pin(0)
    sim.add_force(forces.UniformGravity(g=(0.0, -G_EARTH)))
    jitter(sim)
    return sim, None


def cloth(n=10, integrator="verlet", dt=1e-3, k=500.0, m=0.01):
    """A 1 x 1 cloth in a vertical plane, hanging from its two pinned top corners."""
    sim = Simulation(dim=3, integrator=integrator, dt=dt)
    idx, _ = forces.cloth(sim, corner=(0.0, 0.0, 0.0), edge_u=(1.0, 0.0, 0.0),
                          edge_v=(0.0, 0.0, -1.0), nu=n, nv=n, mass=m, k=k)
    sim.pin(int(idx[0, 0]))
    sim.pin(int(idx[-1, 0]))
    sim.add_force(forces.UniformGravity(g=(0.0, 0.0, -G_EARTH)))
    jitter(sim)
    return sim, idx


def jitter(sim, size=1e-4, seed=7):
    """Small displacements of the free particles, so every mode starts excited."""
    free = ~sim.pinned
    sim.pos[free] += size * np.random.default_rng(seed).standard_normal((int(free.sum()), sim.dim))


def blows_up(make, integrator, dt, steps=2000, every=20):
    """A run of ``steps`` steps fails (SimulationError) or gains energy: more than 5% of
    W = (total weight) x (size 1). A stable run keeps its energy within about 3% of W (the
    worst being symplectic Euler within 1% of its limit, where its modified energy is far from
    the true one); beyond the limit the splitting methods grow exponentially, and rk4 gains
    energy at once, though the damping of its slower modes then holds the growth back."""
    sim, _ = make(integrator=integrator, dt=dt)
    e0 = sim.energy()
    scale = 0.05 * float(sim.mass.sum()) * G_EARTH
    try:
        for _ in range(steps // every):
            sim.step(every)
            if not sim.energy() - e0 < scale:
                return True
    except SimulationError:
        return True
    return False


def measured_limit(make, integrator, predicted, bisections=8):
    """The stability limit by bisection on dt, bracketed by 0.8 and 1.25 x the prediction
    (checked: stable below, unstable above)."""
    lo, hi = 0.8 * predicted, 1.25 * predicted
    assert not blows_up(make, integrator, lo), f"{integrator} unstable at 0.8 x the prediction"
    assert blows_up(make, integrator, hi), f"{integrator} stable at 1.25 x the prediction"
    for _ in range(bisections):
        mid = 0.5 * (lo + hi)
        if blows_up(make, integrator, mid):
            hi = mid
        else:
            lo = mid
    return lo, hi


@pytest.mark.parametrize("make", [rope, cloth], ids=["rope", "cloth"])
@pytest.mark.parametrize("integrator", MEASURED)
def test_stable_dt_is_within_5_percent_of_the_measured_limit(make, integrator):
    sim, _ = make(integrator=integrator)
    predicted = sim.stable_dt()
    assert 1e-4 < predicted < 1e-2
    lo, hi = measured_limit(make, integrator, predicted)
    measured = 0.5 * (lo + hi)
    assert abs(predicted - measured) <= 0.05 * measured, (predicted, lo, hi)


def test_the_issues_cloth():
    """20 x 20 cloth, k = 500, m = 0.01, verlet: dt = 1/240 blows up (omega dt = 0.93 per
    spring, but the network's top frequency is what counts); stable_dt says so before."""
    sim, idx = cloth(20, integrator="verlet", dt=1.0 / 240.0)
    dt = sim.stable_dt()
    assert dt < 1.0 / 240.0
    with pytest.raises(SimulationError):
        sim.step(2000)
    sim, idx = cloth(20, integrator="verlet", dt=0.95 * dt)
    anchor = sim.pos[idx[0, 0]].copy()
    sim.step(2000)
    assert np.all(np.isfinite(sim.pos))
    assert sim.pos[idx[0, 0]].tobytes() == anchor.tobytes()
