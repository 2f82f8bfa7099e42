"""Hard cases: which integrators stay stable, which become inaccurate, which blow up.

Outcomes:

- **blows up**: the engine detected a non-finite state and raised ``SimulationError`` (the
  engine never continues silently from one),
- **inaccurate**: the run finished but misses the case's accuracy criterion or the known
  outcome,
- **stable**: finished, meets the criterion and reproduces the known outcome.

The criteria are stated per case in ``CASES`` and in the report.
"""
import math

import numpy as np

import engine
from engine import SimulationError, analytic

from .jobs import Job
from .problems import (FIGURE_EIGHT_PERIOD, PYTHAGOREAN_ENERGY, Problem, figure_eight, kepler,
                       make_sim, pythagorean)
from .reference import RebRun

FIXED = tuple(name for name in engine.integrators.GENERAL if name != "rk45")

CASES = {
    "e099": {
        "title": "Kepler e = 0.99, pericentre passages",
        "literature": "a closed Kepler ellipse: energy and orbit are conserved exactly "
                      "(the pericentre speed is sqrt(199) = 14.1 at r = 0.01)",
        "criterion": "stable: |dE/E| < 1e-2 and position error < 0.1 a after the run",
    },
    "pythagorean": {
        "title": "Pythagorean three-body problem to t = 70",
        "literature": "the lightest body (m = 3) escapes and bodies 4 and 5 leave as a bound "
                      "binary (Szebehely & Peters 1967)",
        "criterion": "stable: the m = 3 body escapes (positive energy relative to a bound 4-5 "
                     "binary, distance > 10) and |dE/E0| < 1e-2 against E0 = -769/60",
    },
    "figure_eight": {
        "title": "figure-eight, long-term",
        "literature": "the choreography is linearly (KAM) stable (Simo 2002): the bodies keep "
                      "following the eight",
        "criterion": "stable: |dE/E| < 1e-2 at every period and every body within 0.05 of the "
                     "eight traced by IAS15",
    },
    "spring": {
        "title": "stiff spring (k -> infinity at fixed dt)",
        "literature": "explicit methods are stable only for omega dt below a limit: 2 for "
                      "symplectic Euler, leapfrog and Verlet (the lecture's dt < 2/omega), "
                      "2 sqrt(2) for RK4, none for explicit Euler",
        "criterion": "stable: |dE/E| < 1e-2 over the run",
    },
    "flyby": {
        "title": "fast hyperbolic flyby, q = 0.01, v_inf = 10",
        "literature": "a Kepler hyperbola, deflection 2 arcsin(1/e) = 60 degrees for e = 2",
        "criterion": "stable: relative velocity error < 1e-3 after the flyby",
    },
    "coincident": {
        "title": "coincident and near-coincident particles",
        "literature": "two coincident point masses are singular (the engine must refuse: "
                      "SimulationError); Plummer softening makes the force finite",
        "criterion": "stable: |dE/E| < 1e-2 with the energy of the (softened) potential",
    },
}


def _outcome(blew_up, accurate):
    if blew_up:
        return "blows up"
    return "stable" if accurate else "inaccurate"


def _run_to(sim, t_end):
    try:
        sim.integrate(t_end)
        return None
    except SimulationError as exc:
        return exc


def _engine_run(p, integrator, setting):
    """Run problem ``p`` to its end: ``setting`` is the step, or rk45's tolerance."""
    if integrator == "rk45":
        sim = make_sim(p, "rk45", 1e-3, tolerance=setting)
    else:
        sim = make_sim(p, integrator, setting)
    return sim, _run_to(sim, p.t_end)


# -- e = 0.99 --------------------------------------------------------------------------------------

def e099_job(integrator, setting, orbits):
    p = kepler(0.99)
    t_end = orbits * p.unit
    if integrator == "rk45":
        sim = make_sim(p, "rk45", p.unit / 1000, tolerance=setting)
    else:
        sim = make_sim(p, integrator, p.unit / setting)
    e0 = sim.energy()
    exc = _run_to(sim, t_end)
    r, v = analytic.kepler(p.pos[0], p.vel[0], 1.0, sim.t)
    de = abs(sim.energy() - e0) / abs(e0)
    dr = float(np.linalg.norm(sim.pos[0] - r) / max(np.linalg.norm(r), 1.0))  # relative to a = 1
    return {"outcome": _outcome(exc is not None, de < 1e-2 and dr < 0.1), "energy_error": de,
            "pos_error": dr, "steps": sim.steps, "t": sim.t,
            "detail": f"|dE/E| {de:.1e}, dr {dr:.1e}" if exc is None else f"at t = {exc.time:.4g}"}


