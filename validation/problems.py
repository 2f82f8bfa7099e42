"""The validation problems: initial conditions, the engine force terms, and what counts as right.

A :class:`Problem` is plain data (picklable, so worker processes can receive it). ``make_sim``
turns it into an ``engine.Simulation``; ``validation.reference`` turns it into a REBOUND
simulation or a reference solution.

Sources of the initial conditions and published facts:

- Kepler problem (E. Hairer, C. Lubich, G. Wanner, *Geometric Numerical Integration*, 2nd ed.,
  Springer 2006, sec. I.2): q(0) = (1 - e, 0), p(0) = (0, sqrt((1 + e)/(1 - e))), H = -1/2,
  period 2 pi.
- Figure-eight choreography (A. Chenciner, R. Montgomery, "A remarkable periodic solution of
  the three-body problem in the case of equal masses", Annals of Mathematics 152, 2000, with
  C. Simo's initial data), period 6.32591398.
- Pythagorean three-body problem (C. Burrau, Astronomische Nachrichten 195, 1913; V. Szebehely,
  C. F. Peters, "Complete solution of a general problem of three bodies", Astronomical
  Journal 72, 1967), E0 = -769/60; the lightest body (m = 3) escapes and the other two leave as
  a binary.
- Outer solar system (Hairer, Lubich & Wanner, sec. I.2.4) in AU, days and solar masses with
  G = 2.95912208286e-4.
"""
import math
from dataclasses import dataclass, field, replace

import numpy as np

from engine import Simulation, analytic, forces

#: G in AU^3 / (Msun day^2) (Hairer, Lubich & Wanner's outer solar system)
G_SOLAR = 2.95912208286e-4
#: figure-eight period (Simo)
FIGURE_EIGHT_PERIOD = 6.32591398
#: Pythagorean problem's total energy, exactly
PYTHAGOREAN_ENERGY = -769.0 / 60.0


@dataclass(frozen=True)
class Problem:
    """A validation problem.

    ``forces`` is a tuple of ``(kind, parameters)`` with kind one of ``"point_mass"``,
    ``"nbody"``, ``"coulomb"``, ``"springs"``. ``unit`` is the natural time unit (an orbital
    period) in which step counts are quoted, ``length`` the length L that normalises position
    errors, ``reference`` names the reference solution (``"kepler"``, ``"ias15"``, ``"rk45"``,
    ``"modes"``).
    """

    key: str
    title: str
    dim: int
    mass: np.ndarray
    pos: np.ndarray
    vel: np.ndarray
    forces: tuple
    t_end: float
    unit: float
    unit_name: str
    length: float
    length_name: str
    reference: str
    charge: np.ndarray = None
    G: float = 1.0
    rebound: bool = False
    notes: str = ""
    extra: dict = field(default_factory=dict)

    @property
    def n(self):
        return self.mass.shape[0]


def _arr(x):
    return np.array(x, dtype=np.float64)


def make_force(kind, params):
    """One engine force term from its ``(kind, parameters)`` description."""
    if kind == "point_mass":
        return forces.PointMass(**params)
    if kind == "nbody":
        return forces.NBodyGravity(**params)
    if kind == "coulomb":
        return forces.Coulomb(**params)
    if kind == "springs":
        return forces.Springs(**params)
    raise ValueError(f"unknown force kind {kind!r}")


def make_sim(problem, integrator, dt, tolerance=1e-9, overrides=None, options=None):
    """An engine simulation of ``problem`` with the given integrator and step.

    ``overrides`` may replace force parameters: ``{kind: {name: value}}`` (e.g. softening).
    ``options`` are further ``Simulation`` arguments of the integrator (``corrector``,
    ``saba``, ``janus_order``, ...).
    """
    sim = Simulation(dim=problem.dim, integrator=integrator, dt=dt, tolerance=tolerance,
                     G=problem.G, **dict(options or {}))
    sim.add_many(mass=problem.mass, pos=problem.pos, vel=problem.vel,
                 charge=0.0 if problem.charge is None else problem.charge)
    for kind, params in problem.forces:
        params = dict(params)
        if overrides and kind in overrides:
            params.update(overrides[kind])
        sim.add_force(make_force(kind, params))
    return sim


# -- two-body problems -----------------------------------------------------------------------------

