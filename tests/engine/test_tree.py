"""The tree (``engine.tree``; ``NBodyGravity`` and ``Coulomb`` with ``method="tree"``, its
Barnes-Hut walk, ``"fmm"``, its fast multipole walk, and ``"auto"``): forces against the direct sum, the multipoles against their definition and
the Salmon & Warren (1994, J. Comput. Phys. 111, 136) error bound, particle flags, the same
bits at any thread count and particle order, energy and momentum in a run, REBOUND's tree,
the integrators, refusals, bad input, the workspace, lazy loading and ``"auto"``.

An error is per particle, |a_tree - a_direct| / |a_direct| against the engine's own direct sum
on the same scene, summarised by its median and 99th percentile (``tree_scenes``). Bounds are
2 times the values measured (given beside them) on the seeded scenes here: the figures are
deterministic, and a compiler's different round-off moves them by far less.
"""
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numba
import numpy as np
import pytest

from engine import Batch, Simulation, forces
from engine import initial_conditions as ic
from engine.errors import SimulationError
from engine.forces import tree_terms
from engine.integrators import GENERAL
from engine.tree import field, layout
from engine.tree import multipoles as mp

from .tree_scenes import (SCENES, ExactEnergy, accelerations, permuted, relative_errors, scene,
                          simulation, summary)

ROOT = Path(__file__).resolve().parents[2]
THETAS = (0.3, 0.5, 0.7)
EPS = 0.01
#: the tree's two walks
METHODS = ("tree", "fmm")
#: a bound is this many times the value measured
MARGIN = 2.0

# Softening 0 is tested beside softening EPS: a particle's pair with itself must be dropped
# without 0 * inf = NaN (walk.sum_own_group).


def gravity(**options):
    return forces.NBodyGravity(softening=options.pop("softening", EPS), **options)


def coulomb(**options):
    return forces.Coulomb(softening=options.pop("softening", EPS), **options)


def tree_errors(bodies, make, reference, method="tree", **options):
    """Per-particle errors of the tree term ``make(method=method, **options)``."""
    return relative_errors(accelerations(bodies, make(method=method, **options)), reference)


# -- 1. gravity against the direct sum ---------------------------------------------------------

# (median, 99th percentile) of the error at theta = 0.3, 0.5, 0.7: N = 3000, seed 1, softening
# 0.01, for each walk (at softening 0, which the tree evaluates, every value is within 1.0-1.2
# times these or below them, so the unsoftened case takes the same bounds). The fast multipole
# walk's 2-D errors are 2 to 6 times the Barnes-Hut walk's at the same theta: its cells act on
# whole target cells, which in a plane have fewer near neighbours to sum exactly
GRAVITY_ERRORS = {"tree": {
    ("plummer", 2): ((3.5e-05, 3.9e-04), (2.0e-04, 3.5e-03), (1.1e-03, 1.5e-02)),
    ("plummer", 3): ((3.1e-05, 1.8e-04), (1.9e-04, 1.4e-03), (8.4e-04, 5.0e-03)),
    ("cube", 2): ((6.7e-05, 6.3e-04), (5.8e-04, 9.0e-03), (2.9e-03, 4.3e-02)),
    ("cube", 3): ((4.2e-05, 2.8e-04), (2.2e-04, 1.9e-03), (9.5e-04, 6.9e-03)),
    ("disk", 2): ((6.1e-05, 1.1e-03), (4.6e-04, 1.2e-02), (2.2e-03, 4.4e-02)),
    ("disk", 3): ((5.5e-05, 5.0e-04), (4.1e-04, 4.6e-03), (1.9e-03, 1.5e-02)),
    ("clumps", 2): ((3.7e-05, 4.0e-04), (2.3e-04, 4.7e-03), (1.2e-03, 1.7e-02)),
    ("clumps", 3): ((2.2e-05, 1.6e-04), (1.8e-04, 1.5e-03), (9.0e-04, 5.7e-03)),
}, "fmm": {
    ("plummer", 2): ((5.0e-05, 1.2e-03), (6.0e-04, 1.6e-02), (3.2e-03, 6.6e-02)),
    ("plummer", 3): ((3.0e-05, 4.3e-04), (2.1e-04, 3.9e-03), (1.1e-03, 1.3e-02)),
    ("cube", 2): ((2.8e-04, 4.4e-03), (3.4e-03, 5.3e-02), (1.2e-02, 2.2e-01)),
    ("cube", 3): ((5.2e-05, 3.5e-04), (3.9e-04, 2.9e-03), (2.1e-03, 2.6e-02)),
    ("disk", 2): ((1.4e-04, 2.8e-03), (2.0e-03, 3.4e-02), (7.7e-03, 1.9e-01)),
    ("disk", 3): ((1.2e-04, 1.2e-03), (1.7e-03, 1.6e-02), (6.3e-03, 8.5e-02)),
    ("clumps", 2): ((4.7e-05, 1.0e-03), (5.2e-04, 1.5e-02), (2.3e-03, 5.4e-02)),
    ("clumps", 3): ((2.3e-05, 3.5e-04), (2.1e-04, 4.7e-03), (1.1e-03, 1.5e-02)),
}}


def check_falling_errors(bodies, make, reference, measured, method="tree", **options):
    """theta = 0 is the direct sum to round-off; at each theta of ``THETAS`` the median and
    99th percentile stay below ``MARGIN`` times ``measured``, and both fall as theta falls."""
    exact = tree_errors(bodies, make, reference, method, theta=0.0, **options)
    assert exact.max() < 1e-12, exact.max()
    found = [summary(tree_errors(bodies, make, reference, method, theta=theta, **options))
             for theta in THETAS]
    for theta, (median, p99), (m0, p0) in zip(THETAS, found, measured):
        assert median < MARGIN * m0 and p99 < MARGIN * p0, (theta, median, p99)
    for (m_low, p_low), (m_high, p_high) in zip(found, found[1:]):
        assert m_low < m_high and p_low < p_high, found
    return found


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("softening", [EPS, 0.0])
@pytest.mark.parametrize("dim", (2, 3))
@pytest.mark.parametrize("name", SCENES)
def test_gravity_matches_the_direct_sum(name, dim, softening, method):
    bodies = scene(name, 3000, dim)
    reference = accelerations(bodies, gravity(softening=softening))
    assert np.all(np.isfinite(reference))
    check_falling_errors(bodies, gravity, reference, GRAVITY_ERRORS[method][name, dim],
                         method, softening=softening)


@pytest.mark.parametrize("method", METHODS)
def test_the_gravity_bounds_catch_a_tree_without_its_quadrupole(method):
    """Positive control: the monopole alone (order 0) on the 3-D Plummer sphere at theta =
    0.3: median 1.7e-4 (Barnes-Hut) and 1.5e-4 (FMM), 5.6 and 5.2 times the quadrupole's,
    and more than twice the bound above (about the centre of mass the dipole vanishes, so
    the monopole is the first two orders, and the quadrupole gains one more)."""
    bodies = scene("plummer", 3000, 3)
    reference = accelerations(bodies, gravity())
    median, _ = summary(tree_errors(bodies, gravity, reference, method, theta=0.3, order=0))
    assert median > 2.0 * MARGIN * GRAVITY_ERRORS[method]["plummer", 3][0][0]


@pytest.mark.parametrize("method", METHODS)
def test_unsoftened_tree_forces_are_finite(method):
    """Two bodies 1 apart at softening 0 (the default): the direct sum gives (1, 0, 0) and
    (-1, 0, 0); the tree gives NaN for both, and a step raises SimulationError."""
    bodies = ic.Bodies([1.0, 1.0], [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], np.zeros((2, 3)),
                       [0.0, 0.0])
    direct = accelerations(bodies, forces.NBodyGravity())
    assert np.array_equal(direct, [[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]])
    sim = simulation(bodies, forces.NBodyGravity(method=method))
    assert np.allclose(sim.accelerations(), direct, rtol=0.0, atol=1e-15)
    try:
        sim.step(1)
    except SimulationError as error:
        pytest.fail(f"a step of two bodies 1 apart: {error}")


