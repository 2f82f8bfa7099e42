"""Springs that yield and break: closed forms for held ends, the weakest link, the energy
bookkeeping, bad input."""
import math

import numpy as np
import pytest

from engine import Simulation, forces


def held_spring(length, rest=1.0, k=10.0, dt=0.1, **plastic):
    """One spring between two pinned particles ``length`` apart."""
    sim = Simulation(dim=2, integrator="leapfrog", dt=dt)
    sim.add(mass=1.0, pos=(0.0, 0.0), pinned=True)
    sim.add(mass=1.0, pos=(length, 0.0), pinned=True)
    springs = forces.Springs([(0, 1)], k=k, rest_length=rest, **plastic)
    sim.add_force(springs)
    return sim, springs


@pytest.mark.parametrize("length", [1.3, 0.7])  # stretched, compressed: strain +-0.3
@pytest.mark.parametrize("dt", [0.1, 0.01])
def test_a_held_spring_past_yield_flows_at_its_rate_to_the_yield_strain(length, dt):
    sim, springs = held_spring(length, dt=dt, yield_strain=0.1, break_strain=0.5,
                               flow_rate=2.0)
    e0 = sim.energy()
    sim.integrate(0.1)
    # dl/dt = 2 (r - l) from l = 1: exactly r + (1 - r) exp(-2 t), whatever dt
    assert springs.rest_length[0] == pytest.approx(length + (1 - length) * math.exp(-0.2),
                                                   rel=1e-14)
    sim.integrate(5.0)
    # the flow stops where the strain is the yield strain
    stop = length / 1.1 if length > 1 else length / 0.9
    assert springs.rest_length[0] == pytest.approx(stop, rel=1e-14)
    # the elastic energy it released is in the ledger
    assert sim.energy() == pytest.approx(0.5 * 10.0 * (length - stop) ** 2, rel=1e-12)
    assert sim.energy() + sim.energy_ledger == pytest.approx(e0, rel=1e-12)
    assert not springs.broken[0] and sim.contacts == ()


def test_below_yield_nothing_flows():
    sim, springs = held_spring(1.05, yield_strain=0.1)
    sim.step(50)
    assert springs.rest_length[0] == 1.0 and sim.energy_ledger == 0.0


def test_a_spring_stretched_past_yield_and_let_go_keeps_a_longer_length():
    sim = Simulation(dim=2, integrator="leapfrog", dt=0.01)
    sim.add(mass=1.0, pos=(0.0, 0.0), pinned=True)
    sim.add(mass=1.0, pos=(1.0, 0.0), vel=(2.0, 0.0))  # yanked: strain reaches about 0.6
    springs = forces.Springs([(0, 1)], k=10.0, rest_length=1.0, yield_strain=0.05,
                             break_strain=2.0, flow_rate=20.0)
    sim.add_force(springs)
    lengths = []
    for _ in range(400):
        sim.step(5)
        lengths.append(sim.pos[1, 0])
    # it oscillates about its new rest length, which stays put once the strain is small
    late = np.array(lengths[200:])
    assert springs.rest_length[0] > 1.3
    assert abs(late.mean() - springs.rest_length[0]) < 0.02
    assert np.abs(late - springs.rest_length[0]).max() <= 0.05 * springs.rest_length[0] + 1e-9


def test_a_rope_pulled_parts_at_its_weakest_spring():
    sim = Simulation(dim=2, integrator="leapfrog", dt=1e-3)
    idx = sim.add_many(mass=1.0, pos=np.column_stack((np.arange(11.0), np.zeros(11))))
    sim.pin(int(idx[0]))
    # a heavy end pulls the rope slowly (10 times below its wave speed, 7 lengths a unit of
    # time): the strain stays nearly even along it, and the weakest spring goes
    sim.vel[10] = (0.5, 0.0)
    sim.mass[10] = 1e4
    weak = 6
    strain = np.full(10, 0.3)
    strain[weak] = 0.2
    springs = forces.Springs(np.column_stack((idx[:-1], idx[1:])), k=50.0, rest_length=1.0,
                             break_strain=strain)
    sim.add_force(springs)
    e0 = sim.energy()
    sim.integrate(4.0)  # it parts at about t = 3.5
    breaks = [c for c in sim.contacts if c.action == "break"]
    assert len(breaks) == 1
    (c,) = breaks
    assert (c.i, c.j) == (int(idx[weak]), int(idx[weak + 1])) and c.speed > 0
    assert springs.broken.tolist() == [k == weak for k in range(10)]
    assert springs.k[weak] == 0.0 and c.energy == pytest.approx(0.5 * 50.0 * 0.2 ** 2, rel=0.05)
    # the energy the break took out is the ledger's (leapfrog's own error aside)
    assert abs(sim.energy() + sim.energy_ledger - e0) < 0.05 * c.energy


def test_bad_plastic_parameters_are_refused_naming_the_value():
    with pytest.raises(ValueError, match="yield_strain must be below break_strain.*0.5.*0.2"):
        forces.Springs([(0, 1)], yield_strain=0.5, break_strain=0.2)
    with pytest.raises(ValueError, match="yield_strain must be > 0"):
        forces.Springs([(0, 1)], yield_strain=-0.1)
    with pytest.raises(ValueError, match="break_strain must be finite"):
        forces.Springs([(0, 1)], break_strain=float("nan"))
    with pytest.raises(ValueError, match="flow_rate must be >= 0"):
        forces.Springs([(0, 1)], yield_strain=0.1, flow_rate=-1.0)
    with pytest.raises(ValueError, match=r"rest_length\[0\] = 0.0"):
        forces.Springs([(0, 1)], rest_length=0.0, break_strain=1.0)
    assert not forces.Springs([(0, 1)]).plastic


def test_a_batch_refuses_plastic_springs_and_keeps_its_terms():
    from engine import Batch

    batch = Batch(systems=2, dim=2, integrator="leapfrog", dt=0.01, capacity=4)
    batch.add_many(mass=np.ones((2, 2)), pos=np.array([[[0.0, 0.0], [1.0, 0.0]]] * 2))
    with pytest.raises(ValueError, match="Batch does not take plastic springs"):
        batch.add_force(forces.Springs([(0, 1)], break_strain=0.5))
    assert batch.forces == ()
    batch.add_force(forces.Springs([(0, 1)]))
    assert len(batch.forces) == 1