def kepler(e, t_end_orbits=10.0):
    """A test particle on a bound orbit about a fixed mu = 1 attractor, a = 1, from pericentre."""
    r0 = _arr([[1.0 - e, 0.0]])
    v0 = _arr([[0.0, math.sqrt((1.0 + e) / (1.0 - e))]])
    period = 2.0 * math.pi
    return Problem(
        key=f"kepler_e{e:g}", title=f"Kepler e = {e:g}", dim=2, mass=_arr([1.0]), pos=r0,
        vel=v0, forces=(("point_mass", {"mu": 1.0}),), t_end=t_end_orbits * period,
        unit=period, unit_name="orbit", length=1.0, length_name="a = 1",
        reference="kepler", rebound=True,
        notes="test particle about a fixed mu = 1 centre (PointMass); REBOUND: central mass 1 "
              "plus a massless particle", extra={"e": e, "mu": 1.0, "a": 1.0})


def hyperbolic(e=2.0, start=-math.pi):
    """A hyperbolic flyby, a = -1, e = 2 (pericentre q = 1), starting ``start`` before pericentre.

    The time unit is 2 pi |a|^(3/2) / sqrt(mu) = 2 pi, the same as for the bound orbits.
    """
    q = 1.0
    rp = np.array([q, 0.0])
    vp = np.array([0.0, math.sqrt((1.0 + e) / q)])
    r0, v0 = analytic.kepler(rp, vp, 1.0, start)
    period = 2.0 * math.pi
    return Problem(
        key="hyperbolic", title=f"hyperbolic flyby e = {e:g}", dim=2, mass=_arr([1.0]),
        pos=np.array([r0]), vel=np.array([v0]), forces=(("point_mass", {"mu": 1.0}),),
        t_end=10 * period, unit=period, unit_name="unit 2 pi |a|^1.5", length=1.0,
        length_name="q = 1", reference="kepler", rebound=True,
        notes=f"a = -1, pericentre q = 1, starts {abs(start):.4g} time units before pericentre",
        extra={"e": e, "mu": 1.0, "a": -1.0})


def kepler_long(e=0.9, orbits=100):
    """``kepler(e)`` over ``orbits`` orbits, under a key of its own (the two-body section has a
    ``kepler_e0.9`` of 10 orbits)."""
    p = kepler(e, t_end_orbits=orbits)
    return replace(p, key=f"kepler_e{e:g}_{orbits:g}_orbits",
                   title=f"Kepler e = {e:g}, {orbits:g} orbits",
                   extra=dict(p.extra, wp_steps_factor=10))


def star_with_test_particles(n=200, orbits=20, seed=3):
    """``n`` test particles on random bound orbits about a fixed mu = 1 star (``PointMass``).

    Semi-major axes uniform in [0.6, 1.6], eccentricities uniform in [0, 0.3], inclinations
    uniform in [0, 0.5] rad, the node, the argument of pericentre and the mean anomaly uniform
    (numpy seed ``seed``). Each particle is an independent Kepler problem, so the closed form
    is the reference; the time unit is the period 2 pi of a = 1.
    """
    rng = np.random.default_rng(seed)
    a = rng.uniform(0.6, 1.6, n)
    e = rng.uniform(0.0, 0.3, n)
    inc = rng.uniform(0.0, 0.5, n)
    node, peri, mean = rng.uniform(0.0, 2.0 * math.pi, (3, n))
    pos = np.empty((n, 3))
    vel = np.empty((n, 3))
    for i in range(n):
        r_p = a[i] * (1.0 - e[i])
        v_p = math.sqrt((1.0 + e[i]) / r_p)  # mu = 1, at pericentre
        # pericentre state in the orbital plane, then the time from pericentre to mean anomaly
        r, v = analytic.kepler(np.array([r_p, 0.0]), np.array([0.0, v_p]), 1.0,
                               mean[i] * a[i] ** 1.5)
        rot = orbit_rotation(node[i], inc[i], peri[i])
        pos[i] = rot @ np.array([r[0], r[1], 0.0])
        vel[i] = rot @ np.array([v[0], v[1], 0.0])
    period = 2.0 * math.pi
    return Problem(
        key=f"star_{n}_test_particles", title=f"star with {n} test particles, {orbits:g} orbits",
        dim=3, mass=np.ones(n), pos=pos, vel=vel,
        forces=(("point_mass", {"mu": 1.0, "pos": (0.0, 0.0, 0.0)}),),
        t_end=orbits * period, unit=period, unit_name="orbit of a = 1", length=1.0,
        length_name="1 (a = 1)", reference="kepler", rebound=True,
        notes=f"{n} particles about a fixed mu = 1 star (PointMass), no mutual forces; a in "
              f"[0.6, 1.6], e in [0, 0.3], inclination in [0, 0.5] rad, angles uniform (numpy "
              f"seed {seed}); REBOUND: a central mass 1 and {n} massless particles (N_active = "
              "1)", extra={"seed": seed})


