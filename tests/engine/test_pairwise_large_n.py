"""The large-N gravity and Coulomb kernels (vectorised, multi-core) against a direct sum."""
import numpy as np
import pytest

from engine import Simulation, SimulationError, forces
from engine.forces import pairwise
from engine.state import EMPTY_WORKSPACE

from .test_forces import accel

N = pairwise.PARALLEL_MIN + 57
#: one size on the single-core vectorised kernel, one on the multi-core one
SIZES = [pairwise.PARALLEL_MIN + 57, pairwise.THREADS_MIN + 57]


def numpy_field(pos, weights, eps2, targets, sources, box=0.0):
    """a_i = sum_{j in sources, j != i} w_j d / (d^2 + eps^2)^1.5, in plain numpy."""
    out = np.zeros((len(targets), pos.shape[1]))
    for row, i in enumerate(targets):
        d = pos[sources] - pos[i]
        if box:
            d -= box * np.floor(d / box + 0.5)
        r2 = (d ** 2).sum(axis=1) + eps2
        w = weights[sources] / r2 ** 1.5
        w[np.asarray(sources) == i] = 0.0
        out[row] = (w[:, None] * d).sum(axis=0)
    return out


@pytest.mark.parametrize("n", SIZES)
@pytest.mark.parametrize("dim", [2, 3])
def test_gravity_large_n_matches_a_direct_sum(dim, n):
    rng = np.random.default_rng(dim)
    sim = Simulation(dim=dim)
    sim.add_many(mass=rng.uniform(0.5, 2.0, n), pos=rng.normal(size=(n, dim)),
                 test=rng.random(n) < 0.2)
    for i in rng.choice(n, 15, replace=False):
        sim.deactivate(int(i))
    sim.add_force(forces.NBodyGravity(G=0.7, softening=0.01))
    a = accel(sim)
    live = np.flatnonzero(sim.active)
    sources = [i for i in live if not sim.test[i]]
    expected = numpy_field(sim.pos, 0.7 * sim.mass, 1e-4, live, sources)
    np.testing.assert_allclose(a[live], expected, rtol=1e-11, atol=1e-12 * np.abs(expected).max())
    np.testing.assert_array_equal(a[~sim.active], 0.0)


@pytest.mark.parametrize("n", SIZES)
def test_coulomb_large_n_matches_a_direct_sum_on_a_torus(n):
    rng = np.random.default_rng(7)
    sim = Simulation(dim=2, box=10.0)
    sim.add_many(mass=rng.uniform(0.5, 2.0, n), pos=rng.uniform(-5, 5, size=(n, 2)),
                 charge=rng.choice([-1.0, 0.0, 1.0], n))
    sim.add_force(forces.Coulomb(k=0.3, softening=0.05))
    a = accel(sim)
    charged = np.flatnonzero(sim.charge != 0)
    field = numpy_field(sim.pos, sim.charge, 0.0025, charged, charged, box=10.0)
    expected = -0.3 * (sim.charge[charged] / sim.mass[charged])[:, None] * field
    np.testing.assert_allclose(a[charged], expected, rtol=1e-11, atol=1e-12 * np.abs(expected).max())


@pytest.mark.parametrize("kind", ["gravity", "coulomb"])
def test_without_a_workspace_the_scalar_loop_gives_the_same_field(kind):
    # Spacewar's compiled frame passes no workspace: the kernels must not touch it then
    from engine.forces.dispatch import accelerations

    rng = np.random.default_rng(11)
    n = SIZES[1]
    sim = Simulation(dim=3)
    sim.add_many(mass=rng.uniform(0.5, 2.0, n), pos=rng.normal(size=(n, 3)),
                 charge=rng.choice([-1.0, 1.0], n), test=rng.random(n) < 0.2)
    term = forces.NBodyGravity(softening=0.01) if kind == "gravity" else forces.Coulomb(softening=0.01)
    sim.add_force(term)
    state, model = sim.kernel_arguments()
    m = state.n
    vectorised = np.zeros((3, m))
    accelerations(sim.t, state, model, vectorised, pairwise.workspace(m))
    scalar = np.zeros((3, m))
    accelerations(sim.t, state, model, scalar, EMPTY_WORKSPACE)
    np.testing.assert_allclose(vectorised, scalar, rtol=1e-11, atol=1e-13 * np.abs(scalar).max())
    assert np.abs(scalar).max() > 0.1