@pytest.mark.parametrize("method", METHODS)
def test_potential_energy_by_the_tree(method):
    """``potential_energy`` of a tree term is the tree's, at its theta: the direct sum's to
    round-off at theta = 0 (measured 2.6e-14), within the force error's order at 0.5
    (measured POTENTIAL_ERRORS)."""
    bodies = scene("plummer", 3000, 3)
    exact = simulation(bodies, gravity()).potential_energy()
    at_zero = simulation(bodies, gravity(method=method, theta=0.0)).potential_energy()
    at_half = simulation(bodies, gravity(method=method, theta=0.5)).potential_energy()
    assert abs(at_zero / exact - 1.0) < 1e-12
    assert 1e-8 < abs(at_half / exact - 1.0) < MARGIN * POTENTIAL_ERRORS[method]


#: |U_tree / U - 1| at theta = 0.5 on the scene above, by walk
POTENTIAL_ERRORS = {"tree": 1.45e-5, "fmm": 1.37e-5}


# -- 2. Coulomb ---------------------------------------------------------------------------------

# (median, 99th percentile) at theta = 0.3, 0.5, 0.7 for orders 2, 1, 0: N = 3000, seed 1,
# softening 0.01, side 1, for each walk. The neutral plasma's quadrupole error (3-D, theta =
# 0.5, Barnes-Hut): median 1.2e-3, 99th percentile 1.0e-2, 5 times the one-sign cloud's (its
# cells nearly cancel, so what is left of their field is all dipole and quadrupole, and the
# remainder is larger in proportion).
COULOMB_ERRORS = {"tree": {
    ("plasma", 3): {2: ((2.3e-04, 1.5e-03), (1.2e-03, 1.0e-02), (5.3e-03, 3.9e-02)),
                    1: ((1.2e-03, 7.9e-03), (5.1e-03, 3.5e-02), (1.5e-02, 9.8e-02)),
                    0: ((9.6e-03, 5.8e-02), (2.2e-02, 1.3e-01), (4.6e-02, 2.8e-01))},
    ("plasma", 2): {2: ((9.9e-05, 1.3e-03), (6.4e-04, 9.9e-03), (2.9e-03, 4.5e-02)),
                    1: ((7.7e-04, 8.7e-03), (2.6e-03, 3.6e-02), (8.6e-03, 1.1e-01)),
                    0: ((5.7e-03, 6.6e-02), (1.5e-02, 1.8e-01), (3.1e-02, 3.7e-01))},
    ("cloud", 3): {2: ((4.2e-05, 2.8e-04), (2.2e-04, 1.9e-03), (9.5e-04, 6.9e-03))},
    ("cloud", 2): {2: ((6.7e-05, 6.3e-04), (5.8e-04, 9.0e-03), (2.9e-03, 4.3e-02))},
}, "fmm": {
    ("plasma", 3): {2: ((2.3e-04, 1.6e-03), (1.8e-03, 1.4e-02), (7.1e-03, 5.8e-02)),
                    1: ((1.2e-03, 7.8e-03), (5.2e-03, 3.5e-02), (1.5e-02, 1.1e-01)),
                    0: ((9.5e-03, 5.7e-02), (2.2e-02, 1.3e-01), (4.5e-02, 2.7e-01))},
    ("plasma", 2): {2: ((1.4e-04, 2.1e-03), (1.3e-03, 2.0e-02), (5.6e-03, 9.8e-02)),
                    1: ((7.7e-04, 8.8e-03), (2.8e-03, 3.9e-02), (1.0e-02, 1.4e-01)),
                    0: ((5.7e-03, 6.5e-02), (1.5e-02, 1.8e-01), (3.1e-02, 3.6e-01))},
    ("cloud", 3): {2: ((5.2e-05, 3.5e-04), (3.9e-04, 2.9e-03), (2.1e-03, 2.6e-02))},
    ("cloud", 2): {2: ((2.8e-04, 4.4e-03), (3.4e-03, 5.3e-02), (1.2e-02, 2.2e-01))},
}}


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("dim", (2, 3))
def test_coulomb_neutral_plasma_and_its_orders(dim, method):
    """A neutral two-species plasma: each order's error falls with theta, and at every theta
    the quadrupole (2) beats the dipole (1), which beats the monopole (0), at the median and
    the 99th percentile."""
    bodies = ic.plasma(3000, dim, seed=1, neutral=True)
    assert bodies.charge.sum() == 0.0
    reference = accelerations(bodies, coulomb())
    by_order = {order: check_falling_errors(bodies, coulomb, reference,
                                            COULOMB_ERRORS[method]["plasma", dim][order],
                                            method, order=order)
                for order in (2, 1, 0)}
    for k in range(len(THETAS)):
        for stat in (0, 1):
            assert by_order[2][k][stat] < by_order[1][k][stat] < by_order[0][k][stat], by_order


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("softening", [EPS, 0.0])
@pytest.mark.parametrize("dim", (2, 3))
def test_coulomb_one_sign_cloud(dim, softening, method):
    bodies = ic.plasma(3000, dim, seed=1, neutral=False)
    reference = accelerations(bodies, coulomb(softening=softening))
    check_falling_errors(bodies, coulomb, reference, COULOMB_ERRORS[method]["cloud", dim][2],
                         method, softening=softening)


# -- 3. multipoles --------------------------------------------------------------------------------

def cell_of(points, beta, slots=1):
    """A cell table of ``slots`` cells, cell 0 made from every point by P2M."""
    cells = np.zeros((layout.CELL_FLOATS, slots))
    mp.leaf_box(points[0], points[1], points[2], 0, points.shape[1], cells, 0)
    mp.leaf_moments(points[0], points[1], points[2], beta, 0, points.shape[1], cells, 0)
    return cells


def moments_by_definition(points, beta, centre):
    """M, D_a, Q_ab (multipoles.py: sum_j beta_j, beta_j s_ja, beta_j s_ja s_jb) in numpy."""
    s = points - centre[:, None]
    q = np.einsum("j,aj,bj->ab", beta, s, s)
    return np.array([beta.sum(), *(beta * s).sum(axis=1), q[0, 0], q[1, 1], q[2, 2], q[0, 1],
                     q[0, 2], q[1, 2]])


def test_leaf_box_and_moments_follow_their_definition():
    rng = np.random.default_rng(11)
    points = rng.random((3, 37)) * np.array([[2.0], [0.5], [1.0]]) + 3.0
    beta = rng.normal(size=37)  # charges of both signs
    cells = cell_of(points, beta)
    lo, hi = points.min(axis=1), points.max(axis=1)
    centre = (np.abs(beta) * points).sum(axis=1) / np.abs(beta).sum()
    assert np.array_equal(cells[[mp.LOX, mp.LOY, mp.LOZ], 0], lo)
    assert np.array_equal(cells[[mp.HIX, mp.HIY, mp.HIZ], 0], hi)
    assert np.allclose(cells[[mp.CX, mp.CY, mp.CZ], 0], centre, rtol=1e-15, atol=0.0)
    assert not np.allclose(centre, 0.5 * (lo + hi), rtol=1e-3)  # not the box's centre
    assert cells[mp.SIZE, 0] == (hi - lo).max()
    farthest = np.linalg.norm(points - cells[[mp.CX, mp.CY, mp.CZ], 0][:, None], axis=0).max()
    assert math.isclose(cells[mp.RADIUS, 0], farthest, rel_tol=1e-15)
    assert math.isclose(cells[mp.ABSW, 0], np.abs(beta).sum(), rel_tol=1e-14)
    expected = moments_by_definition(points, beta, cells[[mp.CX, mp.CY, mp.CZ], 0])
    got = cells[mp.M:mp.MOMENTS, 0]
    assert np.allclose(got, expected, rtol=1e-13, atol=1e-14 * np.abs(expected).max())


