"""The lecture's worked example: G = (0, -1), v0 = (2, 4), p0 = 0, dt = 1 (slides 57-59)."""
import numpy as np
import pytest

from engine import Simulation, forces, analytic

# Slide 59 (the table): velocity first, then position with the new velocity.
SYMPLECTIC_POS = [(2, 3), (4, 5), (6, 6), (8, 6), (10, 5), (12, 3), (14, 0)]
SYMPLECTIC_VEL = [(2, 3), (2, 2), (2, 1), (2, 0), (2, -1), (2, -2), (2, -3)]
# Slide 57 (the pseudo code): position with the old velocity, then velocity.
EULER_POS = [(2, 4), (4, 7), (6, 9), (8, 10), (10, 10), (12, 9), (14, 7)]
EULER_VEL = SYMPLECTIC_VEL


def _run(integrator):
    sim = Simulation(dim=2, integrator=integrator, dt=1.0)
    sim.add(mass=1.0, pos=(0.0, 0.0), vel=(2.0, 4.0))
    sim.add_force(forces.UniformGravity(g=(0.0, -1.0)))
    out = []
    for _ in range(7):
        sim.step()
        out.append((sim.t, sim.pos[0].copy(), sim.vel[0].copy()))
    return out


@pytest.mark.parametrize("integrator, positions, velocities", [
    ("symplectic_euler", SYMPLECTIC_POS, SYMPLECTIC_VEL),
    ("euler", EULER_POS, EULER_VEL),
])
def test_first_seven_steps_exact(integrator, positions, velocities):
    for k, (t, p, v) in enumerate(_run(integrator)):
        assert t == k + 1
        assert tuple(p) == positions[k]
        assert tuple(v) == velocities[k]


def test_step_n_in_one_call_equals_single_steps():
    sim = Simulation(dim=2, integrator="symplectic_euler", dt=1.0)
    sim.add(mass=1.0, pos=(0.0, 0.0), vel=(2.0, 4.0))
    sim.add_force(forces.UniformGravity(g=(0.0, -1.0)))
    sim.step(7)
    assert tuple(sim.pos[0]) == SYMPLECTIC_POS[-1]
    assert sim.t == 7.0 and sim.steps == 7


@pytest.mark.parametrize("integrator", ["leapfrog", "verlet", "rk4", "yoshida4", "pefrl"])
def test_second_order_and_better_are_exact_for_constant_force(integrator):
    # a quadratic trajectory is integrated exactly by any method of order >= 2
    t, p, v = _run(integrator)[-1]
    p_exact, v_exact = analytic.ballistic((0.0, 0.0), (2.0, 4.0), (0.0, -1.0), 7.0)
    np.testing.assert_allclose(p, p_exact, rtol=0, atol=1e-12)
    np.testing.assert_allclose(v, v_exact, rtol=0, atol=1e-12)
    assert tuple(p_exact) == (14.0, 3.5)
