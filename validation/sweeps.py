"""Work-precision sweeps: error against cost for every method on every problem.

For each problem, every fixed-step engine integrator runs a sweep of step counts N (dt =
t_end / N, ``sim.step(N)``), ``rk45`` a sweep of tolerances (``sim.integrate(t_end)``), and on
the gravity problems REBOUND's ``ias15`` a sweep of epsilon and its ``whfast``, ``leapfrog``
and ``saba`` the same step counts. Each point records

- the error at t_end against the problem's reference (max_i |r_i - r_i^ref| / L; for the
  Pythagorean problem the relative energy error against E0 = -769/60, see ``metric``),
- the wall time of ``sim.step``/``sim.integrate`` alone (``time.perf_counter``; numba
  compilation excluded by a warm-up run of each integrator first; a run shorter than
  ``level.wp_repeat_below`` seconds is repeated up to ``level.wp_repeats`` times and the
  median kept),
- the force evaluations: ``engine.integrators.FORCE_EVALUATIONS`` per step (``rk45``: 6 per
  accepted step; rejected attempts are not visible from outside the engine and are not
  counted), REBOUND's counted by an ``additional_forces`` callback in a separate, untimed run.

A sweep goes from coarse to fine and stops once the error is below the reference's own
uncertainty (nothing more can be measured), or before a run whose force evaluations times
interacting pairs would pass ``level.wp_work_cap`` (a deterministic cost cap, so the set of
runs does not depend on the machine's speed).
"""
import math
import statistics
import time

import numpy as np

import engine
from engine import SimulationError

from .jobs import Job
from .problems import make_sim, work_precision_set
from .reference import RebRun, position_error, reference_states, reference_uncertainty

REBOUND_METHODS = ("ias15", "whfast", "leapfrog", "saba")
#: error levels of the "cheapest method" table
ERROR_LEVELS = (1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12)


def metric(problem):
    return "energy" if problem.key == "pythagorean" else "position"


def step_counts(level, problem=None):
    """Log-spaced step counts; a problem may ask for a longer sweep (``wp_steps_factor``)."""
    top = level.wp_max_steps * (problem.extra.get("wp_steps_factor", 1) if problem else 1)
    decades = math.log10(top / level.wp_min_steps)
    n = max(2, int(round(decades * level.wp_points)) + 1)
    return sorted({int(round(x)) for x in np.logspace(math.log10(level.wp_min_steps),
                                                      math.log10(top), n)})


def stop_floor(problem, ref):
    """Below this error a finer run measures nothing new (the reference's uncertainty)."""
    return ref["floor"] if metric(problem) == "position" else 1e-14