def test_m2m_equals_the_moments_of_the_particles():
    """A parent from three children of different sizes and places (M2M, exact by construction:
    multipoles.py) equals P2M over all its particles (measured 4e-15 of the largest moment)."""
    rng = np.random.default_rng(12)
    parts = [rng.random((3, k)) * scale + offset for k, scale, offset in
             ((9, 0.3, 0.0), (20, 1.0, 2.0), (5, 0.1, -1.5))]
    points = np.ascontiguousarray(np.concatenate(parts, axis=1))
    beta = rng.normal(size=points.shape[1])
    cells = np.zeros((layout.CELL_FLOATS, 4))
    start = 0
    for c, part in enumerate(parts):
        end = start + part.shape[1]
        mp.leaf_box(points[0], points[1], points[2], start, end, cells, c)
        mp.leaf_moments(points[0], points[1], points[2], beta, start, end, cells, c)
        start = end
    mp.parent_moments(cells, 3, 0, 3)
    whole = cell_of(points, beta)
    scale = np.abs(whole[:, 0]).max()
    same = [row for row in range(layout.CELL_FLOATS) if row != mp.RADIUS]
    assert np.allclose(cells[same, 3], whole[same, 0], rtol=0.0, atol=1e-14 * scale)
    # a parent's radius bounds its particles' distances (a leaf's is the largest of them), to
    # round-off, and is no more than the farthest corner of its box
    lo, hi = points.min(axis=1), points.max(axis=1)
    centre = whole[[mp.CX, mp.CY, mp.CZ], 0]
    corner = np.linalg.norm(np.maximum(centre - lo, hi - centre))
    assert whole[mp.RADIUS, 0] * (1.0 - 1e-15) <= cells[mp.RADIUS, 3] <= corner * (1.0 + 1e-15)
    # the moments really moved: the children's sum about their own centres is different
    assert np.abs(cells[mp.DX:mp.MOMENTS, :3].sum(axis=1) - whole[mp.DX:mp.MOMENTS, 0]).max() \
        > 1e-3 * scale


def truncated(moments, order):
    """The moments of an expansion of ``order``: the higher ones zeroed."""
    out = moments.copy()
    if order < 1:
        out[1:4] = 0.0
    if order < 2:
        out[4:] = 0.0
    return out


def far_field_errors(points, beta, moments, centre, radius, ratios, eps=0.0):
    """The largest error |field_at - exact| over 8 directions at each distance ratio * radius,
    absolute and relative to the exact field."""
    rng = np.random.default_rng(13)
    directions = rng.normal(size=(8, 3))
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    absolute, relative = [], []
    for ratio in ratios:
        worst_abs = worst_rel = 0.0
        for u in directions:
            target = centre + ratio * radius * u
            approx = np.array(mp.field_at(*(centre - target), eps * eps, *moments)[:3])
            d = points - target[:, None]
            exact = (beta * d / (np.sum(d * d, axis=0) + eps * eps) ** 1.5).sum(axis=1)
            err = np.linalg.norm(approx - exact)
            worst_abs = max(worst_abs, err)
            worst_rel = max(worst_rel, err / np.linalg.norm(exact))
        absolute.append(worst_abs)
        relative.append(worst_rel)
    return np.array(absolute), np.array(relative)


def salmon_warren_bound(weight, b, r, order):
    """Salmon & Warren 1994, eq. 19 (multipoles.py): the field's error bound at distance r of
    an expansion of ``order`` about a centre within b of every source."""
    q = b / r
    return weight * ((order + 2) * q ** (order + 1) - (order + 1) * q ** (order + 2)) / (r - b) ** 2


RATIOS = np.array([2.0, 4.0, 8.0, 16.0, 32.0, 64.0])


def one_cell():
    rng = np.random.default_rng(14)
    points = rng.random((3, 50)) - 0.5
    beta = rng.random(50) + 0.5
    cells = cell_of(points, beta)
    return points, beta, cells[:, 0]


@pytest.mark.parametrize("order", (0, 1, 2))
def test_far_field_obeys_the_salmon_warren_bound_and_its_order(order):
    """The error of the order-p expansion of one cell (50 sources of positive weight in a unit
    cube) against the exact sum: below the bound at r/b = 2 ... 64, and its relative error
    falls as (b/r)^(p+1), except that about the centre of the weights the dipole vanishes, so
    that the monopole (p = 0) is the dipole expansion and falls as (b/r)^2: fitted slopes over
    r/b = 4 ... 64 measured -2.05, -2.05, -3.03 (``SLOPES``); the errors 0.1-2%, 3-6% and
    3-5% of the bound."""
    points, beta, cell = one_cell()
    centre, b = cell[mp.CX:mp.CZ + 1], cell[mp.RADIUS]
    assert np.linalg.norm(points - centre[:, None], axis=0).max() <= b
    moments = truncated(cell[mp.M:mp.MOMENTS], order)
    absolute, relative = far_field_errors(points, beta, moments, centre, b, RATIOS)
    bound = salmon_warren_bound(np.abs(beta).sum(), b, RATIOS * b, order)
    assert np.all(absolute < bound), absolute / bound
    slope = np.polyfit(np.log(RATIOS[1:]), np.log(relative[1:]), 1)[0]
    assert abs(slope - SLOPES[order]) < 0.15, slope


#: the error's power of b/r for each order (the test above)
SLOPES = {0: -2.0, 1: -2.0, 2: -3.0}


def test_softened_far_field_falls_as_the_quadrupole_order():
    """With Plummer softening eps = b (the softened kernel expanded: multipoles.py) the
    quadrupole's relative error still falls as (b/r)^3 (fitted slope -3.00 over r/b = 4 ... 64)."""
    points, beta, cell = one_cell()
    centre, b = cell[mp.CX:mp.CZ + 1], cell[mp.RADIUS]
    _, relative = far_field_errors(points, beta, cell[mp.M:mp.MOMENTS], centre, b, RATIOS[1:],
                                   eps=b)
    slope = np.polyfit(np.log(RATIOS[1:]), np.log(relative), 1)[0]
    assert abs(slope + 3.0) < 0.15, slope


def test_order_slope_catches_a_quadrupole_without_cross_terms():
    """Positive control: quadrupole moments that lost Q_xy, Q_xz, Q_yz (an M2M that forgot
    them) fall only as (b/r)^2, and the slope check above fails."""
    points, beta, cell = one_cell()
    centre, b = cell[mp.CX:mp.CZ + 1], cell[mp.RADIUS]
    broken = cell[mp.M:mp.MOMENTS].copy()
    broken[mp.QXY - mp.M:] = 0.0
    _, relative = far_field_errors(points, beta, broken, centre, b, RATIOS)
    slope = np.polyfit(np.log(RATIOS[1:]), np.log(relative[1:]), 1)[0]
    assert abs(slope + 3.0) > 0.5, slope


def local_errors(cell, centre, distances, spread, eps=0.0):
    """The largest relative errors (field, potential), over 8 targets at ``spread`` from a
    group's centre z at each distance of z from the cell's centre, of the local expansion
    about z (local.cells_to_local, local_to_targets) against the cell's multipoles summed at
    each target (multipoles.field_at)."""
    from engine.tree import local
    rng = np.random.default_rng(15)
    directions = rng.normal(size=(8, 3))
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    away = np.array([0.8, 0.48, -0.36])
    out = []
    for distance in distances:
        z = centre + distance * away
        lc = np.zeros((13, 1))
        lc[:, 0] = cell[:mp.MOMENTS]
        loc = np.zeros(32)
        local.cells_to_local(lc, 1, *z, eps * eps, loc)
        local.cells_to_local_potential(lc, 1, *z, eps * eps, loc)
        targets = (z + spread * directions).T.copy()
        acc = [np.zeros(8) for _ in range(4)]
        local.local_to_targets(*targets, 0, 8, *z, loc, *acc, True)
        worst_field = worst_potential = 0.0
        for k in range(8):
            exact = mp.field_at(*(centre - targets[:, k]), eps * eps, *cell[mp.M:mp.MOMENTS])
            field = np.array(exact[:3])
            got = np.array([acc[0][k], acc[1][k], acc[2][k]])
            worst_field = max(worst_field, np.linalg.norm(got - field) / np.linalg.norm(field))
            worst_potential = max(worst_potential, abs(acc[3][k] - exact[3]) / abs(exact[3]))
        out.append((worst_field, worst_potential))
    return np.array(out)