def orbit_rotation(node, inc, peri):
    """R_z(node) R_x(inc) R_z(peri): orbital plane to the reference frame."""
    def rz(x):
        c, s = math.cos(x), math.sin(x)
        return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    c, s = math.cos(inc), math.sin(inc)
    rx = np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    return rz(node) @ rx @ rz(peri)


def two_body_set():
    """The eccentricities of the two-body section and the hyperbolic flyby."""
    return [kepler(0.0), kepler(0.5), kepler(0.9), kepler(0.99), hyperbolic()]


# -- few-body gravity ------------------------------------------------------------------------------

def figure_eight(periods=10.0):
    x1 = np.array([0.97000436, -0.24308753])
    v3 = np.array([-0.93240737, -0.86473146])
    return Problem(
        key="figure_eight", title="figure-eight, 10 periods", dim=2, mass=_arr([1.0, 1.0, 1.0]),
        pos=np.array([x1, -x1, [0.0, 0.0]]), vel=np.array([-v3 / 2, -v3 / 2, v3]),
        forces=(("nbody", {}),), t_end=periods * FIGURE_EIGHT_PERIOD, unit=FIGURE_EIGHT_PERIOD,
        unit_name="period", length=1.0, length_name="1 (the eight is 2.2 wide)",
        reference="ias15", rebound=True,
        notes="Chenciner & Montgomery (2000), Simo's data. REBOUND's WHFast and SABA work in "
              "Jacobi coordinates: body 3 starts exactly at the centre of mass of bodies 1 and "
              "2, its Jacobi coordinate is zero, and both return NaN after their first step at "
              "every dt (so they have no points here)")


def pythagorean(t_end=70.0):
    """The Pythagorean problem to ``t_end``: to t = 70 (key ``pythagorean``) measured by the
    energy error (no double precision solution is known there to better than about 1e-2 in
    position); to an earlier time (key ``pythagorean_t30`` for 30) by the position error
    against IAS15, which is known there to a few 1e-9."""
    if t_end != 70.0:
        p = pythagorean()
        return replace(p, key=f"pythagorean_t{t_end:g}",
                       title=f"Pythagorean three-body, t = {t_end:g}", t_end=t_end,
                       notes="Burrau (1913), Szebehely & Peters (1967); E0 = -769/60; up to "
                             f"t = {t_end:g}, through the first close encounters, before the "
                             "escape", extra=dict(p.extra, metric="position"))
    return Problem(
        key="pythagorean", title="Pythagorean three-body, t = 70", dim=2,
        mass=_arr([3.0, 4.0, 5.0]), pos=_arr([[1.0, 3.0], [-2.0, -1.0], [1.0, -1.0]]),
        vel=np.zeros((3, 2)), forces=(("nbody", {}),), t_end=t_end, unit=1.0,
        unit_name="time unit", length=1.0, length_name="1", reference="ias15", rebound=True,
        notes="Burrau (1913), Szebehely & Peters (1967); E0 = -769/60; the m = 3 body escapes",
        extra={"energy": PYTHAGOREAN_ENERGY, "wp_steps_factor": 10})


def outer_solar_system(t_end=1.0e5):
    mass = _arr([1.00000597682, 9.54786104043e-4, 2.85583733151e-4, 4.37273164546e-5,
                 5.17759138449e-5, 1.0 / 1.3e8])
    pos = _arr([[0.0, 0.0, 0.0],
                [-3.5023653, -3.8169847, -1.5507963],
                [9.0755314, -3.0458353, -1.6483708],
                [8.3101420, -16.2901086, -7.2521278],
                [11.4707666, -25.7294829, -10.8169456],
                [-15.5387357, -25.2225594, -3.1902382]])
    vel = _arr([[0.0, 0.0, 0.0],
                [0.00565429, -0.00412490, -0.00190589],
                [0.00168318, 0.00483525, 0.00192462],
                [0.00354178, 0.00137102, 0.00055029],
                [0.00288930, 0.00114527, 0.00039677],
                [0.00276725, -0.00170702, -0.00136504]])
    jupiter_period = 4332.59
    return Problem(
        key="outer_solar_system", title=f"outer solar system, {t_end:.0e} days", dim=3,
        mass=mass, pos=pos, vel=vel, forces=(("nbody", {}),), t_end=t_end,
        unit=jupiter_period, unit_name="Jupiter orbit", length=5.2,
        length_name="5.2 AU (Jupiter's a)", reference="ias15", G=G_SOLAR, rebound=True,
        notes="Sun + Jupiter, Saturn, Uranus, Neptune, Pluto; AU, days, Msun; "
              "heliocentric start, no shift to the centre of mass (same in REBOUND)",
        extra={"names": ["Sun", "Jupiter", "Saturn", "Uranus", "Neptune", "Pluto"]})


