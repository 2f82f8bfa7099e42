"""A gas of hard disks (2-D) and hard spheres (3-D) in a periodic box, started with one speed
for all: the speeds relax to the Maxwell-Boltzmann law of the dimension, and the pressure from
the collisional virial matches the hard-disk and hard-sphere equations of state."""
import math

import numpy as np
import pytest

from engine import Collisions, Simulation

RADIUS = 0.5


def gas(dim, n, packing, seed=1):
    """n equal spheres at ``packing`` (the fraction of the box they fill), speeds all 1 in
    random directions, no overlaps (placed on a jittered lattice), zero total momentum."""
    rng = np.random.default_rng(seed)
    volume = n * (math.pi * RADIUS ** 2 if dim == 2 else 4 / 3 * math.pi * RADIUS ** 3) / packing
    side = volume ** (1 / dim)
    per_side = math.ceil(n ** (1 / dim))
    spacing = side / per_side
    cells = np.stack(np.meshgrid(*[np.arange(per_side)] * dim, indexing="ij"), -1)
    cells = cells.reshape(-1, dim)[rng.permutation(per_side ** dim)[:n]]
    jitter = rng.uniform(-1, 1, (n, dim)) * (spacing / 2 - RADIUS) * 0.9
    pos = (cells + 0.5) * spacing - side / 2 + jitter
    direction = rng.normal(size=(n, dim))
    vel = direction / np.linalg.norm(direction, axis=1)[:, None]
    vel -= vel.mean(axis=0)
    vel /= np.sqrt((vel ** 2).sum(axis=1).mean())  # mean square speed 1
    sim = Simulation(dim=dim, integrator="leapfrog", dt=0.05, box=side)
    sim.add_many(mass=1.0, pos=pos, vel=vel, radius=RADIUS)
    sim.collisions = Collisions(restitution=1.0)
    return sim


def speed_cdf(v, dim, kT):
    """The Maxwell-Boltzmann speed distribution's CDF for unit mass: Rayleigh in 2-D,
    Maxwell in 3-D (a = sqrt(kT))."""
    x = v / math.sqrt(kT)
    if dim == 2:
        return 1.0 - np.exp(-x * x / 2)
    erf = np.vectorize(math.erf)
    return erf(x / math.sqrt(2)) - np.sqrt(2 / math.pi) * x * np.exp(-x * x / 2)


def ks_p_value(samples, cdf):
    """Kolmogorov-Smirnov: the largest gap between the samples' CDF and ``cdf``, and its
    p-value by Kolmogorov's asymptotic series (with Stephens's small-sample correction)."""
    x = np.sort(samples)
    n = len(x)
    f = cdf(x)
    d = max((np.arange(1, n + 1) / n - f).max(), (f - np.arange(n) / n).max())
    lam = (math.sqrt(n) + 0.12 + 0.11 / math.sqrt(n)) * d
    p = 2 * sum((-1) ** (k - 1) * math.exp(-2 * k * k * lam * lam) for k in range(1, 101))
    return d, min(max(p, 0.0), 1.0)


@pytest.mark.parametrize("dim, n, packing", [(2, 400, 0.2), (3, 512, 0.1)])
def test_speeds_relax_to_maxwell_boltzmann_and_the_pressure_follows_the_equation_of_state(
        dim, n, packing):
    sim = gas(dim, n, packing)
    kT = 1.0 / dim  # mean square speed 1, unit masses: kT = <v^2> / dim
    start = np.linalg.norm(sim.vel, axis=1)
    assert ks_p_value(start, lambda v: speed_cdf(v, dim, kT))[1] < 1e-6  # the control
    e0, p0 = sim.energy(), sim.momentum().copy()
    sim.integrate(20.0)  # relax: about 20 contacts a sphere
    # then measure: the speeds at three moments, the virial over the run
    virial, span, p_values = 0.0, 60.0, []
    for _ in range(3):
        sim.integrate(sim.t + span / 3)
        # each elastic contact of equal masses exchanges an impulse J = m u_n along the line
        # of centres at separation 2 RADIUS: the virial sum_contacts J sigma
        virial += sum(c.speed * 2 * RADIUS for c in sim.contacts)
        p_values.append(ks_p_value(np.linalg.norm(sim.vel, axis=1),
                                   lambda v: speed_cdf(v, dim, kT))[1])
    assert min(p_values) > 0.01, p_values
    # P V = N kT + (1 / dim) <sum J . r> / time (the collisional virial, e.g. Allen &
    # Tildesley, Computer Simulation of Liquids, section 2.4)
    z = 1.0 + virial / (dim * span * n * kT)
    if dim == 2:
        eta = packing
        expected = (1 + eta * eta / 8) / (1 - eta) ** 2  # Henderson 1975, Mol. Phys. 30, 971
    else:
        eta = packing  # Carnahan & Starling 1969, J. Chem. Phys. 51, 635
        expected = (1 + eta + eta ** 2 - eta ** 3) / (1 - eta) ** 3
    assert z == pytest.approx(expected, rel=0.02), (z, expected)
    assert sim.energy() == pytest.approx(e0, rel=1e-11)
    np.testing.assert_allclose(sim.momentum(), p0, atol=1e-11 * n)