DISTANCES = np.array([5.0, 10.0, 20.0, 40.0, 80.0])


@pytest.mark.parametrize("eps", (0.0, 0.3))
def test_local_expansion_matches_the_multipoles_to_third_order(eps):
    """M2L then L2P (local.py: a far cell's field expanded about a group's centre z to total
    order 2 in the cell's size and the target's offset from z) against the cell's multipoles
    summed at each target: with targets one cell radius b from z, the relative error falls as
    (b/R)^3 with the distance R (fitted slopes measured -2.95 and -3.00 for the field and the
    potential, the same with softening 0.3 b), and a target at z itself gets the multipoles'
    field to round-off."""
    points, beta, cell = one_cell()
    centre, b = cell[mp.CX:mp.CZ + 1], cell[mp.RADIUS]
    errors = local_errors(cell, centre, DISTANCES * b, b, eps)
    slope_field = np.polyfit(np.log(DISTANCES), np.log(errors[:, 0]), 1)[0]
    slope_potential = np.polyfit(np.log(DISTANCES), np.log(errors[:, 1]), 1)[0]
    assert abs(slope_field + 3.0) < 0.3, slope_field
    assert abs(slope_potential + 3.0) < 0.3, slope_potential
    assert errors[2, 0] < 2e-3, errors[2, 0]  # R = 20 b: measured 5.7e-4
    at_centre = local_errors(cell, centre, DISTANCES[:1] * b, 0.0, eps)
    assert at_centre.max() < 1e-13


def test_local_expansion_slope_catches_a_missing_gradient():
    """Positive control: the same check on an expansion that lost its gradient (the first
    order in the target's offset) falls only as (b/R)^1."""
    from engine.tree import local
    points, beta, cell = one_cell()
    centre, b = cell[mp.CX:mp.CZ + 1], cell[mp.RADIUS]
    errors = []
    for distance in DISTANCES * b:
        z = centre + distance * np.array([0.8, 0.48, -0.36])
        lc = np.zeros((13, 1))
        lc[:, 0] = cell[:mp.MOMENTS]
        loc = np.zeros(32)
        local.cells_to_local(lc, 1, *z, 0.0, loc)
        loc[3:9] = 0.0
        target = z + b * np.array([0.6, 0.0, 0.8])
        acc = [np.zeros(1) for _ in range(4)]
        local.local_to_targets(*[np.array([v]) for v in target], 0, 1, *z, loc, *acc, False)
        exact = np.array(mp.field_at(*(centre - target), 0.0, *cell[mp.M:mp.MOMENTS])[:3])
        got = np.array([a[0] for a in acc[:3]])
        errors.append(np.linalg.norm(got - exact) / np.linalg.norm(exact))
    slope = np.polyfit(np.log(DISTANCES), np.log(errors), 1)[0]
    assert abs(slope + 3.0) > 1.0, slope


def test_a_local_expansion_moved_is_the_same_quadratic():
    """L2L (local.shift_local) is exact: a local expansion (field and potential) moved from z
    to z + t and evaluated at a target equals the original evaluated there, to round-off
    (measured 3e-16 of the largest value), for any t; and moving it changes its coefficients
    (else the test would prove nothing)."""
    from engine.tree import local
    rng = np.random.default_rng(21)
    loc = np.zeros(32)
    loc[:29] = rng.normal(size=29)
    z = np.array([0.3, -1.2, 2.0])
    targets = (z[:, None] + rng.normal(size=(3, 10))).copy()
    before = [np.zeros(10) for _ in range(4)]
    local.local_to_targets(*targets, 0, 10, *z, loc, *before, True)
    for t in (np.array([0.5, -0.25, 0.125]), np.array([-3.0, 1.0, 2.0])):
        moved = np.zeros(32)
        local.shift_local(loc, moved, *t, True)
        assert not np.allclose(moved[:9], loc[:9])
        after = [np.zeros(10) for _ in range(4)]
        local.local_to_targets(*targets, 0, 10, *(z + t), moved, *after, True)
        scale = max(np.abs(b).max() for b in before)
        for b, a in zip(before, after):
            assert np.abs(a - b).max() < 1e-14 * scale


def test_fmm_below_its_theta_and_in_too_deep_a_tree_is_the_barnes_hut_walk():
    """The fast multipole walk hands over to the Barnes-Hut walk (the same bits) below theta
    ``field.FMM_THETA_MIN``, and where its frames run out: a Plummer sphere of 1600 bodies
    beside a chain of 300 at x = 5 / 2^k, in whose tree every level splits one body off (267
    levels, more than ``layout.DEPTH``). Above that theta, on an ordinary scene, the two
    walks differ."""
    bodies = scene("plummer", 3000, 3)
    below = field.FMM_THETA_MIN * 0.9
    assert np.array_equal(accelerations(bodies, gravity(method="fmm", theta=below)),
                          accelerations(bodies, gravity(method="tree", theta=below)))
    assert not np.array_equal(accelerations(bodies, gravity(method="fmm", theta=0.5)),
                              accelerations(bodies, gravity(method="tree", theta=0.5)))
    bulk = ic.plummer(1600, 3, seed=1)
    links = np.zeros((300, 3))
    links[:, 0] = 5.0 * 2.0 ** -np.arange(300, dtype=float)
    pos = np.concatenate([bulk.pos + np.array([20.0, 0.0, 0.0]), links])
    n = pos.shape[0]
    chain = ic.Bodies(np.full(n, 1.0 / n), pos, np.zeros_like(pos), np.zeros(n))
    deep = accelerations(chain, gravity(softening=1e-3, method="fmm", theta=0.5))
    assert np.array_equal(deep, accelerations(chain, gravity(softening=1e-3, method="tree",
                                                             theta=0.5)))
    exact = accelerations(chain, gravity(softening=1e-3))
    assert np.median(relative_errors(deep, exact)) < 1e-3


# -- 4. test, inactive and pinned particles -----------------------------------------------------

def flagged_simulation(bodies, term, test, inactive, pinned):
    sim = Simulation(dim=bodies.dim, integrator="leapfrog", dt=1e-3, G=1.0)
    sim.add_many(mass=bodies.mass, pos=bodies.pos, vel=bodies.vel, charge=bodies.charge,
                 test=test, pinned=pinned)
    for i in inactive:
        sim.deactivate(int(i))
    sim.add_force(term)
    return sim


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("make", (gravity, coulomb), ids=("gravity", "coulomb"))
def test_test_inactive_and_pinned_particles(make, method):
    """3000 bodies of a Plummer sphere: 400 test particles 1000 times heavier than the rest
    (gravity: they feel and do not act; if they acted the error would be of order 1000),
    200 inactive ones (feel and exert nothing: exactly zero in both sums), 100 pinned ones
    (they act and are acted on; a step leaves them in place); for Coulomb, charges of
    alternate signs and 100 uncharged bodies (no Coulomb force). Tree against direct:
    theta = 0 to round-off (measured 5e-15 gravity, 6e-14 Coulomb), theta = 0.5 as
    ``FLAGGED_ERRORS``."""
    n = 3000
    base = ic.plummer(n, 3, seed=9)
    order = np.random.default_rng(3).permutation(n)
    test_i, inactive, pinned_i, neutral = order[:400], order[400:600], order[600:700], \
        order[700:800]
    mass = base.mass.copy()
    mass[test_i] *= 1000.0
    charge = np.where(np.arange(n) % 2 == 0, 1.0, -1.0)
    charge[neutral] = 0.0
    bodies = ic.Bodies(mass, base.pos, base.vel, charge)
    test = np.isin(np.arange(n), test_i)
    pinned = np.isin(np.arange(n), pinned_i)

    def run(name, theta=0.5):
        return flagged_simulation(bodies, make(method=name, theta=theta), test, inactive,
                                  pinned)

    reference = run("direct").accelerations()
    live = np.setdiff1d(np.arange(n), inactive)
    if make is coulomb:
        assert np.all(reference[neutral] == 0.0)
        live = np.setdiff1d(live, neutral)
    assert np.all(reference[inactive] == 0.0)
    measured = FLAGGED_ERRORS[method, make.__name__]
    for theta, (median_bound, p99_bound) in ((0.0, (1e-12, 1e-12)),
                                             (0.5, (MARGIN * measured[0],
                                                    MARGIN * measured[1]))):
        got = run(method, theta).accelerations()
        assert np.all(got[inactive] == 0.0)
        if make is coulomb:
            assert np.all(got[neutral] == 0.0)
        errors = relative_errors(got[live], reference[live])
        median, p99 = summary(errors)
        assert median < median_bound and p99 < p99_bound, (theta, median, p99)
        for group in (test_i, pinned_i):
            assert np.median(relative_errors(got[group], reference[group])) < median_bound
    sim = run(method)
    before = sim.pos.copy()
    sim.step(3)
    assert np.array_equal(sim.pos[pinned_i], before[pinned_i])
    assert np.array_equal(sim.pos[inactive], before[inactive])
    assert np.all(sim.vel[pinned_i] == 0.0)
    assert not np.array_equal(sim.pos[live], before[live])