# -- Pythagorean -----------------------------------------------------------------------------------

def escaper(pos, vel, mass):
    """Index of the body that escapes from a bound binary of the other two, or None."""
    for k in range(3):
        i, j = [x for x in range(3) if x != k]
        mb = mass[i] + mass[j]
        cb = (mass[i] * pos[i] + mass[j] * pos[j]) / mb
        vb = (mass[i] * vel[i] + mass[j] * vel[j]) / mb
        mu = mass[k] * mb / (mass[k] + mb)
        r = float(np.linalg.norm(pos[k] - cb))
        e_rel = 0.5 * mu * float(np.sum((vel[k] - vb) ** 2)) - mass[k] * mb / r
        rb = float(np.linalg.norm(pos[i] - pos[j]))
        e_bin = 0.5 * mass[i] * mass[j] / mb * float(np.sum((vel[i] - vel[j]) ** 2)) \
            - mass[i] * mass[j] / rb
        if e_rel > 0.0 and e_bin < 0.0 and r > 10.0:
            return k
    return None


def pythagorean_job(integrator, setting, code="engine"):
    p = pythagorean()
    if code == "rebound":
        run = RebRun(p, "ias15", epsilon=setting)
        closest = (math.inf, 0.0)
        while run.t < p.t_end:
            run.steps(1)
            pos, _ = run.state()
            d = min(np.linalg.norm(pos[a] - pos[b]) for a, b in ((0, 1), (0, 2), (1, 2)))
            if d < closest[0]:
                closest = (float(d), float(run.t))
        run.integrate(p.t_end)
        pos, vel = run.state()
        energy, steps, exc = run.energy(), int(run.sim.steps_done), None
    else:
        sim, exc = _engine_run(p, integrator, setting)
        pos, vel, energy, steps = sim.pos.copy(), sim.vel.copy(), sim.energy(), sim.steps
        closest = None
    de = abs(energy - PYTHAGOREAN_ENERGY) / abs(PYTHAGOREAN_ENERGY)
    k = None if exc is not None else escaper(pos, vel, p.mass)
    reproduced = k == 0
    out = {"outcome": _outcome(exc is not None, reproduced and de < 1e-2), "energy_error": de,
           "escaper_mass": None if k is None else float(p.mass[k]), "reproduced": reproduced,
           "steps": steps}
    if exc is not None:
        out["detail"] = f"at t = {exc.time:.4g}"
    else:
        who = "no escape" if k is None else f"m = {p.mass[k]:g} escapes"
        out["detail"] = f"{who}, |dE/E0| {de:.1e}"
    if closest is not None:
        out["closest_approach"] = closest[0]
        out["closest_approach_time"] = closest[1]
    return out


# -- figure-eight ----------------------------------------------------------------------------------

def _eight_curve(samples=3000):
    """Body 1's path over one period from IAS15: the eight every body should follow."""
    run = RebRun(figure_eight(), "ias15", epsilon=1e-11)
    pts = [run.state()[0][0]]
    for t in np.linspace(0.0, FIGURE_EIGHT_PERIOD, samples, endpoint=False)[1:]:
        run.integrate(float(t))
        pts.append(run.state()[0][0])
    return np.array(pts)


def _distance_to_curve(points, curve):
    """Distance of each point to the closed polyline ``curve`` (segment-wise, not vertex-wise)."""
    a = curve
    b = np.roll(curve, -1, axis=0)
    ab = b - a
    ab2 = np.sum(ab * ab, axis=1)
    out = np.empty(points.shape[0])
    for i, p in enumerate(points):
        if not np.all(np.isfinite(p)):
            out[i] = math.inf
            continue
        s = np.clip(np.sum((p - a) * ab, axis=1) / ab2, 0.0, 1.0)
        d = p - (a + s[:, None] * ab)
        out[i] = math.sqrt(float(np.min(np.sum(d * d, axis=1))))
    return out