def test_large_n_momentum_and_determinism():
    def run():
        rng = np.random.default_rng(3)
        sim = Simulation(dim=3, integrator="leapfrog", dt=1e-3)
        sim.add_many(mass=rng.uniform(0.5, 2.0, N), pos=rng.normal(size=(N, 3)),
                     vel=rng.normal(size=(N, 3)) * 0.1)
        sim.add_force(forces.NBodyGravity(softening=0.05))
        p0 = sim.momentum()
        sim.step(20)
        return sim, p0
    a, p0 = run()
    b, _ = run()
    assert a.pos.tobytes() == b.pos.tobytes()
    # each pair is evaluated once, but its two sides are scaled by different masses, so
    # momentum holds to round-off only
    np.testing.assert_allclose(a.momentum(), p0, atol=1e-11 * a.mass.sum())


#: particle counts around the kernel's edges: fewer sources than a four, counts that are not a
#: multiple of four, the first sizes on all cores, and where the chunks' rows move
AWKWARD = [pairwise.PARALLEL_MIN, pairwise.PARALLEL_MIN + 1, pairwise.PARALLEL_MIN + 3, 31,
           pairwise.THREADS_MIN, pairwise.THREADS_MIN + 1, pairwise.THREADS_MIN + 3, 517]


@pytest.mark.parametrize("n", AWKWARD)
def test_each_pair_once_matches_a_direct_sum_at_awkward_sizes(n):
    rng = np.random.default_rng(n)
    test = np.zeros(n, dtype=bool)
    test[rng.choice(n, min(n - 2, 9), replace=False)] = True  # as few as 2 sources
    sim = Simulation(dim=3)
    sim.add_many(mass=rng.uniform(0.5, 2.0, n), pos=rng.normal(size=(n, 3)), test=test)
    sim.add_force(forces.NBodyGravity(G=1.3, softening=0.02))
    a = accel(sim)
    sources = np.flatnonzero(~test)
    expected = numpy_field(sim.pos, 1.3 * sim.mass, 4e-4, range(n), sources)
    np.testing.assert_allclose(a, expected, rtol=1e-11, atol=1e-12 * np.abs(expected).max())


def test_each_pair_once_gives_equal_and_opposite_forces():
    """Without test particles, the sum of m_i a_i over all bodies is zero to round-off of the
    forces' size (each pair's two sides come from one evaluation of d / r^3)."""
    rng = np.random.default_rng(12)
    n = 300
    sim = Simulation(dim=3)
    sim.add_many(mass=rng.uniform(0.5, 2.0, n), pos=rng.normal(size=(n, 3)))
    sim.add_force(forces.NBodyGravity(softening=0.01))
    force = sim.mass[:, None] * accel(sim)
    assert np.abs(force.sum(axis=0)).max() < 1e-13 * np.abs(force).sum()


@pytest.mark.parametrize("precision", ["float64", "float32"])
def test_the_pair_sum_is_the_same_to_the_bit_on_one_thread_and_on_all(precision):
    import numba

    rng = np.random.default_rng(21)
    n = pairwise.THREADS_MIN + 301
    sim = Simulation(dim=3)
    sim.add_many(mass=rng.uniform(0.5, 2.0, n), pos=rng.normal(size=(n, 3)),
                 test=rng.random(n) < 0.1)
    sim.add_force(forces.NBodyGravity(softening=0.01, precision=precision))
    threads = numba.get_num_threads()
    fields = []
    try:  # one thread against all numba may start (a test worker runs on one thread)
        for count in (1, numba.config.NUMBA_NUM_THREADS):
            numba.set_num_threads(count)
            fields.append(accel(sim))
    finally:
        numba.set_num_threads(threads)
    assert fields[0].tobytes() == fields[1].tobytes()