#: (median, 99th percentile) of the scene above at theta = 0.5, by walk and term
FLAGGED_ERRORS = {("tree", "gravity"): (1.7e-4, 1.8e-3), ("tree", "coulomb"): (1.7e-3, 2.0e-2),
                  ("fmm", "gravity"): (2.2e-4, 4.9e-3), ("fmm", "coulomb"): (2.2e-3, 3.4e-2)}


def test_heavy_test_particles_would_be_seen():
    """Positive control for the test above: the same scene with the test flags cleared (the
    heavy bodies acting) moves the others' accelerations by far more than its bounds."""
    n = 3000
    base = ic.plummer(n, 3, seed=9)
    heavy = np.random.default_rng(3).permutation(n)[:400]
    mass = base.mass.copy()
    mass[heavy] *= 1000.0
    bodies = ic.Bodies(mass, base.pos, base.vel, base.charge)
    test = np.isin(np.arange(n), heavy)
    light = np.setdiff1d(np.arange(n), heavy)
    as_test = flagged_simulation(bodies, gravity(), test, [], np.zeros(n, bool)).accelerations()
    acting = flagged_simulation(bodies, gravity(), np.zeros(n, bool), [],
                                np.zeros(n, bool)).accelerations()
    assert np.median(relative_errors(acting[light], as_test[light])) > 10.0


# -- 5. the same bits at any thread count and particle order ------------------------------------

@pytest.mark.parametrize("method", METHODS)
def test_same_bits_at_one_and_two_threads(method):
    bodies = scene("plummer", 3000, 3, seed=5)
    assert bodies.n > field.THREADS_MIN
    saved = numba.get_num_threads()
    results = []
    try:
        for threads in (1, min(2, numba.config.NUMBA_NUM_THREADS)):
            numba.set_num_threads(threads)
            sim = simulation(bodies, gravity(method=method))
            first = sim.accelerations()
            sim.step(3)
            results.append((first, sim.pos.copy(), sim.vel.copy()))
    finally:
        numba.set_num_threads(saved)
    for one, two in zip(*results):
        assert np.array_equal(one, two)


_ONE_THREAD_RUN = """
import numpy as np
from engine import Simulation, forces, initial_conditions as ic
bodies = ic.plummer(3000, 3, seed=5)
sim = Simulation(dim=3, integrator="leapfrog", dt=1e-3)
ic.add_to(sim, bodies)
sim.add_force(forces.NBodyGravity(softening=0.01, method={method!r}))
np.save({path!r}, np.append(sim.accelerations().ravel(), sim.potential_energy()))
"""


@pytest.mark.parametrize("method", METHODS)
def test_a_process_with_one_thread_gets_the_same_bits(tmp_path, method):
    """A process whose numba has one thread (NUMBA_NUM_THREADS=1) makes workspaces with lists
    for one thread, while the cached compiled code may come from a process with two: the walk
    reads its lane count from the workspace, so both give the same bits (the count once frozen
    into the cached code made the walk read past a one-thread workspace).

    The two processes load the compiled code this test's process cached. Against this process
    the bits may differ at round-off: measured, a process that compiles the tree's code itself
    differs from the processes that load it from the cache in 162 of 9001 values, by at most
    4.6e-17 of the largest (numba's code made in a process and its cached code are not always
    the same instructions)."""
    here = _tree_run(Path(tmp_path / "here.npy"), {}, method)
    one = _tree_run(Path(tmp_path / "one.npy"), {"NUMBA_NUM_THREADS": "1"}, method)
    two = _tree_run(Path(tmp_path / "two.npy"), {"NUMBA_NUM_THREADS": "2"}, method)
    assert np.array_equal(one, two)
    assert np.abs(one - here).max() <= 1e-15 * np.abs(here).max()


def _tree_run(path, variables, method):
    """The accelerations and potential energy of a tree scene, computed in a new process with
    these environment variables (``{}``: in this process)."""
    code = _ONE_THREAD_RUN.format(path=str(path), method=method)
    if not variables:
        exec(code, {})
    else:
        env = dict(os.environ, **variables)
        subprocess.run([sys.executable, "-c", code], env=env, check=True, timeout=600)
    return np.load(path)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("dim", (2, 3))
def test_permuted_particles_get_the_same_accelerations(dim, method):
    """Listing the bodies in another order changes only the order of the accelerations: the
    Morton sort puts them back in one order (measured: the same bits; round-off would come
    only from bodies sharing a key)."""
    bodies = scene("plummer", 3000, dim, seed=5)
    order = np.random.default_rng(1).permutation(bodies.n)
    straight = accelerations(bodies, gravity(method=method))
    shuffled = accelerations(permuted(bodies, order), gravity(method=method))
    back = np.empty_like(shuffled)
    back[order] = shuffled
    assert relative_errors(back, straight).max() < 1e-13


# -- 6. energy and momentum in a run -------------------------------------------------------------

ENERGY_N = 10_000


