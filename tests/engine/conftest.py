import math

import numpy as np
import pytest

from engine import Simulation, forces


def kepler_initial(e, mu=1.0):
    """Pericentre start of an orbit with semi-major axis 1 (Hairer, Lubich & Wanner's Kepler)."""
    return np.array([1.0 - e, 0.0]), np.array([0.0, math.sqrt(mu * (1.0 + e) / (1.0 - e))])


def kepler_sim(e, integrator, dt, mu=1.0, **kw):
    """A test particle around a fixed attractor (exactly the two-body relative motion)."""
    sim = Simulation(dim=2, integrator=integrator, dt=dt, **kw)
    r0, v0 = kepler_initial(e, mu)
    sim.add(mass=1.0, pos=r0, vel=v0)
    sim.add_force(forces.PointMass(mu=mu, pos=(0.0, 0.0)))
    return sim


@pytest.fixture
def kepler():
    return kepler_sim