def pairs(problem):
    """Interacting pairs per force evaluation (1 for a single particle about a fixed centre)."""
    return max(1, problem.n * (problem.n - 1) // 2)


def too_much_work(problem, evaluations, level):
    """The sweep's deterministic cost cap: force evaluations times interacting pairs."""
    return evaluations * pairs(problem) > level.wp_work_cap


# -- references (untimed) --------------------------------------------------------------------------

def reference_job(problem):
    pos, vel = reference_states(problem, [problem.t_end])[0]
    sim = make_sim(problem, "leapfrog", 1.0)
    e0 = sim.energy()
    out = {"pos": pos, "vel": vel, "energy0": e0}
    out.update(reference_uncertainty(problem, problem.t_end))
    if problem.key == "pythagorean":
        out["energy0_exact"] = problem.extra["energy"]
    return out


def reference_jobs(level):
    return [Job(("wp_ref", p.key), "sweeps:reference_job", dict(problem=p), cost=50)
            for p in work_precision_set(level)]


# -- timed runs ------------------------------------------------------------------------------------

def _median_time(run_once, level):
    times = []
    result = None
    while True:
        result, seconds = run_once()
        times.append(seconds)
        if result.get("status") != "ok":
            break
        if sum(times) >= level.wp_repeat_below or len(times) >= level.wp_repeats:
            break
    return result, statistics.median(times), len(times)


def _errors(problem, ref, pos, energy):
    e_ref = ref.get("energy0_exact", ref["energy0"])
    out = {"pos_error": position_error(pos, ref["pos"], problem.length),
           "energy_error": abs(energy - e_ref) / abs(e_ref)}
    out["error"] = out["energy_error"] if metric(problem) == "energy" else out["pos_error"]
    return out


def sweep_engine(problem, integrator, ref, level):
    """Time the sweep of one engine integrator on one problem (runs in the main process)."""
    warm = make_sim(problem, integrator, problem.t_end / 1000)
    warm.step(1)  # compile / load the cached machine code before timing
    floor = stop_floor(problem, ref)
    points = []
    settings = level.wp_tolerances if integrator == "rk45" else step_counts(level, problem)
    evals_per = engine.integrators.FORCE_EVALUATIONS[integrator]
    for setting in settings:
        if integrator != "rk45" and too_much_work(problem, evals_per * setting, level):
            break

        def run_once():
            if integrator == "rk45":
                sim = make_sim(problem, "rk45", problem.t_end / 1000, tolerance=setting)
            else:
                sim = make_sim(problem, integrator, problem.t_end / setting)
            status = "ok"
            t0 = time.perf_counter()
            try:
                if integrator == "rk45":
                    sim.integrate(problem.t_end)
                else:
                    sim.step(setting)
            except SimulationError as exc:
                status = f"SimulationError at t = {exc.time:.6g}"
            seconds = time.perf_counter() - t0
            return {"sim": sim, "status": status}, seconds
        res, seconds, repeats = _median_time(run_once, level)
        sim = res["sim"]
        point = {"setting": setting, "steps": sim.steps, "evaluations": evals_per * sim.steps,
                 "time_s": seconds, "timing_repeats": repeats, "status": res["status"]}
        if res["status"] == "ok":
            point.update(_errors(problem, ref, sim.pos, sim.energy()))
        points.append(point)
        if res["status"] == "ok" and point["error"] < max(floor, 1e-14):
            break
        if too_much_work(problem, point["evaluations"], level):
            break
    return points


def sweep_rebound(problem, integrator, ref, level):
    floor = stop_floor(problem, ref)
    points = []
    if integrator == "ias15":
        settings = level.wp_ias15_epsilons
    else:
        settings = step_counts(level, problem)
        counter = RebRun(problem, integrator, dt=problem.t_end / 1000, count_evaluations=True)
        counter.steps(10)
        per_step = counter.evaluations / 10
    for setting in settings:
        if integrator != "ias15" and too_much_work(problem, per_step * setting, level):
            break
        if integrator == "ias15":
            # count first (untimed, with a cost cap): an adaptive run can need unbounded work
            cap = level.wp_work_cap / pairs(problem)
            counter = RebRun(problem, "ias15", epsilon=setting, count_evaluations=True,
                             max_evaluations=cap)
            counter.integrate(problem.t_end)
            evaluations = counter.evaluations
            if counter.stopped:
                points.append({"setting": setting, "steps": int(counter.sim.steps_done),
                               "evaluations": evaluations, "time_s": None,
                               "status": f"stopped at t = {counter.t:.6g}: over the cost cap of "
                                         f"{cap:.3g} force evaluations"})
                continue

        def run_once():
            if integrator == "ias15":
                run = RebRun(problem, "ias15", epsilon=setting)
            else:
                run = RebRun(problem, integrator, dt=problem.t_end / setting)
            status = "ok"
            t0 = time.perf_counter()
            try:
                if integrator == "ias15":
                    run.integrate(problem.t_end)
                else:
                    run.steps(setting)
            except Exception as exc:  # REBOUND's own exception classes
                status = f"REBOUND error: {exc}"
            seconds = time.perf_counter() - t0
            return {"run": run, "status": status}, seconds
        res, seconds, repeats = _median_time(run_once, level)
        run = res["run"]
        pos, _ = run.state()
        status = res["status"]
        if status == "ok" and not np.all(np.isfinite(pos)):
            status = "non-finite state"
        if integrator != "ias15":
            evaluations = int(round(per_step * run.sim.steps_done))
        point = {"setting": setting, "steps": int(run.sim.steps_done), "evaluations": evaluations,
                 "time_s": seconds, "timing_repeats": repeats, "status": status}
        if run.warnings:
            point["rebound_warnings"] = run.warnings
        if status == "ok":
            point.update(_errors(problem, ref, pos, run.energy()))
        points.append(point)
        if status == "ok" and point["error"] < max(floor, 1e-14):
            break
        if too_much_work(problem, evaluations, level):
            break
    return points


def timed_jobs(level):
    out = []
    for p in work_precision_set(level):
        for name in engine.integrators.GENERAL:
            out.append(Job(("wp", p.key, "engine", name), "sweeps:sweep_engine",
                           dict(problem=p, integrator=name)))
        if p.rebound:
            for name in REBOUND_METHODS:
                out.append(Job(("wp", p.key, "rebound", name), "sweeps:sweep_rebound",
                               dict(problem=p, integrator=name)))
    return out


# -- summary ---------------------------------------------------------------------------------------

def cheapest(runs, levels=ERROR_LEVELS, floor=0.0):
    """For each error level: the fastest run, the one with fewest force evaluations, and the
    fastest engine run, among runs whose error is at most the level."""
    table = []
    for lev in levels:
        ok = [r for r in runs if r.get("error") is not None and r["error"] <= lev]
        row = {"level": lev, "below_reference_floor": lev < floor}
        engine_ok = [r for r in ok if r["code"] == "engine"]
        for name, pool, key in (("fastest", ok, "time_s"),
                                ("fewest_evaluations", ok, "evaluations"),
                                ("fastest_engine", engine_ok, "time_s")):
            best = min(pool, key=lambda r: r[key]) if pool else None
            row[name] = None if best is None else {
                "method": best["method"], "setting": best["setting_label"],
                "time_s": best["time_s"], "evaluations": best["evaluations"],
                "error": best["error"]}
        table.append(row)
    return table


def setting_label(code, integrator, setting):
    if integrator == "rk45":
        return f"tol {setting:g}"
    if integrator == "ias15":
        return f"eps {setting:g}"
    return f"N = {setting}"


def assemble(level, references, sweeps):
    section = {}
    for p in work_precision_set(level):
        ref = references[("wp_ref", p.key)]
        runs = []
        for key, points in sweeps.items():
            if key[0] != "wp" or key[1] != p.key:
                continue
            _, _, code, name = key
            for pt in points:
                run = dict(pt)
                run.update({"method": f"{code}:{name}", "code": code, "integrator": name,
                            "setting_label": setting_label(code, name, pt["setting"])})
                runs.append(run)
        order = list(engine.integrators.GENERAL) + list(REBOUND_METHODS)
        runs.sort(key=lambda r: (r["code"] != "engine",
                                 order.index(r["integrator"]) if r["code"] == "engine"
                                 else order.index(r["integrator"], len(engine.integrators.GENERAL)),
                                 r["steps"]))
        floor = ref["floor"] if metric(p) == "position" else 0.0
        section[p.key] = {
            "title": p.title, "notes": p.notes, "t_end": p.t_end, "length": p.length,
            "at_rest": bool(np.all(p.vel == 0.0)),
            "length_name": p.length_name, "metric": metric(p), "n": p.n, "dim": p.dim,
            "reference": {"description": ref["reference"], "checks": ref["checks"],
                          "floor": ref["floor"], "energy0": ref["energy0"]},
            "runs": runs, "cheapest": cheapest(runs, floor=floor),
        }
    return section
