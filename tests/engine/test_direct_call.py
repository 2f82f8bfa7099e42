"""``engine.integrators.direct``: a Simulation's calls skip numba's type dispatch, which is
only sound if every call has the types of the first. Here every kind of scene the direct
calls serve runs with each call's types checked against the fixed signature."""
import math

import numpy as np
import pytest

import engine
from engine.forces import Coulomb, Drag, NBodyGravity, PointMass, Springs
from engine.integrators import direct, ias15, wisdom_holman
from engine.state import first_invalid


@pytest.fixture
def checked(monkeypatch):
    monkeypatch.setattr(direct, "CHECK", True)


def _orbit(sim, r, v, mass=0.0, test=False):
    return sim.add(pos=r, vel=v, mass=mass, test=test)


def _scenes():
    """(name, build) pairs covering modes, dimensions, spaces, particle flags and terms."""
    def lone_orbit_2d(integrator):
        sim = engine.Simulation(dim=2, integrator=integrator, dt=0.05)
        _orbit(sim, [1.0, 0.0], [0.0, 1.1], mass=1.0)
        sim.add_force(PointMass(mu=1.0))
        return sim

    def star_in_box(integrator):
        sim = engine.Simulation(dim=2, integrator=integrator, dt=0.01, box=10)
        _orbit(sim, [1.0, 0.0], [0.0, 1.0], mass=1.0)
        _orbit(sim, [-2.0, 0.0], [0.0, -0.7], mass=1.0)
        # off the half-box lines of the particles: there the attractor's nearest image jumps,
        # its force is discontinuous, and ias15's steps shrink towards the jump until they
        # collapse (as any adaptive high-order method's would)
        sim.add_force(PointMass(mu=1.0, pos=(4.0, 4.5)))
        sim.add_force(Drag(linear=1e-6))
        return sim

    def planets_3d(integrator):
        sim = engine.Simulation(dim=3, integrator=integrator, dt=0.02)
        sim.add(pos=[0, 0, 0], vel=[0, 0, 0], mass=1.0)
        sim.add(pos=[1, 0, 0], vel=[0, 1, 0.01], mass=1e-3)
        sim.add(pos=[0, 2, 0], vel=[-0.7, 0, 0], mass=1e-4)
        sim.add(pos=[3, 0, 0.1], vel=[0, 0.55, 0], mass=0.0, test=True)
        sim.add_force(NBodyGravity(G=1.0))
        return sim

    def planets_with_springs(integrator):
        sim = planets_3d(integrator)
        sim.add_force(Springs(pairs=[(1, 2)], k=1e-6, rest_length=1.0))
        return sim

    def charges(integrator):
        sim = engine.Simulation(dim=2, integrator=integrator, dt=0.001)
        sim.add(pos=[1.0, 0.0], vel=[0.0, 0.1], mass=1.0, charge=1.0)
        sim.add(pos=[2.0, 0.0], vel=[0.0, 0.0], mass=1.0, charge=1.0)
        sim.add_force(Coulomb(k=1.0))
        return sim

    return {"lone orbit 2d": lone_orbit_2d, "star in a box": star_in_box,
            "planets 3d": planets_3d, "planets with springs": planets_with_springs,
            "charges": charges}


KEPLER_SCENES = ("lone orbit 2d", "star in a box", "planets 3d", "planets with springs")


@pytest.mark.parametrize("integrator", ["whfast", "saba", "ias15"])
def test_every_direct_call_has_the_fixed_signature(checked, integrator):
    for name, build in _scenes().items():
        if integrator != "ias15" and name not in KEPLER_SCENES:
            continue
        sim = build(integrator)
        sim.step(3)
        sim.integrate(sim.t + 0.123)  # a shorter last step, a float t_end
        if integrator == "whfast":
            for corrector in (0, 11):
                sim.corrector = corrector
                sim.step(2)
            sim.kernel = "lazy"
            sim.step(2)
        # the arrays regrow (a light body: a massless one would feel an infinite drag)
        sim.add(pos=[3.0] + [0.0] * (sim.dim - 1), vel=[0.1] + [0.5] * (sim.dim - 1), mass=1e-3)
        sim.step(np.int64(2))  # numpy integers are converted
    assert direct.signature_of(wisdom_holman.advance if integrator != "ias15"
                               else ias15.advance) is not None
    assert direct.signature_of(first_invalid) is not None


def test_a_call_with_other_types_is_caught_by_the_check(checked):
    sim = engine.Simulation(dim=2, integrator="whfast", dt=0.05)
    sim.add(pos=[1.0, 0.0], vel=[0.0, 1.0], mass=1.0)
    sim.add_force(PointMass(mu=1.0))
    sim.step(1)
    state, _ = sim.kernel_arguments()
    bad = state._replace(box=0)  # an int where the kernels were compiled for a float
    with pytest.raises(TypeError, match="called directly with types"):
        direct.call(first_invalid, (bad,))


def test_direct_and_dispatched_calls_give_identical_bits():
    def run(direct_calls):
        sim = engine.Simulation(dim=3, integrator="whfast", dt=0.02, corrector=11)
        sim.add(pos=[0, 0, 0], vel=[0, 0, 0], mass=1.0)
        sim.add(pos=[1, 0, 0], vel=[0, 1, 0.01], mass=1e-3)
        sim.add(pos=[0, 2, 0], vel=[-0.7, 0, 0], mass=1e-4)
        sim.add_force(NBodyGravity(G=1.0))
        if direct_calls:
            sim.step(50)
        else:
            state, model = sim.kernel_arguments()
            plan = sim.kepler_plan()
            t, _, done, _ = engine.integrators.advance("whfast", 0.0, 0.02, 50, state, model,
                                                        False, plan=plan, corrector=11)
            assert done == 50 and t == pytest.approx(1.0)
        return sim.pos.copy(), sim.vel.copy()

    (p1, v1), (p2, v2) = run(True), run(False)
    assert np.array_equal(p1, p2) and np.array_equal(v1, v2)
    assert math.isfinite(p1.sum())
