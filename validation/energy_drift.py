"""Energy error against time over long runs, and its growth exponent.

Each run advances in chunks (``sim.step(n)`` for the fixed-step methods, ``integrate(t)`` for
the adaptive ones) and samples the relative energy error |E(t) - E0| / |E0| at log-spaced
times. The growth exponent is the least-squares slope of log(error envelope) against log(t)
over the last two decades of the run, where the envelope is the running maximum of the
sampled error (a bounded error that oscillates within each orbit then has slope ~0). A run
stops counting once its error passes 0.1 (the orbit is no longer the one it started on, e.g.
Euler's widening orbit); the fit window then ends there.

Classes: slope < 0.25 bounded; 0.25-0.75 a random walk if the error is at round-off level
(< 1e-11; Brouwer's law, t^1/2), otherwise sublinear growth; 0.75-1.25 linear drift; above
1.25 faster-than-linear growth; "too short to fit" when the error passes 0.1 before the fit
window spans a decade.
"""
import math

import numpy as np

import engine
from engine import SimulationError

from .jobs import Job
from .problems import kepler, make_sim, outer_solar_system
from .reference import RebRun

DESTROYED = 0.1
FIT_DECADES = 2.0


def _sample_counts(total, first, samples):
    counts = np.unique(np.round(np.logspace(math.log10(first), math.log10(total), samples)))
    return [int(c) for c in counts if c >= 1]


def run_engine_fixed(problem, integrator, dt, total_steps, samples, first_steps=1, setting="",
                     stop_above=None):
    """``stop_above``: stop once the error passes it (a destroyed orbit needs no more steps)."""
    sim = make_sim(problem, integrator, dt)
    e0 = sim.energy()
    t, err = [], []
    status = "ok"
    done = 0
    for n in _sample_counts(total_steps, first_steps, samples):
        try:
            sim.step(n - done)
        except SimulationError as exc:
            status = f"SimulationError at t = {exc.time:.6g}"
            break
        done = n
        t.append(sim.t)
        err.append(abs(sim.energy() - e0) / abs(e0))
        if stop_above is not None and err[-1] > stop_above:
            status = f"stopped at t = {sim.t:.4g}: error above {stop_above:g}"
            break
    return {"t": t, "err": err, "steps": sim.steps, "status": status, "setting": setting}


def run_engine_adaptive(problem, tolerance, t_end, t_first, samples, dt0, setting=""):
    sim = make_sim(problem, "rk45", dt0, tolerance=tolerance)
    e0 = sim.energy()
    t, err = [], []
    status = "ok"
    for tk in np.logspace(math.log10(t_first), math.log10(t_end), samples):
        try:
            sim.integrate(float(tk))
        except SimulationError as exc:
            status = f"SimulationError at t = {exc.time:.6g}"
            break
        t.append(sim.t)
        err.append(abs(sim.energy() - e0) / abs(e0))
    return {"t": t, "err": err, "steps": sim.steps, "status": status, "setting": setting}


def run_rebound(problem, integrator, t_end, t_first, samples, dt=None, total_steps=None,
                setting=""):
    run = RebRun(problem, integrator, dt=dt)
    e0 = run.energy()
    t, err = [], []
    if total_steps is not None:  # fixed step: whole steps, as the engine does
        done = 0
        for n in _sample_counts(total_steps, 1, samples):
            run.steps(n - done)
            done = n
            t.append(run.t)
            err.append(abs(run.energy() - e0) / abs(e0))
    else:
        for tk in np.logspace(math.log10(t_first), math.log10(t_end), samples):
            if tk <= run.t:  # an adaptive step already passed it (REBOUND would go back)
                continue
            run.integrate(float(tk), exact=False)
            t.append(run.t)
            err.append(abs(run.energy() - e0) / abs(e0))
    return {"t": t, "err": err, "steps": int(run.sim.steps_done), "status": "ok",
            "setting": setting, "rebound_warnings": run.warnings}


def drift_problems(level):
    return {"kepler": kepler(0.6), "solar": outer_solar_system(level.drift_solar_days)}