def energy_run(method, steps, every):
    """|dE/E| (by the direct sum of each state, ``ExactEnergy``) and |dP| / sum m|v| every
    ``every`` steps of a Plummer sphere of ``ENERGY_N`` bodies (G = M = a = 1, softening 0.01)
    by leapfrog at dt = 0.005, 1/1250 of the crossing time G M^(5/2) / (2|E|)^(3/2) = 6.3."""
    bodies = ic.plummer(ENERGY_N, 3, seed=3)
    scale = float(np.sum(bodies.mass * np.linalg.norm(bodies.vel, axis=1)))
    sim = simulation(bodies, gravity(method=method, theta=0.5), dt=0.005)
    energy = ExactEnergy(sim, EPS)
    e0, p0 = energy(), sim.momentum()
    t, de, dp = [], [], []
    for _ in range(steps // every):
        sim.step(every)
        t.append(sim.t)
        de.append((energy() - e0) / abs(e0))
        dp.append(np.linalg.norm(sim.momentum() - p0) / scale)
    assert np.all(np.isfinite(sim.pos))
    return np.array(t), np.array(de), np.array(dp)


@pytest.fixture(scope="module")
def direct_energy_run():
    """The direct sum's run over the first 200 steps (1000 would take minutes of CPU)."""
    return energy_run("direct", 200, 50)


#: measured over 1000 steps at theta = 0.5: largest |dE/E|, its fitted growth per unit time,
#: largest momentum drift
RUN_MEASURED = {"tree": (2.0e-6, 5.6e-7, 1.25e-5), "fmm": (3.4e-6, 9.3e-7, 9.9e-6)}


@pytest.mark.parametrize("method", METHODS)
def test_energy_and_momentum_of_a_plummer_sphere(method, direct_energy_run):
    """10^4 bodies, 1000 leapfrog steps (``energy_run``), each walk at theta = 0.5; the
    energy measured by the direct sum of each state, so that the tree's own potential error
    does not hide the run's. Measured (``RUN_MEASURED``): largest |dE/E| 2.0e-6 (Barnes-Hut)
    and 3.4e-6 (FMM), fitted growth -5.6e-7 and -9.3e-7 per unit time; the momentum drifts
    (the forces are not antisymmetric pair by pair) to 1.3e-5 and 9.9e-6 of sum m|v|. The
    direct sum over the first 200 steps (1000 would take minutes of CPU): |dE/E| 4.8e-7 at
    most, the momentum to round-off (1e-16). On the development machine the runs take 24 s
    (Barnes-Hut), 17 s (FMM) and 10 s (direct, 200 steps)."""
    t, de, dp = energy_run(method, 1000, 100)
    growth = np.polyfit(t, de, 1)[0]
    largest, rate, drift = RUN_MEASURED[method]
    assert np.abs(de).max() < MARGIN * largest
    assert abs(growth) < MARGIN * rate
    assert 1e-8 < dp.max() < MARGIN * drift
    _, de_d, dp_d = direct_energy_run
    assert np.abs(de_d).max() < MARGIN * DIRECT_ENERGY
    assert dp_d.max() < 1e-14
    # over the same 200 steps the tree's energy error is of the direct sum's size
    assert np.abs(de[:2]).max() < 5.0 * max(np.abs(de_d).max(), 1e-7)


#: the direct sum's largest |dE/E| over its 200 steps
DIRECT_ENERGY = 4.8e-7


# -- 7. REBOUND's tree ---------------------------------------------------------------------------

def rebound_accelerations(rebound, bodies, theta, eps, gravity_module="tree"):
    """REBOUND's accelerations on ``bodies`` (a dt = 0 leapfrog step: the forces at the
    current positions, which do not move)."""
    sim = rebound.Simulation()
    sim.G = 1.0
    sim.gravity = gravity_module
    sim.integrator = "leapfrog"
    sim.root_size = 2.05 * np.abs(bodies.pos).max()
    sim.opening_angle2 = theta * theta
    sim.softening = eps
    for m, p, v in zip(bodies.mass, bodies.pos, bodies.vel):
        sim.add(m=m, x=p[0], y=p[1], z=p[2], vx=v[0], vy=v[1], vz=v[2])
    sim.dt = 0.0
    sim.steps(1)
    assert np.array_equal([[q.x, q.y, q.z] for q in sim.particles], bodies.pos)
    return np.array([[q.ax, q.ay, q.az] for q in sim.particles])


REBOUND_THETAS = (0.3, 0.5, 0.7, 1.0)


@pytest.mark.parametrize("method", METHODS)
def test_against_rebound_s_tree(optional, method):
    """The same Plummer sphere (3000 bodies, softening 0.01) in REBOUND's tree and ours, both
    against our direct sum (REBOUND's direct sum agrees with it to 7e-15). Median and 99th
    percentile of the error against theta (REBOUND opens a cell when its width exceeds theta
    times the distance to its centre of mass, and takes its monopole; ours measures from the
    nearest point of the group's box and takes the quadrupole):

        theta          0.3             0.5             0.7             1.0
        REBOUND   6.6e-4/3.7e-3   2.4e-3/1.5e-2   5.9e-3/4.0e-2   1.5e-2/1.1e-1
        ours      2.8e-5/1.8e-4   1.9e-4/1.4e-3   9.5e-4/7.8e-3   4.7e-3/3.9e-2

    Both fall with theta; ours is 5 to 20 times smaller at the same theta."""
    rebound = optional("rebound")
    bodies = ic.plummer(3000, 3, seed=2)
    reference = accelerations(bodies, gravity())
    basic = rebound_accelerations(rebound, bodies, 0.5, EPS, "basic")
    assert relative_errors(basic, reference).max() < 1e-13
    theirs, ours = [], []
    for theta in REBOUND_THETAS:
        theirs.append(summary(relative_errors(
            rebound_accelerations(rebound, bodies, theta, EPS), reference)))
        ours.append(summary(tree_errors(bodies, gravity, reference, method, theta=theta)))
    for curve in (theirs, ours):
        for low, high in zip(curve, curve[1:]):
            assert low[0] < high[0] and low[1] < high[1], curve
    for (m_r, p_r), (m_o, p_o) in zip(theirs, ours):
        assert m_o < m_r and p_o < p_r


# -- 8. integrators and refusals -----------------------------------------------------------------

# |dE/E| (the tree's own energy) over t = 0.5 (50 steps of 0.01; rk45 to tolerance 1e-8) of a
# 400-body Plummer sphere, softening 0.05, theta = 0.5, by walk; a bound is MARGIN times it.
# The fourth-order methods sit at the tree's own floor (its potential's error, 2e-5 at this
# theta and N; the direct sum gives them 1e-9)
ENERGY_MEASURED = {
    "tree": {"euler": 2.7e-3, "symplectic_euler": 5.5e-5, "leapfrog": 6.4e-6, "verlet": 5.1e-7,
             "rk4": 4.6e-6, "yoshida4": 4.6e-6, "pefrl": 4.9e-6, "rk45": 4.8e-6,
             "janus": 4.5e-6},
    "fmm": {"euler": 2.7e-3, "symplectic_euler": 6.2e-5, "leapfrog": 1.4e-5, "verlet": 8.3e-6,
            "rk4": 1.2e-5, "yoshida4": 1.2e-5, "pefrl": 1.3e-5, "rk45": 1.3e-5, "janus": 1.2e-5},
}


def small_sphere(integrator, method, **options):
    return simulation(ic.plummer(400, 3, seed=8),
                      gravity(softening=0.05, method=method, theta=0.5),
                      integrator=integrator, dt=0.01, **options)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("integrator", GENERAL + ("janus",))
def test_every_general_integrator_steps_a_tree_scene(integrator, method):
    sim = small_sphere(integrator, method, tolerance=1e-8) if integrator == "rk45" \
        else small_sphere(integrator, method)
    e0 = sim.energy()
    if integrator == "rk45":
        sim.integrate(0.5)
    else:
        sim.step(50)
    assert math.isclose(sim.t, 0.5, rel_tol=1e-12)
    assert np.all(np.isfinite(sim.pos)) and np.all(np.isfinite(sim.vel))
    assert abs(sim.energy() / e0 - 1.0) < MARGIN * ENERGY_MEASURED[method][integrator]


@pytest.mark.parametrize("method", METHODS)
def test_janus_retraces_a_tree_scene_bit_for_bit(method):
    """Tree forces are a deterministic function of the positions, so janus's reversal holds:
    100 steps forward and 100 back return the lattice state bit for bit."""
    sim = small_sphere("janus", method)
    sim.step(1)  # the first step chooses the lattice and puts the state on it
    sim.dt = -sim.dt
    sim.step(1)
    sim.dt = -sim.dt
    start = (sim.pos.copy(), sim.vel.copy())
    sim.step(100)
    assert not np.array_equal(sim.pos, start[0])
    sim.dt = -sim.dt
    sim.step(100)
    assert np.array_equal(sim.pos, start[0]) and np.array_equal(sim.vel, start[1])


@pytest.mark.parametrize("integrator", ("whfast", "saba", "ias15"))
@pytest.mark.parametrize("method", METHODS + ("auto",))
def test_kepler_and_ias15_integrators_refuse_a_tree_term(integrator, method):
    """"auto" is refused from ``DIRECT_BELOW`` particles on (where it is the tree) and
    accepted below (where it is the direct sum)."""
    n = tree_terms.DIRECT_BELOW if method == "auto" else 50
    bodies = ic.plummer(n, 3, seed=4)
    sim = simulation(bodies, gravity(method=method), integrator=integrator, dt=1e-3)
    before = (sim.pos.copy(), sim.vel.copy(), sim.t, sim.steps)
    with pytest.raises(ValueError, match=rf"^{integrator} cannot step NBodyGravity\(method="
                                         rf"'{method}'\).*nothing was changed"):
        sim.step(1)
    assert np.array_equal(sim.pos, before[0]) and np.array_equal(sim.vel, before[1])
    assert (sim.t, sim.steps) == before[2:]


def test_ias15_steps_auto_below_its_threshold():
    sim = simulation(ic.plummer(50, 3, seed=4), gravity(method="auto"), integrator="ias15",
                     dt=1e-3)
    sim.step(2)
    assert sim.steps == 2 and np.all(np.isfinite(sim.pos))


@pytest.mark.parametrize("method", METHODS + ("auto",))
def test_batch_periodic_space_and_float32_refuse_the_tree(method):
    batch = Batch(2, dim=3)
    for term in (gravity(method=method), coulomb(method=method)):
        with pytest.raises(ValueError, match=rf"method='{method}'\) cannot act in a Batch"):
            batch.add_force(term)
    assert batch.forces == ()
    attached = batch.add_force(gravity())
    with pytest.raises(ValueError, match="cannot act in a Batch"):
        attached.method = method
    assert attached.method == "direct"

    periodic = Simulation(dim=3, box=10.0)
    with pytest.raises(ValueError, match=r"cannot act in a periodic space \(box=10.0\)"):
        periodic.add_force(gravity(method=method))
    assert periodic.forces == ()

    sim = Simulation(dim=3)
    with pytest.raises(ValueError, match=rf"NBodyGravity\(method='{method}'\) computes in "
                                         r"float64: precision='float32'"):
        sim.add_force(gravity(method=method, precision="float32"))
    assert sim.forces == ()
    single = sim.add_force(gravity(precision="float32"))
    with pytest.raises(ValueError, match="precision='float32' is the direct sum's"):
        single.method = method
    assert single.method == "direct"


# -- 9. bad input ----------------------------------------------------------------------------------

BAD = [("theta", -0.1, ValueError, r"theta must be in \[0, 2\).*got -0\.1"),
       ("theta", float("nan"), ValueError, "theta must be finite, got nan"),
       ("theta", float("inf"), ValueError, "theta must be finite, got inf"),
       ("theta", 2.0, ValueError, r"theta must be in \[0, 2\).*got 2\.0"),
       ("theta", 7.5, ValueError, r"theta must be in \[0, 2\).*got 7\.5"),
       ("theta", "0.5", TypeError, "theta must be a real number, got '0.5'"),
       ("order", 3, ValueError, r"order must be an int in \[0, 2\], got 3"),
       ("order", -1, ValueError, r"order must be an int in \[0, 2\], got -1"),
       ("order", True, TypeError, r"order must be an int in \[0, 2\], got True"),
       ("order", 1.0, TypeError, r"order must be an int in \[0, 2\], got 1\.0"),
       ("method", "barnes", ValueError,
        "method must be one of direct, tree, fmm, auto; got 'barnes'")]


@pytest.mark.parametrize("field_name, value, error, message", BAD,
                         ids=[f"{f}={v!r}" for f, v, _, _ in BAD])
@pytest.mark.parametrize("make", (forces.NBodyGravity, forces.Coulomb),
                         ids=("gravity", "coulomb"))
def test_bad_tree_parameters_are_refused(make, field_name, value, error, message):
    with pytest.raises(error, match=message):
        make(**{field_name: value})
    bodies = ic.plummer(300, 3, seed=6, mass=1.0)
    bodies = ic.Bodies(bodies.mass, bodies.pos, bodies.vel, np.where(np.arange(300) % 2, 1.0,
                                                                     -1.0))
    term = make(softening=EPS, method="tree", theta=0.4, order=1)
    sim = simulation(bodies, term)
    before = sim.accelerations()
    with pytest.raises(error, match=message):
        setattr(term, field_name, value)
    assert (term.method, term.theta, term.order) == ("tree", 0.4, 1)
    assert np.array_equal(sim.accelerations(), before)


# -- 10. the workspace ---------------------------------------------------------------------------

def _peak_bytes(call):
    """The most memory Python and numpy held at once during ``call()``, beyond what they held
    before (tracemalloc sees numpy's arrays)."""
    import tracemalloc
    tracemalloc.start()
    try:
        tracemalloc.reset_peak()
        before, _ = tracemalloc.get_traced_memory()
        call()
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    return peak - before


def test_the_workspace_is_made_once_per_particle_count():
    """After the first step a tree scene's steps allocate no more than the same scene's with
    the direct sum (the integrator's own scratch for a call, 400 KB here), nothing like the
    tree's 1.6 MB workspace for 5000 bodies; adding a body makes a new workspace (the positive
    control: the peak then exceeds the workspace's size)."""
    bodies = ic.plummer(5000, 3, seed=7)
    size = layout.bytes_per_particle(5000) * 5000
    peaks = {}
    for method in ("direct",) + METHODS:
        sim = simulation(bodies, gravity(method=method))
        sim.step(1)
        sim.accelerations()
        sim.energy()
        peaks[method] = _peak_bytes(lambda: sim.step(5))
    for method in METHODS:
        assert peaks[method] < peaks["direct"] + 0.05 * size, (peaks, size)
    sim.add(mass=1e-3, pos=(30.0, 0.0, 0.0))
    grown = _peak_bytes(lambda: sim.step(1))
    assert grown > size, (grown, size)
    assert _peak_bytes(lambda: sim.step(3)) < peaks["direct"] + 0.05 * size


def test_workspace_bytes_per_particle():
    """212 bytes a particle at 10^6 (layout.py's 20 floats and 6.5 ints, and the threads'
    lists)."""
    assert layout.bytes_per_particle(10 ** 6) <= 300


ALLOCATIONS = r"""
import json
from numba.core.runtime import rtsys
from engine import forces
from engine import initial_conditions as ic
from tests.engine.tree_scenes import simulation

counts = {}
for method in ("tree", "fmm", "direct"):
    sim = simulation(ic.plummer(3000, 3, seed=7), forces.NBodyGravity(softening=0.01,
                                                                      method=method))
    sim.step(1)
    per_call = []
    for steps in (1, 20):
        before = rtsys.get_allocation_stats().alloc
        sim.step(steps)
        per_call.append(rtsys.get_allocation_stats().alloc - before)
    counts[method] = per_call
print(json.dumps(counts))
"""


def test_no_allocation_per_step():
    """numba's allocation count (NUMBA_NRT_STATS) over one step(1) and one step(20) after the
    first: the same (measured 28 each, the call's own), so a step allocates nothing."""
    env = dict(os.environ, NUMBA_NRT_STATS="1")
    out = subprocess.run([sys.executable, "-c", ALLOCATIONS], env=env, cwd=ROOT,
                         capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    counts = json.loads(out.stdout.strip().splitlines()[-1])
    for method in ("tree", "fmm", "direct"):
        one, twenty = counts[method]
        assert one == twenty, counts


# -- 11. lazy loading ---------------------------------------------------------------------------

LAZY = r"""
import json, sys
from engine import forces
from engine import initial_conditions as ic
from tests.engine.tree_scenes import simulation

bodies = ic.plasma(3000, 3, seed=1)
sim = simulation(bodies, forces.NBodyGravity(softening=0.01), forces.Coulomb(softening=0.01))
sim.step(3)
sim.accelerations()
sim.energy()
small = simulation(ic.plummer(100, 3), forces.NBodyGravity(softening=0.01, method="auto"))
small.step(2)
small.energy()
print(json.dumps(sorted(sys.modules)))
"""


def test_a_scene_without_tree_terms_loads_no_tree_code():
    """A direct-sum gravity and Coulomb scene of 3000 bodies (the multi-core kernels), and an
    "auto" term below its threshold: stepped, accelerations, energy, in a fresh interpreter."""
    out = subprocess.run([sys.executable, "-c", LAZY], cwd=ROOT, capture_output=True,
                         text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    modules = json.loads(out.stdout.strip().splitlines()[-1])
    assert "engine.forces.gravity" in modules  # the scene really ran
    loaded = [m for m in modules if m == "engine.tree" or m.startswith("engine.tree.")
              or m in ("engine.forces.gravity_tree", "engine.forces.coulomb_tree")]
    assert not loaded, loaded


# -- 12. "auto" --------------------------------------------------------------------------------

@pytest.mark.parametrize("make", (gravity, coulomb), ids=("gravity", "coulomb"))
def test_auto_is_the_direct_sum_below_its_threshold_and_the_fmm_above(make):
    below = tree_terms.DIRECT_BELOW - 1
    for n, same_as in ((below, "direct"), (tree_terms.DIRECT_BELOW, "fmm"), (5000, "fmm")):
        bodies = ic.plasma(n, 3, seed=6, neutral=False) if make is coulomb \
            else ic.plummer(n, 3, seed=6)
        auto = accelerations(bodies, make(method="auto"))
        assert np.array_equal(auto, accelerations(bodies, make(method=same_as))), n
        for other in {"direct", "tree", "fmm"} - {same_as}:
            assert not np.array_equal(auto, accelerations(bodies, make(method=other))), n


def test_auto_decides_by_particle_slots_everywhere():
    """"auto" decides by the simulation's particle slots (sim.n, inactive ones included), in
    the kernel, the potential energy and the integrators' refusals alike: above the threshold
    in slots and below it in active particles it is the FMM, and ias15 refuses it."""
    bodies = ic.plummer(tree_terms.DIRECT_BELOW + 4, 3, seed=6)
    results = []
    for method in ("auto", "fmm"):
        sim = simulation(bodies, gravity(method=method))
        for i in range(10):
            sim.deactivate(i)
        results.append((sim.accelerations(), sim.potential_energy()))
    assert np.array_equal(results[0][0], results[1][0])
    assert results[0][1] == results[1][1]
    sim.integrator = "ias15"
    with pytest.raises(ValueError, match="ias15"):
        sim.step(1)


@pytest.mark.parametrize("method", METHODS)
def test_a_far_escaper_does_not_crowd_the_cluster_into_one_leaf(method):
    """One body 10^7 scale radii away makes 2^21 Morton cells an axis too coarse to tell the
    cluster's bodies apart: they share a key, and are keyed again in their own cube
    (build.rekey). Without that, the whole cluster was one leaf and one group, summed pair by
    pair on one core (measured before: 10 cells for 3000 bodies; after: the cells of the
    cluster alone). The field is the direct sum's at theta = 0 and as accurate as without the
    escaper at theta = 0.5."""
    bodies = ic.plummer(3000, 3, seed=8)
    far = bodies.pos.copy()
    far[0] = (1e7, 0.0, 0.0)
    escaped = ic.Bodies(bodies.mass, far, bodies.vel, bodies.charge)
    exact = accelerations(escaped, gravity(method="direct"))
    assert relative_errors(accelerations(escaped, gravity(method=method, theta=0.0)),
                           exact).max() < 1e-12
    cluster = np.arange(1, 3000)
    err_escaped = np.median(relative_errors(
        accelerations(escaped, gravity(method=method, theta=0.5))[cluster], exact[cluster]))
    plain_exact = accelerations(bodies, gravity(method="direct"))
    err_plain = np.median(relative_errors(accelerations(bodies, gravity(method=method,
                                                                          theta=0.5)),
                                          plain_exact))
    assert err_escaped < 3.0 * err_plain, (err_escaped, err_plain)
    # the tree's cells: as many as the cluster alone needs, and no group over its size
    n = escaped.n
    work = layout.workspace(n)
    work.ints[n:2 * n] = np.arange(n)
    part = layout.particle_blocks(work.floats, n)
    part[5, :n] = escaped.mass
    part[6, :n] = 1.0
    cells = field.solve(np.ascontiguousarray(escaped.pos.T), n, n, work.floats, work.ints, 0.5,
                        1e-4, 2, False, False, method == "fmm")
    assert cells > 300, cells
    start, count, child, children, groups = layout.cell_links(work.ints, n)
    from engine.tree import build
    found = build.list_groups(count, child, children, field.GROUP_SIZE, groups,
                              layout.lane_stack(work.ints, n, 0))
    assert count[groups[:found]].max() <= field.GROUP_SIZE


def test_a_periodic_space_declared_after_a_tree_term_is_refused():
    """Setting sim.box with a tree term declared: ValueError naming the method, the box
    unchanged (the forces would otherwise be open-space ones in a periodic space)."""
    sim = simulation(ic.uniform_cube(50, 3, seed=2), gravity(method="tree"))
    with pytest.raises(ValueError, match="periodic"):
        sim.box = 1.0
    assert sim.box == 0.0
    sim.step(1)


def test_a_massless_charge_in_no_field_stays_finite_as_in_the_direct_sum():
    """alpha = -k q / m is infinite for a massless charged particle: a zero field must leave
    it at zero acceleration (the direct sum skips an exactly zero force), not NaN."""
    for k_e in (1.0, 0.0):
        sim = Simulation(dim=3, integrator="leapfrog", dt=1e-3)
        sim.add_many(mass=[0.0, 1.0, 1.0, 1.0, 1.0], pos=np.arange(15.0).reshape(5, 3) ** 1.5,
                     charge=[1.0, 0.0, 0.0, 0.0, 0.0] if k_e else 1.0)
        sim.add_force(forces.Coulomb(k=k_e, method="tree"))
        assert np.all(sim.accelerations() == 0.0)


def test_an_array_given_as_the_order_is_refused_naming_it():
    with pytest.raises(TypeError, match="order"):
        forces.NBodyGravity(method="tree", order=np.array([1, 2]))


# -- edges: crowded cells, coincident bodies, two tree terms -------------------------------------

def crowded_lattice(units=8):
    """units^3 unit cells of 17 bodies each (2 or 3 at each octant's centre), so that every unit
    cell splits into 8 leaves: 9 cells for 17 bodies, more than the workspace's n/2 + 64 at
    leaf size 16 (4681 against 4417 here), and the build must double its leaves."""
    g = np.arange(units, dtype=float)
    corners = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
    octants = np.array([[x, y, z] for x in (0.25, 0.75) for y in (0.25, 0.75)
                        for z in (0.25, 0.75)])
    inside = np.concatenate([octants, octants + 0.01, octants[:1] + 0.02])
    pos = (corners[:, None, :] + inside[None]).reshape(-1, 3)
    # two bodies on the bounding cube's corners align the Morton grid with the unit cells
    pos = np.concatenate([pos, [[0.0, 0.0, 0.0], [units, units, units]]])
    n = pos.shape[0]
    return ic.Bodies(np.full(n, 1.0 / n), pos, np.zeros_like(pos), np.zeros(n))


@pytest.mark.parametrize("method", METHODS)
def test_a_scene_with_more_cells_than_the_workspace(method):
    """Measured: 1.3e-15 median, 9e-15 largest at theta = 0; 2.3e-4 median, 2.6e-2 largest
    at 0.5."""
    bodies = crowded_lattice()
    reference = accelerations(bodies, gravity(softening=1e-3))
    exact = tree_errors(bodies, gravity, reference, method, softening=1e-3, theta=0.0)
    assert exact.max() < 1e-12
    median, p99 = summary(tree_errors(bodies, gravity, reference, method, softening=1e-3,
                                      theta=0.5))
    assert median < 1e-3 and p99 < 2e-2, (median, p99)


@pytest.mark.parametrize("method", METHODS)
def test_coincident_bodies_and_two_tree_terms(method):
    """100 bodies at two points (leaves that cannot split, larger than a group), and gravity
    and Coulomb both by the tree in one simulation (one workspace, used in turn): the direct
    sums' accelerations at theta = 0 (measured 6e-16 and 4e-14)."""
    pos = np.zeros((100, 3))
    pos[50:] = 1.0
    pair = ic.Bodies(np.ones(100), pos, np.zeros((100, 3)), np.zeros(100))
    direct = accelerations(pair, gravity(softening=0.1))
    tree = accelerations(pair, gravity(softening=0.1, method=method, theta=0.5))
    assert np.abs(tree - direct).max() < 1e-13 * np.abs(direct).max()
    plasma = ic.plasma(2000, 3, seed=2)
    terms = ({"G": 2.0}, {"k": 1e-3})
    direct = accelerations(plasma, gravity(**terms[0]), coulomb(**terms[1]))
    tree = accelerations(plasma, gravity(method=method, theta=0.0, **terms[0]),
                         coulomb(method=method, theta=0.0, **terms[1]))
    assert relative_errors(tree, direct).max() < 1e-12