def figure_eight_job(integrator, setting, periods):
    p = figure_eight()
    curve = _eight_curve()
    if integrator == "rk45":
        sim = make_sim(p, "rk45", FIGURE_EIGHT_PERIOD / 100, tolerance=setting)
    else:
        sim = make_sim(p, integrator, FIGURE_EIGHT_PERIOD / setting)
    e0 = sim.energy()
    worst_e = 0.0
    worst_shape = 0.0
    exc = None
    checks = np.unique(np.round(np.geomspace(1, periods, 40)).astype(int))
    for k in range(1, periods + 1):
        exc = _run_to(sim, k * FIGURE_EIGHT_PERIOD)
        if exc is not None:
            break
        worst_e = max(worst_e, abs(sim.energy() - e0) / abs(e0))
        if k in checks or k == periods:
            worst_shape = max(worst_shape, float(_distance_to_curve(sim.pos, curve).max()))
        if not np.all(np.abs(sim.pos) < 1e6):
            break
    ok = exc is None and worst_e < 1e-2 and worst_shape < 0.05
    return {"outcome": _outcome(exc is not None, ok), "energy_error": worst_e,
            "shape_error": worst_shape, "steps": sim.steps, "periods": periods,
            "detail": (f"|dE/E| {worst_e:.1e}, off the eight {worst_shape:.1e}"
                       if exc is None else f"at t = {exc.time:.4g}")}


# -- stiff spring ----------------------------------------------------------------------------------

def spring_problem(k, stretch=0.1):
    """Two unit masses joined by one zero-rest-length spring: f = k d exactly, a linear
    oscillator at every amplitude (a spring with a rest length turns nonlinear once an
    amplified numerical oscillation pushes the ends through each other)."""
    return Problem(
        key="spring", title=f"one spring, k = {k:g}", dim=2, mass=np.array([1.0, 1.0]),
        pos=np.array([[0.0, 0.0], [stretch, 0.0]]), vel=np.zeros((2, 2)),
        forces=(("springs", {"pairs": [(0, 1)], "k": k, "rest_length": 0.0}),),
        t_end=1.0, unit=1.0, unit_name="", length=1.0, length_name="", reference="modes")


def spring_omega(k):
    return math.sqrt(2.0 * k)  # two unit masses: reduced mass 1/2


GROWTH_LIMIT = 1e6


