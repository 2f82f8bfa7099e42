"""The force registry: every kind unique, declared once, and reached by the compiled table through its own kernels."""
import numpy as np
import pytest

from engine import Simulation, forces
from engine.forces import dispatch, registry
from engine.forces.pairwise import workspace

ENTRIES = registry.entries()


def _example(entry, dim):
    """A term of the entry's kind with non-trivial parameters, in a small scene."""
    sim = Simulation(dim=dim)
    rng = np.random.default_rng(entry.kind)
    sim.add_many(mass=rng.uniform(0.5, 2.0, 4), pos=rng.normal(size=(4, dim)),
                 vel=rng.normal(size=(4, dim)), charge=[1.0, -1.0, 2.0, 0.5],
                 radius=[0.6, 0.8, 0.5, 0.7])
    make = {
        "NBodyGravity": lambda: forces.NBodyGravity(G=0.7, softening=0.1),
        "PointMass": lambda: forces.PointMass(mu=2.0, pos=np.full(dim, 0.3), softening=0.1),
        "UniformGravity": lambda: forces.UniformGravity(g=np.arange(1.0, dim + 1.0)),
        "Coulomb": lambda: forces.Coulomb(k=0.4, softening=0.1),
        "Springs": lambda: forces.Springs([(0, 1), (1, 2), (2, 3)], k=3.0, rest_length=0.5,
                                          damping=0.2),
        "Drag": lambda: forces.Drag(linear=0.3, quadratic=0.2),
        "Thrust": lambda: forces.Thrust(),
        "Wind": lambda: forces.Wind(w=(0.5, 0.2, 1.0), triangles=[(0, 1, 2), (1, 2, 3)]),
        "Buoyancy": lambda: forces.Buoyancy(level=0.2, density=2.0, g=9.8, up=1),
        "Blast": lambda: forces.Blast(center=np.zeros(dim), strength=2.0, scale=0.5),
    }[entry.name]
    term = sim.add_force(make())
    if entry.name == "Thrust":
        term.set(1, np.ones(dim))
    return sim, term


def test_every_kind_is_unique_and_every_module_declares_a_term():
    kinds = [e.kind for e in ENTRIES]
    assert len(set(kinds)) == len(kinds) == len(registry.TERMS)
    for e in ENTRIES:
        assert e.term.KIND == e.kind and issubclass(e.term, forces.Force)
        assert e.doc and e.term.__doc__, e.name  # documented where it is declared
        assert registry.by_kind(e.kind) == e
        assert getattr(forces, e.name) is e.term  # and exported
    with pytest.raises(KeyError, match="no force term has kind 99"):
        registry.by_kind(99)


@pytest.mark.parametrize("entry", ENTRIES, ids=[e.name for e in ENTRIES])
def test_each_kind_reaches_both_dispatchers_through_its_own_kernels(entry):
    dim = 3 if entry.name == "Wind" else 2
    sim, term = _example(entry, dim)
    state, model = sim.kernel_arguments()
    n = state.n
    work = workspace(n)
    via_dispatch = np.zeros((dim, n))
    dispatch.accelerations(0.0, state, model, via_dispatch, work)
    direct = np.zeros((dim, n))
    entry.accumulate(0.0, state, model.params, model.param_offsets[0], model.param_offsets[1], model.indices,
                     model.index_offsets[0], model.index_offsets[1], direct, work)
    np.testing.assert_array_equal(via_dispatch, direct)
    assert np.abs(direct).max() > 0.0  # the example really acts
    out = np.zeros(1)
    dispatch.potential_terms(0.0, state, model, out)
    u = entry.potential(0.0, state, model.params, model.param_offsets[0], model.param_offsets[1], model.indices,
                        model.index_offsets[0], model.index_offsets[1])
    assert out[0] == u
    assert (u != 0.0) == entry.conservative  # only conservative terms have a potential
    # the table reaches the term through the addresses of this very module's kernels
    assert tuple(model.accumulators) + tuple(model.potentials) == dispatch.kernel_addresses(entry.kind)
    # a kind the registry does not know has no kernels to call
    with pytest.raises(KeyError, match="99"):
        dispatch.kernel_addresses(99)


@pytest.mark.parametrize("entry", ENTRIES, ids=[e.name for e in ENTRIES])
def test_the_layout_names_every_packed_float(entry):
    dim = 3 if entry.name == "Wind" else 2
    sim, term = _example(entry, dim)
    layout = term.layout(sim)
    _, model = sim.kernel_arguments()
    packed = model.param_offsets[1] - model.param_offsets[0]
    assert sum(int(np.prod(shape)) for _, shape in layout.values()) == packed
    for name, (offset, shape) in layout.items():
        value = sim.parameter(term, name)
        assert value.shape == shape
        np.testing.assert_array_equal(value.reshape(-1),
                                      model.params[model.param_offsets[0] + offset:][:value.size])


def test_parameters_read_by_name():
    sim = Simulation(dim=2)
    sim.add_many(mass=1.0, pos=np.zeros((3, 2)))
    star = sim.add_force(forces.PointMass(mu=2.0, pos=(0.25, -0.5), softening=0.5))
    thrust = sim.add_force(forces.Thrust())
    thrust.set(2, (1.0, 3.0))
    np.testing.assert_array_equal(sim.parameter(star, "pos"), (0.25, -0.5))
    assert sim.parameter(star, "softening_squared") == 0.25
    np.testing.assert_array_equal(sim.parameter(thrust, "force"), [[0, 0], [0, 0], [1.0, 3.0]])
    with pytest.raises(ValueError, match="PointMass has no parameter 'center'"):
        sim.parameter(star, "center")
