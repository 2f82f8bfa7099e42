"""Same algorithm, two codes: the engine's ``leapfrog`` against REBOUND's ``leapfrog``.

Both are drift-kick-drift with one force evaluation per step. Given the same system (same
masses, positions, velocities, G = 1, no shift to the centre of mass in either code) and the
same step, they can differ only by the rounding of the force arithmetic. To show that the
difference is round-off and not a different scheme, both are also compared with the same
algorithm run in 80-bit extended precision (numpy ``longdouble``): each code's own
round-off is then visible, and the two codes differ by about as much as each differs from
the extended-precision run.
"""
import math

import numpy as np

from .problems import Problem, figure_eight, kepler, make_sim
from .reference import RebRun


def two_massive_bodies():
    """m = 1 and 0.3 on an e = 0.5 relative orbit, with the centre of mass off the origin and
    moving (so a code that silently moved to the centre-of-mass frame would show at once)."""
    m1, m2 = 1.0, 0.3
    e = 0.5
    M = m1 + m2
    rel_r = np.array([1.0 - e, 0.0, 0.0])
    rel_v = np.array([0.0, math.sqrt(M * (1.0 + e) / (1.0 - e)), 0.0])
    com = np.array([0.1, 0.2, -0.05])
    com_v = np.array([0.01, -0.02, 0.003])
    pos = np.array([com - m2 / M * rel_r, com + m1 / M * rel_r])
    vel = np.array([com_v - m2 / M * rel_v, com_v + m1 / M * rel_v])
    period = 2.0 * math.pi / math.sqrt(M)
    return Problem(
        key="two_massive_bodies", title="two massive bodies (m = 1, 0.3), e = 0.5", dim=3,
        mass=np.array([m1, m2]), pos=pos, vel=vel,
        forces=(("nbody", {}),), t_end=period, unit=period, unit_name="orbit", length=1.0,
        length_name="1", reference="ias15", rebound=True)


def _prime_near(n):
    def is_prime(k):
        return k > 1 and all(k % d for d in range(2, int(k ** 0.5) + 1))
    while not is_prime(n):
        n += 1
    return n


def _extended_leapfrog(problem, h, n_steps, sample_every):
    """Drift-kick-drift in numpy longdouble; returns positions at every sample."""
    L = np.longdouble
    x = problem.pos.astype(L)
    v = problem.vel.astype(L)
    G = L(problem.G)
    kind, params = problem.forces[0]
    h = L(h)
    half = h / L(2)
    out = []
    if kind == "point_mass":
        mu = L(params.get("mu", 1.0))

        def acc(x):
            r2 = np.sum(x * x, axis=1)
            return -mu * x / (r2 * np.sqrt(r2))[:, None]
    else:
        m = problem.mass.astype(L)

        def acc(x):
            a = np.zeros_like(x)
            for i in range(x.shape[0]):
                for j in range(i + 1, x.shape[0]):
                    d = x[j] - x[i]
                    r2 = np.sum(d * d)
                    s = G / (r2 * np.sqrt(r2))
                    a[i] += s * m[j] * d
                    a[j] -= s * m[i] * d
            return a
    for k in range(1, n_steps + 1):
        x += half * v
        v += h * acc(x)
        x += half * v
        if k % sample_every == 0:
            out.append(np.array(x, dtype=np.float64))
    return out


def _scale(x, mass):
    """Size of a configuration (or velocity spread): largest |x_i - x_com|, at least |x_com|
    for a single particle about a fixed centre."""
    if x.shape[0] == 1:
        return float(np.linalg.norm(x[0]))
    com = (mass[:, None] * x).sum(axis=0) / mass.sum()
    return float(np.max(np.linalg.norm(x - com, axis=1)))


def compare(problem, steps_per_orbit, orbits, sample_every=None, extended=True):
    """Run both leapfrogs side by side; return the largest differences seen.

    Differences are max over samples and components of |x_engine - x_rebound| divided by the
    size of the configuration at that sample (largest distance from the centre of mass; for
    one particle about a fixed centre, its distance from the centre), and the same for
    velocities. Samples are taken every ``sample_every`` steps (default: a prime number of
    steps near a sixth of an orbit, so that the samples visit every phase of the orbit).
    """
    h = problem.unit / steps_per_orbit
    n_steps = int(round(orbits * steps_per_orbit))
    sample_every = sample_every or _prime_near(max(2, steps_per_orbit // 6))
    sim = make_sim(problem, "leapfrog", h)
    reb = RebRun(problem, "leapfrog", dt=h)
    dpos = dvel = 0.0
    eng_positions = []
    reb_positions = []
    done = 0
    while done + sample_every <= n_steps:
        sim.step(sample_every)
        reb.steps(sample_every)
        done += sample_every
        rp, rv = reb.state()
        dpos = max(dpos, float(np.max(np.abs(sim.pos - rp))) / _scale(rp, problem.mass))
        dvel = max(dvel, float(np.max(np.abs(sim.vel - rv))) / _scale(rv, problem.mass))
        eng_positions.append(sim.pos.copy())
        reb_positions.append(rp)
    out = {
        "problem": problem.title, "steps_per_orbit": steps_per_orbit, "dt": h,
        "steps": done, "orbits": done / steps_per_orbit,
        "max_rel_pos_difference": dpos, "max_rel_vel_difference": dvel,
        "time_engine": sim.t, "time_rebound": reb.t,
    }
    if extended and np.finfo(np.longdouble).eps < np.finfo(np.float64).eps:
        ext = _extended_leapfrog(problem, h, done, sample_every)
        m = problem.mass
        e_eng = max(float(np.max(np.abs(a - b))) / _scale(b, m) for a, b in zip(eng_positions, ext))
        e_reb = max(float(np.max(np.abs(a - b))) / _scale(b, m) for a, b in zip(reb_positions, ext))
        out["max_rel_pos_engine_vs_extended"] = e_eng
        out["max_rel_pos_rebound_vs_extended"] = e_reb
        out["extended_precision_eps"] = float(np.finfo(np.longdouble).eps)
    return out


def crosscheck_cases():
    return [
        ("two_massive_bodies", two_massive_bodies(), 110),
        ("kepler_test_particle", kepler(0.6), 100),
        ("figure_eight", figure_eight(), 200),
    ]


def run(orbits):
    """Every cross-check case for ``orbits`` orbits (periods)."""
    return {key: compare(problem, n, orbits) for key, problem, n in crosscheck_cases()}