def spring_run(integrator, k, dt, steps, chunks=40, stop_on_growth=True):
    """One spring for ``steps`` steps: ``(blew_up, grew, max |dE/E|, steps_done)``.

    ``grew``: the energy passed GROWTH_LIMIT times its start (exponential growth; a stable
    linear scheme keeps a modified energy, so its energy stays within a bounded factor that
    only approaches 1e6 within about 1e-6 of its stability limit).
    """
    p = spring_problem(k)
    sim = make_sim(p, integrator, dt)
    e0 = sim.energy()
    worst = 0.0
    biggest = e0
    # irregular chunk lengths, so that a state that repeats every few steps (omega dt = sqrt 2
    # makes leapfrog's one-step matrix a quarter turn) is not sampled at one phase only
    base = max(1, steps // chunks - 6)
    sizes = [base + (7 * c) % 13 for c in range(chunks)]
    sizes[-1] = max(1, sizes[-1] + steps - sum(sizes))
    try:
        for per in sizes:
            sim.step(per)
            e = sim.energy()
            worst = max(worst, abs(e - e0) / e0)
            biggest = max(biggest, e)
            if stop_on_growth and (not math.isfinite(e) or biggest > GROWTH_LIMIT * e0):
                break
    except SimulationError:
        return True, True, math.inf, sim.steps
    grew = not math.isfinite(biggest) or biggest > GROWTH_LIMIT * e0
    return False, grew, worst, sim.steps


def spring_limit_job(integrator, k, steps, iterations):
    """Largest stable omega dt: scan a grid for the first unstable value, then bisect."""
    omega = spring_omega(k)
    grid = np.concatenate((np.geomspace(1e-3, 0.5, 12), np.arange(0.55, 4.0001, 0.05)))
    last_stable = 0.0
    first_unstable = None
    for x in grid:
        blew, grew, _, _ = spring_run(integrator, k, x / omega, steps)
        if blew or grew:
            first_unstable = float(x)
            break
        last_stable = float(x)
    if first_unstable is None:
        return {"omega": omega, "limit": None, "note": "stable up to omega dt = 4"}
    lo, hi = last_stable, first_unstable
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        blew, grew, _, _ = spring_run(integrator, k, mid / omega, steps)
        if blew or grew:
            hi = mid
        else:
            lo = mid
    return {"omega": omega, "limit": lo, "limit_dt": lo / omega, "bracket": [lo, hi],
            "steps": steps}


def spring_outcome_job(integrator, k, dt, steps):
    if integrator == "rk45":
        p = spring_problem(k)
        sim = make_sim(p, "rk45", dt, tolerance=1e-9)
        e0 = sim.energy()
        exc = _run_to(sim, steps * dt)
        de = abs(sim.energy() - e0) / e0
        return {"outcome": _outcome(exc is not None, de < 1e-2), "energy_error": de,
                "steps": sim.steps, "detail": f"|dE/E| {de:.1e}, {sim.steps} adaptive steps"}
    blew, _, err, done = spring_run(integrator, k, dt, steps, stop_on_growth=False)
    return {"outcome": _outcome(blew, err < 1e-2), "energy_error": err, "steps": done,
            "detail": "non-finite, detected" if blew else f"|dE/E| {err:.1e}"}


def theory_limit(integrator):
    """omega dt stability limit of each scheme on x'' = -omega^2 x, from its published
    coefficients (reference doc), independently of the engine: the first omega h where the
    one-step matrix stops being stable."""
    w1 = 1.0 / (2.0 - 2.0 ** (1.0 / 3.0))
    w0 = -(2.0 ** (1.0 / 3.0)) / (2.0 - 2.0 ** (1.0 / 3.0))
    xi, lam, chi = 0.1786178958448091, -0.2123418310626054, -0.06626458266981849
    verlet = [("k", 0.5), ("d", 1.0), ("k", 0.5)]
    sequences = {
        "symplectic_euler": [("k", 1.0), ("d", 1.0)],
        "leapfrog": [("d", 0.5), ("k", 1.0), ("d", 0.5)],
        "verlet": verlet,
        "yoshida4": [(s, c * w) for w in (w1, w0, w1) for s, c in verlet],
        "pefrl": [("d", xi), ("k", (1 - 2 * lam) / 2), ("d", chi), ("k", lam),
                  ("d", 1 - 2 * (chi + xi)), ("k", lam), ("d", chi), ("k", (1 - 2 * lam) / 2),
                  ("d", xi)],
    }

    def stable(z):  # z = omega h
        if integrator == "rk4":
            w = 1j * z
            return abs(1 + w + w ** 2 / 2 + w ** 3 / 6 + w ** 4 / 24) <= 1.0 + 1e-15
        m = np.eye(2)
        for s, c in sequences[integrator]:
            if s == "d":
                step = np.array([[1.0, c * z], [0.0, 1.0]])
            else:
                step = np.array([[1.0, 0.0], [-c * z, 1.0]])
            m = step @ m
        return abs(np.trace(m)) / 2.0 <= 1.0  # det = 1: stable while |trace| <= 2

    if integrator == "rk45":
        return None
    if integrator == "euler":
        return 0.0  # |1 + i omega h| > 1 for every h > 0
    lo, hi = 0.0, None
    for z in np.arange(0.001, 6.0, 0.001):
        if not stable(z):
            hi = z
            break
        lo = z
    if hi is None:
        return None
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if stable(mid) else (lo, mid)
    return lo


# -- fast flyby ------------------------------------------------------------------------------------

def flyby_problem():
    q, e, mu = 0.01, 2.0, 1.0
    rp = np.array([q, 0.0])
    vp = np.array([0.0, math.sqrt(mu * (1.0 + e) / q)])
    r0, v0 = analytic.kepler(rp, vp, mu, -1.0)
    return Problem(key="flyby", title="fast flyby", dim=2, mass=np.array([1.0]),
                   pos=np.array([r0]), vel=np.array([v0]), forces=(("point_mass", {"mu": mu}),),
                   t_end=2.0, unit=1.0, unit_name="", length=1.0, length_name="",
                   reference="kepler", rebound=True, extra={"e": e, "q": q})


def flyby_job(integrator, setting):
    p = flyby_problem()
    if integrator == "ias15":
        run = RebRun(p, "ias15", epsilon=setting)
        run.integrate(p.t_end)
        pos, vel = run.state()
        steps, exc = int(run.sim.steps_done), None
    else:
        sim, exc = _engine_run(p, integrator, setting)
        vel, steps = sim.vel, sim.steps
    r, v = analytic.kepler(p.pos[0], p.vel[0], 1.0, p.t_end)
    dv = float(np.linalg.norm(vel[0] - v) / np.linalg.norm(v))
    cosang = float(np.dot(vel[0], v) / (np.linalg.norm(vel[0]) * np.linalg.norm(v)))
    dang = math.degrees(math.acos(max(-1.0, min(1.0, cosang))))
    return {"outcome": _outcome(exc is not None, dv < 1e-3), "vel_error": dv,
            "deflection_error_deg": dang, "steps": steps,
            "detail": f"dv/v {dv:.1e}, angle off {dang:.2g} deg" if exc is None
            else f"at t = {exc.time:.4g}"}


# -- coincident particles --------------------------------------------------------------------------

def coincident_problem(variant):
    """``exact``: two bodies at the same point (plus a third to move things), at rest.
    ``near``: two unit masses on a nearly radial orbit with pericentre 1e-6."""
    if variant == "exact":
        return Problem(key="coincident", title="coincident", dim=2, mass=np.ones(3),
                       pos=np.array([[0.0, 0.0], [0.0, 0.0], [1.0, 0.0]]), vel=np.zeros((3, 2)),
                       forces=(("nbody", {}),), t_end=0.1, unit=1.0, unit_name="", length=1.0,
                       length_name="", reference="ias15")
    # relative orbit: mu = 2, apocentre 1, pericentre 1e-6
    mu, ra, rp = 2.0, 1.0, 1e-6
    a = 0.5 * (ra + rp)
    v_apo = math.sqrt(mu * rp / (a * ra))  # vis-viva at apocentre with h = sqrt(mu a (1-e^2))
    period = 2.0 * math.pi * math.sqrt(a ** 3 / mu)
    return Problem(key="near_coincident", title="near-coincident", dim=2, mass=np.ones(2),
                   pos=np.array([[-0.5, 0.0], [0.5, 0.0]]),
                   vel=np.array([[0.0, -0.5 * v_apo], [0.0, 0.5 * v_apo]]),
                   forces=(("nbody", {}),), t_end=period, unit=period, unit_name="", length=1.0,
                   length_name="", reference="ias15", extra={"pericentre": rp})


def coincident_job(integrator, variant, softening, dt):
    p = coincident_problem(variant)
    overrides = {"nbody": {"softening": softening}}
    sim = make_sim(p, integrator, dt, tolerance=1e-9, overrides=overrides)
    e0 = sim.energy()
    exc = _run_to(sim, p.t_end)
    de = abs(sim.energy() - e0) / abs(e0)
    out = {"outcome": _outcome(exc is not None, de < 1e-2), "energy_error": de, "steps": sim.steps}
    if exc is not None:
        out["detail"] = f"SimulationError at step {exc.step}"
    else:
        out["detail"] = f"|dE/E| {de:.1e}"
    return out


# -- jobs ------------------------------------------------------------------------------------------

COINCIDENT_ROWS = (
    ("exact", 0.0, 1e-3, "coincident, no softening"),
    ("exact", 0.01, 1e-3, "coincident, softening 0.01"),
    ("near", 0.0, 1e-4, "pericentre 1e-6, no softening"),
    ("near", 0.01, 1e-4, "pericentre 1e-6, softening 0.01"),
)


ADAPTIVE = {  # rk45 tolerances (and IAS15 epsilons) per case
    "e099": (1e-9, 1e-12),
    "pythagorean": (1e-10, 1e-12),
    "figure_eight": (1e-9,),
    "flyby": (1e-6, 1e-9),
}


def jobs(level):
    out = []
    for name in engine.integrators.GENERAL:
        adaptive = name == "rk45"
        for s in ADAPTIVE["e099"] if adaptive else level.hc_e099_steps:
            out.append(Job(("hc", "e099", name, s), "hard_cases:e099_job",
                           dict(integrator=name, setting=s, orbits=level.hc_e099_orbits),
                           cost=1e5 if adaptive else s * level.hc_e099_orbits))
        for s in ADAPTIVE["pythagorean"] if adaptive else level.hc_pyth_dts:
            out.append(Job(("hc", "pythagorean", name, s), "hard_cases:pythagorean_job",
                           dict(integrator=name, setting=s),
                           cost=3e5 if adaptive else (70 / s) * 3))
        for s in ADAPTIVE["figure_eight"] if adaptive else level.hc_fig8_steps:
            out.append(Job(("hc", "figure_eight", name, s), "hard_cases:figure_eight_job",
                           dict(integrator=name, setting=s, periods=level.hc_fig8_periods),
                           cost=level.hc_fig8_periods * (300 if adaptive else s) * 3))
        for k in level.hc_spring_ks:
            out.append(Job(("hc", "spring_outcome", name, k), "hard_cases:spring_outcome_job",
                           dict(integrator=name, k=k, dt=0.01, steps=10_000),
                           cost=1e4 * (math.sqrt(k) if adaptive else 1)))
            if not adaptive:
                out.append(Job(("hc", "spring_limit", name, k), "hard_cases:spring_limit_job",
                               dict(integrator=name, k=k, steps=level.hc_spring_steps,
                                    iterations=level.hc_bisect_iterations),
                               cost=level.hc_spring_steps * (level.hc_bisect_iterations + 20)))
        for s in ADAPTIVE["flyby"] if adaptive else level.hc_flyby_dts:
            out.append(Job(("hc", "flyby", name, s), "hard_cases:flyby_job",
                           dict(integrator=name, setting=s), cost=1e4 if adaptive else 2 / s))
        for variant, soft, dt, _ in COINCIDENT_ROWS:
            out.append(Job(("hc", "coincident", name, (variant, soft)), "hard_cases:coincident_job",
                           dict(integrator=name, variant=variant, softening=soft, dt=dt), cost=2e4))
    out.append(Job(("hc", "pythagorean", "ias15", 1e-9), "hard_cases:pythagorean_job",
                   dict(integrator="ias15", setting=1e-9, code="rebound"), cost=1e4))
    out.append(Job(("hc", "flyby", "ias15", 1e-9), "hard_cases:flyby_job",
                   dict(integrator="ias15", setting=1e-9), cost=1e3))
    return out


def _label(case, name, setting):
    if name == "rk45":
        return f"rk45, tolerance {setting:g}"
    if name == "ias15":
        return f"REBOUND ias15, epsilon {setting:g}"
    if case == "e099":
        return f"{setting} steps/orbit"
    if case == "figure_eight":
        return f"{setting} steps/period"
    return f"dt {setting:g}"


def assemble(level, results):
    section = {"cases": CASES, "tables": {}}
    for case in ("e099", "pythagorean", "figure_eight", "flyby"):
        fixed, adaptive = {}, {}
        for key, res in sorted(results.items(), key=lambda kv: str(kv[0])):
            if key[0] != "hc" or key[1] != case:
                continue
            _, _, name, setting = key
            label = _label(case, name, setting)
            if name in ("rk45", "ias15"):
                adaptive[label] = dict(res, integrator=name, setting=setting)
            else:
                fixed.setdefault(name, {})[label] = dict(res, setting=setting)
        section["tables"][case] = {"fixed": fixed, "adaptive": adaptive}
    # stiff spring
    limits = {}
    outcomes = {}
    for key, res in results.items():
        if key[0] != "hc":
            continue
        if key[1] == "spring_limit":
            limits.setdefault(key[2], {})[key[3]] = res
        elif key[1] == "spring_outcome":
            outcomes.setdefault(key[2], {})[key[3]] = res
    section["spring_limits"] = {
        name: {"theory": theory_limit(name), "measured": limits.get(name, {})}
        for name in engine.integrators.GENERAL}
    section["spring_outcomes"] = outcomes
    section["spring_dt"] = 0.01
    section["spring_steps"] = level.hc_spring_steps
    coincident = {}
    for key, res in results.items():
        if key[0] == "hc" and key[1] == "coincident":
            coincident.setdefault(key[2], {})[f"{key[3][0]}|{key[3][1]:g}"] = res
    section["tables"]["coincident"] = {"fixed": coincident, "adaptive": {}}
    section["coincident_rows"] = [{"key": f"{v}|{s:g}", "label": lab, "dt": dt}
                                  for v, s, dt, lab in COINCIDENT_ROWS]
    return section
