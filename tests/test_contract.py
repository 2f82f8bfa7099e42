"""The public names of shared/DESIGN.md's "Contract", used exactly as written there."""
import math

import numpy as np
import pytest


def test_engine_contract():
    import engine
    from engine import Simulation, analytic, forces

    sim = Simulation(dim=2, integrator="symplectic_euler", dt=1.0)
    i = sim.add(mass=1.0, pos=(0.0, 0.0), vel=(2.0, 4.0))
    sim.add_force(forces.UniformGravity(g=(0.0, -1.0)))
    sim.step()
    sim.step(3)
    assert (sim.t, sim.dt) == (4.0, 1.0)
    assert sim.pos.shape == (1, 2) and sim.vel.shape == (1, 2) and sim.mass.shape == (1,)
    sim.dt = -sim.dt
    sim.step(4)
    assert sim.t == 0.0 and sim.dt == -1.0
    sim.integrate(2.5)
    assert sim.t == 2.5
    for value in (sim.energy(), sim.kinetic_energy(), sim.potential_energy()):
        assert math.isfinite(value)
    assert sim.momentum().shape == (2,) and isinstance(sim.angular_momentum(), float)
    assert engine.INTEGRATORS[:8] == ("euler", "symplectic_euler", "leapfrog", "verlet", "rk4",
                                      "yoshida4", "pefrl", "rk45")
    assert "whfast" in engine.INTEGRATORS
    assert set(engine.ADAPTIVE_INTEGRATORS) <= set(engine.INTEGRATORS)
    assert "rk45" in engine.ADAPTIVE_INTEGRATORS
    Simulation(integrator="rk45", dt=0.01, tolerance=1e-10)
    s3 = Simulation(dim=3, units=("AU", "yr", "Msun"))
    assert s3.G == pytest.approx(39.478, rel=1e-3)
    forces.NBodyGravity(G=None, softening=0.0)
    forces.PointMass(mu=1.0, pos=(0.0, 0.0))
    forces.UniformGravity(g=(0.0, -9.8))
    forces.Coulomb(k=1.0, softening=0.0)
    forces.Springs(pairs=[(0, 1)], k=10.0, rest_length=1.0, damping=0.0)
    forces.Drag(linear=0.0, quadratic=0.0)
    s2 = Simulation(dim=2)
    j = s2.add(mass=2.0)
    thrust = forces.Thrust()
    s2.add_force(thrust)
    thrust.set(j, (1.0, 0.5))
    p, v = analytic.ballistic((0.0, 0.0), (2.0, 4.0), (0.0, -1.0), 1.0)
    np.testing.assert_allclose(p, (2.0, 3.5))
    r, v = analytic.kepler((1.0, 0.0), (0.0, 1.0), 1.0, math.pi)
    np.testing.assert_allclose(r, (-1.0, 0.0), atol=1e-12)
    assert issubclass(engine.SimulationError, Exception)


def test_spacewar_contract():
    import spacewar
    from spacewar.cli import build_parser

    a = spacewar.Action(turn=-1, thrust=False, fire=False, hyperspace=False)
    assert a.turn == -1
    parser = build_parser()
    parser.parse_args(["bots"])
    parser.parse_args(["match", "--p1", "chaser", "--p2", "sniper", "--seed", "7", "--rounds", "5",
                       "--json", "--replay", "FILE"])
    parser.parse_args(["replay", "FILE", "--check"])
    parser.parse_args(["replay", "FILE", "--gif", "OUT.gif"])
    parser.parse_args(["tournament", "--bots", "idle,random,chaser,sniper", "--games", "10",
                       "--seed", "1", "--workers", "2", "--json"])
    parser.parse_args(["play", "--p2", "chaser"])