# -- other forces ----------------------------------------------------------------------------------

def coulomb_cloud(n=20, softening=0.1, t_end=3.0, seed=1):
    """``n`` unit masses with alternating charges +1/-1, at rest, uniform in the unit ball."""
    rng = np.random.default_rng(seed)
    p = rng.normal(size=(n, 3))
    p /= np.linalg.norm(p, axis=1)[:, None]
    p *= rng.uniform(size=(n, 1)) ** (1.0 / 3.0)
    q = np.where(np.arange(n) % 2 == 0, 1.0, -1.0)
    return Problem(
        key="coulomb_cloud", title=f"Coulomb cloud, {n} charges", dim=3, mass=np.ones(n),
        pos=p, vel=np.zeros((n, 3)), charge=q,
        forces=(("coulomb", {"k": 1.0, "softening": softening}),), t_end=t_end, unit=1.0,
        unit_name="time unit", length=1.0, length_name="1 (cloud radius)", reference="rk45",
        notes=f"charges +1/-1 alternating, k = 1, Plummer softening {softening:g}, "
              f"uniform in the unit ball (numpy seed {seed}), at rest",
        extra={"softening": softening, "seed": seed})


def spring_chain(n=8, k_stiff=1.0e4, k_soft=1.0, amplitude=0.1, t_end=10.0, seed=7):
    """A free 1-D chain of unit masses: stiff springs inside pairs, soft springs between them.

    Motion stays on the x axis, where Hooke springs are exactly linear, so the normal modes of
    the stiffness matrix give the exact solution.
    """
    rng = np.random.default_rng(seed)
    x = np.arange(n, dtype=np.float64) + amplitude * rng.uniform(-1.0, 1.0, size=n)
    pos = np.column_stack((x, np.zeros(n)))
    k = np.array([k_stiff if s % 2 == 0 else k_soft for s in range(n - 1)])
    pairs = [(s, s + 1) for s in range(n - 1)]
    omega_max = float(np.sqrt(np.linalg.eigvalsh(stiffness_matrix(k, np.ones(n))).max()))
    return Problem(
        key="spring_chain", title=f"stiff spring chain, k = {k_stiff:g} / {k_soft:g}", dim=2,
        mass=np.ones(n), pos=pos, vel=np.zeros((n, 2)),
        forces=(("springs", {"pairs": pairs, "k": k, "rest_length": 1.0}),), t_end=t_end,
        unit=2.0 / omega_max, unit_name="2/omega_max", length=amplitude,
        length_name=f"{amplitude:g} (initial displacement scale)", reference="modes",
        notes=f"{n} unit masses on a line, springs of rest length 1 alternating k = "
              f"{k_stiff:g} and {k_soft:g}, random displacements up to {amplitude:g} (seed "
              f"{seed}), at rest; omega_max = {omega_max:.6g}",
        extra={"k": k, "omega_max": omega_max, "rest_length": 1.0})


def stiffness_matrix(k, mass):
    """Mass-weighted stiffness matrix M^-1/2 K M^-1/2 of a free 1-D chain."""
    n = mass.shape[0]
    K = np.zeros((n, n))
    for s, ks in enumerate(k):
        K[s, s] += ks
        K[s + 1, s + 1] += ks
        K[s, s + 1] -= ks
        K[s + 1, s] -= ks
    w = 1.0 / np.sqrt(mass)
    return K * w[:, None] * w[None, :]


def work_precision_set(level):
    """The problems of the work-precision section."""
    return [kepler(0.6), kepler_long(0.9, level.wp_kepler_orbits),
            star_with_test_particles(level.wp_star_particles, level.wp_star_orbits),
            figure_eight(), pythagorean(), pythagorean(30.0),
            outer_solar_system(level.solar_wp_days), coulomb_cloud(), spring_chain()]
