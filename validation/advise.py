"""``python -m validation advise --problem NAME --t-end T --error E``: ``engine.advise`` on one of
the validation problems, printing every candidate's predicted step, error, work and time.

The command line takes only the named problems below (``engine.advise`` itself takes any
``Simulation``). Each has a default span, the error metric used for it in the validation
report (the Pythagorean problem's positions are chaotic: its energy is compared) and the
length that normalises its position errors.
"""
import argparse
import json
import math
import sys

import numpy as np

import engine
from engine import Simulation

from . import problems


def star_with_test_particles(n=200, orbits=20.0, seed=3):
    """A star of mass 1 (``NBodyGravity``, G = 1) and ``n`` test particles on prograde orbits
    in 3-D: semi-major axes uniform in [1, 2], eccentricities in [0, 0.2], inclinations up to
    0.1 rad, every angle uniform (numpy seed ``seed``); ``orbits`` periods of a = 1 (2 pi)."""
    rng = np.random.default_rng(seed)
    a = rng.uniform(1.0, 2.0, n)
    e = rng.uniform(0.0, 0.2, n)
    inc = rng.uniform(0.0, 0.1, n)
    node, peri, anomaly = (rng.uniform(0.0, 2.0 * math.pi, n) for _ in range(3))
    pos, vel = np.empty((n, 3)), np.empty((n, 3))
    for k in range(n):
        # true anomaly from the mean anomaly, then the orbit's plane rotated into place
        E = anomaly[k]
        for _ in range(50):
            E -= (E - e[k] * math.sin(E) - anomaly[k]) / (1.0 - e[k] * math.cos(E))
        f = 2.0 * math.atan2(math.sqrt(1 + e[k]) * math.sin(E / 2),
                             math.sqrt(1 - e[k]) * math.cos(E / 2))
        p = a[k] * (1.0 - e[k] ** 2)
        r = p / (1.0 + e[k] * math.cos(f))
        x = np.array([r * math.cos(f), r * math.sin(f), 0.0])
        v = np.array([-math.sin(f), e[k] + math.cos(f), 0.0]) / math.sqrt(p)
        R = problems.orbit_rotation(node[k], inc[k], peri[k])
        pos[k], vel[k] = R @ x, R @ v
    period = 2.0 * math.pi
    return problems.Problem(
        key="star_test_particles", title=f"star and {n} test particles, {orbits:g} orbits",
        dim=3, mass=np.concatenate(([1.0], np.zeros(n))),
        pos=np.vstack((np.zeros(3), pos)), vel=np.vstack((np.zeros(3), vel)),
        forces=(("nbody", {}),), t_end=orbits * period, unit=period, unit_name="orbit at a = 1",
        length=1.0, length_name="1 (the inner edge)", reference="ias15",
        notes=f"star m = 1 and {n} test particles (test=True: they feel the star, exert "
              f"nothing), a in [1, 2], e in [0, 0.2], i < 0.1, seed {seed}",
        extra={"test": np.concatenate(([False], np.ones(n, dtype=bool)))})


#: name -> (problem factory, metric)
PROBLEMS = {
    "outer_solar_system": (lambda: problems.outer_solar_system(1.0e5), "position"),
    "kepler_e0.9": (lambda: problems.kepler(0.9, 100.0), "position"),
    "kepler_e0.5": (lambda: problems.kepler(0.5, 100.0), "position"),
    "star_test_particles": (lambda: star_with_test_particles(200, 20.0), "position"),
    "pythagorean": (lambda: problems.pythagorean(30.0), "energy"),
    "figure_eight": (lambda: problems.figure_eight(10.0), "position"),
}


def make_sim(problem, integrator="leapfrog", dt=1.0, **options):
    """``problems.make_sim`` that also declares ``extra["test"]`` test particles."""
    test = problem.extra.get("test")
    if test is None:
        sim = problems.make_sim(problem, integrator, dt)
    else:
        sim = Simulation(dim=problem.dim, integrator=integrator, dt=dt, G=problem.G)
        sim.add_many(mass=problem.mass, pos=problem.pos, vel=problem.vel, test=test)
        for kind, params in problem.forces:
            sim.add_force(problems.make_force(kind, params))
    for name, value in options.items():
        setattr(sim, name, value)
    return sim


def scene(name, t_end=None):
    """``(problem, sim, t_end, metric)`` of the named problem (``t_end`` default: its own)."""
    if name not in PROBLEMS:
        raise ValueError(f"problem must be one of {', '.join(PROBLEMS)}, got {name!r}")
    factory, metric = PROBLEMS[name]
    problem = factory()
    return problem, make_sim(problem), problem.t_end if t_end is None else t_end, metric


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="python -m validation advise",
        description="Run engine.advise on one of the validation problems (only these named "
                    "problems: engine.advise itself takes any Simulation) and print every "
                    "candidate's predicted step, error, work and wall time.")
    parser.add_argument("--problem", required=True, choices=sorted(PROBLEMS),
                        help="the validation problem")
    parser.add_argument("--t-end", type=float, default=None,
                        help="end time in the problem's code units (default: the problem's)")
    parser.add_argument("--error", type=float, required=True,
                        help="the largest acceptable error at t_end")
    parser.add_argument("--metric", choices=engine.advisor.METRICS, default=None,
                        help="position (max |r - r_ref| / L, L the problem's length) or energy "
                             "(|dE/E0|); default: the problem's (energy for pythagorean)")
    parser.add_argument("--rank", choices=engine.advisor.RANKS, default="work",
                        help="rank by deterministic work (default) or measured wall time")
    parser.add_argument("--json", metavar="FILE", default=None,
                        help="also write the advice as JSON to FILE")
    args = parser.parse_args(argv)
    try:
        problem, sim, t_end, metric = scene(args.problem, args.t_end)
        metric = args.metric or metric
        advice = engine.advise(sim, t_end, args.error, metric=metric,
                               length=problem.length if metric == "position" else None,
                               rank=args.rank)
    except ValueError as exc:
        parser.error(str(exc))
    print(f"{problem.title}; length {problem.length:g} = {problem.length_name}"
          if metric == "position" else problem.title)
    print(advice.table())
    print(f"recommended: {advice.label}, " + (
        f"tolerance {advice.tolerance:.3g}" if advice.tolerance is not None
        else f"dt {advice.dt:.6g}") + f", predicted error {advice.error:.2e}, "
        f"{advice.seconds:.3g} s")
    if args.json:
        with open(args.json, "w") as out:
            json.dump(to_json(advice), out, indent=1)
    return 0


def to_json(advice):
    def clean(x):
        if isinstance(x, float) and not math.isfinite(x):
            return None
        return x
    data = {k: clean(getattr(advice, k)) for k in (
        "method", "dt", "tolerance", "error", "work", "seconds", "steps", "reached",
        "requested_error", "t_end", "span", "metric", "length", "rank", "time_scale",
        "pilot_span", "floor", "advisor_seconds", "advisor_work")}
    data["options"] = advice.options
    data["notes"] = list(advice.notes)
    data["candidates"] = [{k: clean(getattr(c, k)) for k in (
        "label", "method", "dt", "tolerance", "steps", "error", "work", "seconds", "verified",
        "skipped", "note")} | {"options": c.options} for c in advice.candidates]
    return data


if __name__ == "__main__":
    sys.exit(main())
