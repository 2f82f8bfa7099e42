"""Two-body orbits: every engine integrator against the closed form and REBOUND IAS15.

For e = 0, 0.5, 0.9, 0.99 (a = 1, from pericentre) and a hyperbolic flyby, each method runs
to 1, 10, 100 and 1000 time units P = 2 pi (the orbital period of the bound orbits) with
``integrate(k P)``, landing exactly on each checkpoint. The relative position and velocity
errors |r - r_ref| / max(|r_ref|, |a|) and |v - v_ref| / max(|v_ref|, sqrt(mu/|a|)) are taken
against
``engine.analytic.kepler`` and against REBOUND IAS15 (epsilon 1e-11); REBOUND's own
``whfast`` and ``leapfrog`` run the same problems with the same steps.
"""
import numpy as np

import engine
from engine import SimulationError

from .jobs import Job
from .problems import make_sim, two_body_set
from .reference import IAS15_REFERENCE_EPSILON, RebRun, kepler_states

FIXED = tuple(name for name in engine.integrators.GENERAL if name != "rk45")
REBOUND_FIXED = ("whfast", "leapfrog")


def run_engine(problem, integrator, times, dt, tolerance=1e-9):
    sim = make_sim(problem, integrator, dt, tolerance=tolerance)
    states, status = [], "ok"
    for t in times:
        try:
            sim.integrate(float(t))
        except SimulationError as err:
            status = f"SimulationError at t = {err.time:.6g}"
            break
        states.append((sim.pos.copy(), sim.vel.copy()))
    return {"states": states, "steps": sim.steps, "status": status}


def run_rebound(problem, integrator, times, dt=None, epsilon=None):
    run = RebRun(problem, integrator, dt=dt, epsilon=epsilon)
    states, status = [], "ok"
    for t in times:
        try:
            run.integrate(float(t))
        except Exception as err:  # REBOUND raises its own exception classes
            status = f"REBOUND error: {err}"
            break
        state = run.state()
        if not (np.all(np.isfinite(state[0])) and np.all(np.isfinite(state[1]))):
            status = f"non-finite state at t = {run.t:.6g}"
            break
        states.append(state)
    return {"states": states, "steps": int(run.sim.steps_done), "status": status,
            "rebound_warnings": run.warnings}


def jobs(level):
    out = []
    for problem in two_body_set():
        times = [k * problem.unit for k in level.tb_orbits]
        top = level.tb_orbits[-1]
        for n in level.tb_steps_per_orbit:
            dt = problem.unit / n
            for name in FIXED:
                out.append(Job(("two_body", problem.key, "engine", name, n), "two_body:run_engine",
                               dict(problem=problem, integrator=name, times=times, dt=dt),
                               cost=n * top * engine.integrators.FORCE_EVALUATIONS[name]))
            for name in REBOUND_FIXED:
                out.append(Job(("two_body", problem.key, "rebound", name, n), "two_body:run_rebound",
                               dict(problem=problem, integrator=name, times=times, dt=dt),
                               cost=n * top * 0.3))
        for tol in level.tb_tolerances:
            out.append(Job(("two_body", problem.key, "engine", "rk45", tol), "two_body:run_engine",
                           dict(problem=problem, integrator="rk45", times=times,
                                dt=problem.unit / 100, tolerance=tol), cost=top * 3000))
        out.append(Job(("two_body", problem.key, "rebound", "ias15", "ref"), "two_body:run_rebound",
                       dict(problem=problem, integrator="ias15", times=times,
                            epsilon=IAS15_REFERENCE_EPSILON), cost=top * 500))
    return out


def _rel(a, b, floor):
    """|a - b| / max(|b|, floor): relative, but never relative to less than the orbit's scale
    (at the pericentre of e = 0.99, |r| = 0.01 a would make a phase error look 100 times
    larger)."""
    return float(np.linalg.norm(a - b) / max(np.linalg.norm(b), floor))


def scales(problem):
    """(length, speed) floors of the relative errors: |a| and sqrt(mu / |a|)."""
    a = abs(problem.extra.get("a", 1.0))
    mu = problem.extra.get("mu", 1.0)
    return a, (mu / a) ** 0.5


def assemble(level, results):
    """Errors of every run against both references."""
    section = {}
    for problem in two_body_set():
        times = [k * problem.unit for k in level.tb_orbits]
        exact = kepler_states(problem, times)
        ias = results[("two_body", problem.key, "rebound", "ias15", "ref")]["states"]
        ls, vs = scales(problem)
        entry = {
            "title": problem.title, "e": problem.extra["e"], "notes": problem.notes,
            "checkpoints": list(level.tb_orbits), "time_unit": problem.unit,
            "ias15_vs_kepler": {
                "pos": [_rel(s[0][0], r[0][0], ls) for s, r in zip(ias, exact)],
                "vel": [_rel(s[1][0], r[1][0], vs) for s, r in zip(ias, exact)],
            },
            "runs": [],
        }
        for key, res in sorted(results.items(), key=lambda kv: str(kv[0])):
            if key[0] != "two_body" or key[1] != problem.key or key[4] == "ref":
                continue
            _, _, code, name, setting = key
            run = {"method": f"{code}:{name}", "code": code, "integrator": name,
                   "steps": res["steps"], "status": res["status"]}
            if res.get("rebound_warnings"):
                run["rebound_warnings"] = res["rebound_warnings"]
            if name == "rk45":
                run["tolerance"] = setting
                run["setting"] = f"tol {setting:g}"
            else:
                run["steps_per_orbit"] = setting
                run["setting"] = f"{setting} steps/P"
            for ref_name, ref in (("kepler", exact), ("ias15", ias)):
                pos, vel = [], []
                for k in range(len(times)):
                    if k < len(res["states"]):
                        pos.append(_rel(res["states"][k][0][0], ref[k][0][0], ls))
                        vel.append(_rel(res["states"][k][1][0], ref[k][1][0], vs))
                    else:
                        pos.append(None)
                        vel.append(None)
                run[f"pos_err_{ref_name}"] = pos
                run[f"vel_err_{ref_name}"] = vel
            entry["runs"].append(run)
        entry["runs"].sort(key=_run_order)
        # how far apart the two references put the errors
        diffs = [abs(a - b) for r in entry["runs"]
                 for a, b in zip(r["pos_err_kepler"], r["pos_err_ias15"])
                 if a is not None and b is not None]
        entry["max_abs_difference_kepler_vs_ias15_errors"] = max(diffs) if diffs else None
        section[problem.key] = entry
    return section


def _run_order(run):
    order = list(engine.integrators.GENERAL) + ["whfast", "leapfrog"]
    code_rank = 0 if run["code"] == "engine" else 1
    return (code_rank, order.index(run["integrator"]) if run["code"] == "engine"
            else order.index(run["integrator"], len(engine.integrators.GENERAL)),
            run.get("steps_per_orbit", 0), -(run.get("tolerance") or 0))