def jobs(level):
    out = []
    probs = drift_problems(level)
    # Kepler e = 0.6
    p = probs["kepler"]
    n_per = level.drift_steps_per_orbit
    total = int(level.drift_orbits * n_per)
    common = f"{n_per} steps/orbit"
    for name in engine.integrators.GENERAL:
        if name == "rk45":
            out.append(Job(("drift", "kepler", "engine", name, ""), "energy_drift:run_engine_adaptive",
                           dict(problem=p, tolerance=level.drift_tolerance,
                                t_end=level.drift_orbits * p.unit, t_first=0.01 * p.unit,
                                samples=level.drift_samples, dt0=p.unit / 100,
                                setting=f"tol {level.drift_tolerance:g}"),
                           cost=level.drift_orbits * 200 * 6))
            continue
        out.append(Job(("drift", "kepler", "engine", name, ""), "energy_drift:run_engine_fixed",
                       dict(problem=p, integrator=name, dt=p.unit / n_per, total_steps=total,
                            samples=level.drift_samples, first_steps=max(1, n_per // 100),
                            setting=common, stop_above=1.0 if name == "euler" else None),
                       cost=total * engine.integrators.FORCE_EVALUATIONS[name]
                       * (0.01 if name == "euler" else 1)))
        if name == "euler":  # and at a much smaller step, where its orbit survives longer
            ne = level.drift_euler_steps_per_orbit
            out.append(Job(("drift", "kepler", "engine", name, "fine"), "energy_drift:run_engine_fixed",
                           dict(problem=p, integrator=name, dt=p.unit / ne,
                                total_steps=int(level.drift_euler_orbits * ne),
                                samples=level.drift_samples, first_steps=max(1, ne // 100),
                                setting=f"{ne} steps/orbit", stop_above=1.0),
                           cost=level.drift_euler_orbits * ne))
    out.append(Job(("drift", "kepler", "rebound", "ias15", ""), "energy_drift:run_rebound",
                   dict(problem=p, integrator="ias15", t_end=level.drift_orbits * p.unit,
                        t_first=0.01 * p.unit, samples=level.drift_samples,
                        setting="epsilon 1e-9 (default)"),
                   cost=level.drift_orbits * 60 * 10))
    out.append(Job(("drift", "kepler", "rebound", "whfast", ""), "energy_drift:run_rebound",
                   dict(problem=p, integrator="whfast", t_end=level.drift_orbits * p.unit,
                        t_first=0.01 * p.unit, samples=level.drift_samples, dt=p.unit / n_per,
                        total_steps=total, setting=common), cost=total * 0.5))
    # outer solar system
    s = probs["solar"]
    dt = level.drift_solar_dt
    total = int(round(level.drift_solar_days / dt))
    common = f"dt = {dt:g} d"
    for name in engine.integrators.GENERAL:
        if name == "rk45":
            out.append(Job(("drift", "solar", "engine", name, ""), "energy_drift:run_engine_adaptive",
                           dict(problem=s, tolerance=level.drift_tolerance,
                                t_end=level.drift_solar_days, t_first=dt,
                                samples=level.drift_samples, dt0=dt,
                                setting=f"tol {level.drift_tolerance:g}"),
                           cost=total * 6 * 5))
        else:
            out.append(Job(("drift", "solar", "engine", name, ""), "energy_drift:run_engine_fixed",
                           dict(problem=s, integrator=name, dt=dt, total_steps=total,
                                samples=level.drift_samples, setting=common),
                           cost=total * engine.integrators.FORCE_EVALUATIONS[name] * 5))
    out.append(Job(("drift", "solar", "rebound", "ias15", ""), "energy_drift:run_rebound",
                   dict(problem=s, integrator="ias15", t_end=level.drift_solar_days, t_first=dt,
                        samples=level.drift_samples, setting="epsilon 1e-9 (default)"), cost=total))
    out.append(Job(("drift", "solar", "rebound", "whfast", ""), "energy_drift:run_rebound",
                   dict(problem=s, integrator="whfast", t_end=level.drift_solar_days, t_first=dt,
                        samples=level.drift_samples, dt=dt, total_steps=total, setting=common),
                   cost=total))
    return out


def growth_exponent(t, err):
    """(slope, fit window, envelope at the end of the window, destroyed_at) of a run."""
    t = np.asarray(t, dtype=float)
    err = np.asarray(err, dtype=float)
    if t.size == 0:
        return None, None, None, None
    env = np.maximum.accumulate(np.maximum(err, 1e-300))
    destroyed_at = None
    valid = env < DESTROYED
    if not valid.all():
        first_bad = int(np.argmin(valid))
        destroyed_at = float(t[first_bad])
        t, env = t[:first_bad], env[:first_bad]
    if t.size < 4:
        return None, None, float(env[-1]) if env.size else None, destroyed_at
    hi = t[-1]
    lo = hi / 10 ** FIT_DECADES
    window = t >= lo
    if window.sum() < 4:
        window = np.zeros_like(window)
        window[-4:] = True
    x = np.log10(t[window])
    y = np.log10(env[window])
    slope = float(np.polyfit(x, y, 1)[0])
    return slope, (float(t[window][0]), float(t[window][-1])), float(env[-1]), destroyed_at


def classify(slope, level_at_end, window=None):
    if slope is None or (window is not None and window[1] < 10.0 * window[0]):
        return "too short to fit"
    if slope < 0.25:
        return "bounded"
    if slope < 0.75:
        return "random walk (round-off)" if level_at_end < 1e-11 else "sublinear growth"
    if slope < 1.25:
        return "linear drift"
    return "faster than linear"


def assemble(level, results):
    probs = drift_problems(level)
    section = {}
    for pkey, problem in probs.items():
        runs = []
        for key, res in results.items():
            if key[0] != "drift" or key[1] != pkey:
                continue
            _, _, code, name, _variant = key
            slope, window, env_end, destroyed = growth_exponent(res["t"], res["err"])
            runs.append({
                "method": f"{code}:{name}", "code": code, "integrator": name,
                "setting": res["setting"], "t": res["t"], "err": res["err"],
                "steps": res["steps"], "status": res["status"],
                "final_error": res["err"][-1] if res["err"] else None,
                "max_error": max(res["err"]) if res["err"] else None,
                "growth_exponent": slope, "fit_window": window, "envelope_at_fit_end": env_end,
                "destroyed_at": destroyed, "class": classify(slope, env_end or 0.0, window),
            })
        order = list(engine.integrators.GENERAL) + ["ias15", "whfast"]
        runs.sort(key=lambda r: (r["code"] != "engine", order.index(r["integrator"]), r["steps"]))
        section[pkey] = {"title": problem.title, "time_unit": problem.unit,
                         "time_unit_name": problem.unit_name, "runs": runs}
    return section
