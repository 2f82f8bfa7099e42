"""The Wisdom-Holman methods' fast Kepler drift against the engine's reference Kepler solver."""
import math

import numpy as np
import pytest

from engine import analytic
from engine.integrators import kepler_drift


@pytest.mark.parametrize("z", [0.0, 1e-9, 0.05, 0.1, 0.3, 2.0, 30.0, 400.0, -0.05, -3.0, -40.0])
def test_stumpff_functions_match_their_closed_forms(z):
    c = kepler_drift.stumpff(z)
    # the quadruple-argument steps round a little at large |z| (2e-14 measured at z = 400)
    np.testing.assert_allclose(c, analytic.stumpff(z), rtol=1e-13, atol=1e-16)


def _orbit(rng, e, dim):
    """A random state on an orbit of eccentricity e (a = 1 for ellipses, a = -1 for
    hyperbolas), mu = 1, at a random true anomaly (limited on hyperbolas)."""
    p = abs(1.0 - e * e) if e != 1.0 else 2.0
    nu_max = math.pi if e < 1.0 else 0.9 * math.acos(-1.0 / e)
    nu = rng.uniform(-nu_max, nu_max)
    r = p / (1.0 + e * math.cos(nu))
    pos = np.array([r * math.cos(nu), r * math.sin(nu), 0.0])
    vel = np.array([-math.sin(nu), e + math.cos(nu), 0.0]) / math.sqrt(p)
    if dim == 2:
        return pos[:2], vel[:2]
    tilt = rng.uniform(0, math.pi)
    rot = np.array([[1, 0, 0], [0, math.cos(tilt), -math.sin(tilt)],
                    [0, math.sin(tilt), math.cos(tilt)]])
    return rot @ pos, rot @ vel


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("e", [0.0, 0.3, 0.6, 0.9, 0.99, 1.5, 4.0])
def test_drift_matches_the_reference_kepler_solver(e, dim):
    """Steps from a thousandth of an orbit to several orbits: the same state to round-off of
    the state's own size (the largest difference measured was below 3e-13 of |r| and |v|)."""
    rng = np.random.default_rng(int(100 * e) + dim)
    worst = 0.0
    for _ in range(40):
        r0, v0 = _orbit(rng, e, dim)
        dt = 2 * math.pi * 10 ** rng.uniform(-3, 0.7) * rng.choice([-1.0, 1.0])
        if e >= 1.0:
            dt = min(abs(dt), 5.0) * np.sign(dt)
        jp = r0.reshape(dim, 1).copy()
        jv = v0.reshape(dim, 1).copy()
        kepler_drift.drift_column(jp, jv, 0, 1.0, dt, np.empty(dim), np.empty(dim))
        r, v = analytic.kepler(r0, v0, 1.0, dt)
        worst = max(worst, np.abs(jp[:, 0] - r).max() / np.abs(r).max(),
                    np.abs(jv[:, 0] - v).max() / np.abs(v).max())
    assert worst < 1e-11, worst
