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


def _columns(rng, dim, count):
    """``count`` columns on random orbits of mu = 1 with eccentricities from circles to
    hyperbolas, as (dim, count) arrays."""
    jp = np.empty((dim, count))
    jv = np.empty((dim, count))
    for j in range(count):
        jp[:, j], jv[:, j] = _orbit(rng, rng.choice([0.0, 0.05, 0.3, 0.7, 0.95, 1.5]), dim)
    return jp, jv


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("orbits", [1e-4, 3e-3, 0.05, 0.4, 3.0])
def test_every_column_at_once_matches_one_column_at_a_time(dim, orbits):
    """``drift_columns`` (the lockstep solve of a step's columns) against the reference
    solver, as close as ``drift_column`` column by column (largest errors measured up to
    0.4 orbits: lockstep 1.4e-14, one at a time 8.2e-15; at 3 orbits 1.3e-12 both); columns
    with mu = 0 move in straight lines; columns before ``first`` are not touched."""
    rng = np.random.default_rng(int(1000 * orbits) + dim)
    count = 9
    jp, jv = _columns(rng, dim, count)
    mu = np.ones(count)
    mu[4] = 0.0
    dt = 2 * math.pi * orbits
    p1, v1 = jp.copy(), jv.copy()
    kepler_drift.drift_columns(p1, v1, 1, count, mu, dt,
                               np.empty((kepler_drift.SCRATCH_ROWS, count)))
    assert np.array_equal(p1[:, 0], jp[:, 0]) and np.array_equal(v1[:, 0], jv[:, 0])
    np.testing.assert_allclose(p1[:, 4], jp[:, 4] + dt * jv[:, 4], rtol=1e-15, atol=0)
    np.testing.assert_array_equal(v1[:, 4], jv[:, 4])
    worst = {"lockstep": 0.0, "one at a time": 0.0}
    for j in [1, 2, 3, 5, 6, 7, 8]:
        p2, v2 = jp.copy(), jv.copy()
        kepler_drift.drift_column(p2, v2, j, 1.0, dt, np.empty(dim), np.empty(dim))
        r, v = analytic.kepler(jp[:, j], jv[:, j], 1.0, dt)
        for name, (pp, vv) in {"lockstep": (p1, v1), "one at a time": (p2, v2)}.items():
            worst[name] = max(worst[name], np.abs(pp[:, j] - r).max() / np.abs(r).max(),
                              np.abs(vv[:, j] - v).max() / np.abs(v).max())
    assert worst["lockstep"] < 1e-11
    assert worst["lockstep"] < 4 * worst["one at a time"] + 1e-14