def test_the_tree_workspace_is_large_enough_for_the_direct_kernels():
    """A scene with a tree term hands the tree's workspace to every term, direct ones too: the
    direct kernels must find room in it at every size, or they would fall back to the scalar
    loop (correct, five times slower)."""
    from engine.tree import layout

    sizes = list(range(pairwise.PARALLEL_MIN, 5000, 37)) + [10 ** 5, 10 ** 6, 10 ** 7]
    short = [n for n in sizes if layout.float_count(n, layout.THREADS) < pairwise.float_count(n)]
    assert short == []


def test_large_n_coincident_bodies_still_fail_loudly():
    rng = np.random.default_rng(4)
    sim = Simulation(dim=3, integrator="symplectic_euler", dt=1e-3)
    pos = rng.normal(size=(N, 3))
    pos[10] = pos[20]
    sim.add_many(mass=1.0, pos=pos)
    sim.add_force(forces.NBodyGravity())
    before = sim.pos.copy()
    with pytest.raises(SimulationError) as info:
        sim.step(3)
    assert info.value.particle in (10, 20)
    np.testing.assert_array_equal(sim.pos, before)


@pytest.mark.parametrize("n", SIZES)
@pytest.mark.parametrize("box", [None, 30.0])
def test_float32_gravity_is_the_float64_field_to_single_precision(n, box):
    rng = np.random.default_rng(n)
    # a cluster far from the origin: float32 coordinates are taken relative to its centre
    pos = rng.normal(size=(n, 3)) + 1e4 * (box is None)
    masses = rng.uniform(0.5, 2.0, n)
    fields = {}
    for precision in ("float64", "float32"):
        sim = Simulation(dim=3, box=box)
        sim.add_many(mass=masses, pos=pos, test=np.arange(n) % 7 == 3)
        sim.add_force(forces.NBodyGravity(softening=0.01, precision=precision))
        fields[precision] = accel(sim)
    exact, single = fields["float64"], fields["float32"]
    scale = np.linalg.norm(exact, axis=1)
    err = np.linalg.norm(single - exact, axis=1) / scale
    assert err.max() < 1e-4 and np.median(err) < 1e-5
    assert err.max() > 1e-12  # it really is a different computation


def test_precision_is_checked():
    with pytest.raises(ValueError, match="precision.*'float16'"):
        forces.NBodyGravity(precision="float16")


@pytest.mark.parametrize("scale", [1e-9, 1.0, 3.844e8, 1e20])
def test_float32_gravity_holds_in_any_units(scale):
    """A bound system measured in any length unit (1e-9: nanometres of a unit-mass toy; 3.8e8:
    the Earth-Moon distance in metres; 1e20: a galaxy in metres): single precision forces stay
    finite and close to float64 (r^3 of SI distances overflows float32 unless the kernel works
    in a scaled frame)."""
    rng = np.random.default_rng(5)
    n = pairwise.PARALLEL_MIN + 20
    pos = rng.normal(size=(n, 3)) * scale
    pos[0] *= 50.0  # one outlier far from the rest
    masses = rng.uniform(0.5, 2.0, n)
    fields = {}
    for precision in ("float64", "float32"):
        sim = Simulation(dim=3, G=6.674e-11 * scale ** 3)  # keeps accelerations of order one
        sim.add_many(mass=masses, pos=pos)
        sim.add_force(forces.NBodyGravity(precision=precision))
        fields[precision] = accel(sim)
    exact, single = fields["float64"], fields["float32"]
    assert np.isfinite(single).all()
    err = np.linalg.norm(single - exact, axis=1) / np.linalg.norm(exact, axis=1)
    assert err.max() < 1e-4 and np.median(err) < 1e-5
