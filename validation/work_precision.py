"""Work-precision sweeps: error against cost for every method on every problem.

For each problem, every fixed-step engine method runs a sweep of step counts N (dt =
t_end / N, ``sim.step(N)``), ``rk45`` a sweep of tolerances and ``ias15`` a sweep of epsilon
(``sim.integrate(t_end)``); on the gravity problems REBOUND's ``ias15`` a sweep of epsilon and
its ``whfast`` (with correctors 0, 11, 17), ``leapfrog`` and ``saba`` (SABA(10,6,4), SABAC4)
the same step counts. The methods are listed in ``ENGINE_METHODS`` and ``REBOUND_METHODS``
(``Method``: a name in the report, the integrator and its options). The engine's ``whfast``
and ``saba`` need a dominant mass or a ``PointMass``: on other problems the engine refuses
them (``ValueError``) and the sweep records the skip and its reason, as it does for REBOUND's
corrected WHFast and SABAC4 there. REBOUND's WHFast and SABA run with ``safe_mode = 0`` and
one ``synchronize()`` at the end of the run (REBOUND's fastest use of them; the engine, too,
applies a corrector and synchronises once per ``step`` call). Each point records

- the error at t_end against the problem's reference (max_i |r_i - r_i^ref| / L; for the
  Pythagorean problem to t = 70 the relative energy error against E0 = -769/60, see
  ``metric``),
- the wall time of ``sim.step``/``sim.integrate`` alone (``time.perf_counter``; numba
  compilation excluded by a warm-up run of each integrator first; a run shorter than
  ``level.wp_repeat_below`` seconds is repeated up to ``level.wp_repeats`` times and the
  median kept),
- the force evaluations: the engine's own count ``sim.force_evaluations`` where the
  simulation has one, otherwise ``engine_force_evaluations`` (the per-step table, and IAS15's
  counter read through ``ias15_force_evaluations``); REBOUND's counted by an
  ``additional_forces`` callback in separate, untimed runs.

A sweep goes from coarse to fine and stops once the error is below the reference's own
uncertainty (nothing more can be measured) or has stopped falling below 1e-8 (round-off,
``converged``), or before a run whose force evaluations times
interacting pairs would pass ``level.wp_work_cap`` (a deterministic cost cap, so the set of
runs does not depend on the machine's speed). The adaptive IAS15 runs (both codes) are first
counted in an untimed run that stops at the cap.

``versus`` picks, per problem and error level, the fastest engine run and the fastest REBOUND
run that reach the level; ``head_to_head`` times those two again side by side (alternating
repetitions, the median of the per-repetition ratios), which is the ratio the report shows.
"""
import math
import statistics
import time
from dataclasses import dataclass

import numpy as np

import engine
from engine import SimulationError

from .jobs import Job
from .problems import make_sim, work_precision_set
from .reference import RebRun, position_error, reference_states, reference_uncertainty

#: error levels of the "cheapest method" and "engine best / REBOUND best" tables
ERROR_LEVELS = (1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12)


@dataclass(frozen=True)
class Method:
    """One line of the work-precision plots: ``code`` ("engine" or "rebound"), the ``name``
    shown in the report, the ``integrator`` and its ``options`` (engine: ``Simulation``
    arguments; REBOUND: integrator attributes), the ``sweep`` ("steps", "tolerance" or
    "epsilon"), and whether it needs a dominant mass."""

    code: str
    name: str
    integrator: str
    options: tuple = ()
    sweep: str = "steps"
    dominant_mass: bool = False
    description: str = ""

    @property
    def key(self):
        return f"{self.code}:{self.name}"


def _general(name):
    return Method("engine", name, name, sweep="tolerance" if name == "rk45" else "steps",
                  description=name)


ENGINE_METHODS = tuple(_general(name) for name in engine.integrators.GENERAL) + (
    Method("engine", "whfast", "whfast", (("corrector", 0),), dominant_mass=True,
           description="whfast, no corrector"),
    Method("engine", "whfast_c11", "whfast", (("corrector", 11),), dominant_mass=True,
           description="whfast, corrector 11"),
    Method("engine", "whfast_c17", "whfast", (("corrector", 17),), dominant_mass=True,
           description="whfast, corrector 17"),
    Method("engine", "saba", "saba", (("saba", "SABA(10,6,4)"),), dominant_mass=True,
           description="saba SABA(10,6,4)"),
    Method("engine", "sabac4", "saba", (("saba", "SABAC4"),), dominant_mass=True,
           description="saba SABAC4 (lazy corrector)"),
    Method("engine", "ias15", "ias15", sweep="epsilon", description="ias15 (epsilon sweep)"),
    Method("engine", "janus", "janus", (("janus_order", 6),), description="janus, order 6"),
)

#: REBOUND's side. The first four are the report's original REBOUND methods (WHFast and
#: SABA now in safe_mode 0); the corrected ones only run where the engine finds a dominant mass
REBOUND_METHOD_LIST = (
    Method("rebound", "ias15", "ias15", sweep="epsilon", description="IAS15 (epsilon sweep)"),
    Method("rebound", "whfast", "whfast", (("safe_mode", 0),),
           description="WHFast, no corrector, safe_mode 0"),
    Method("rebound", "leapfrog", "leapfrog", description="leapfrog"),
    Method("rebound", "saba", "saba", (("type", "10_6_4"), ("safe_mode", 0)),
           description="SABA(10,6,4), safe_mode 0"),
    Method("rebound", "whfast_c11", "whfast", (("corrector", 11), ("safe_mode", 0)),
           dominant_mass=True, description="WHFast, corrector 11, safe_mode 0"),
    Method("rebound", "whfast_c17", "whfast", (("corrector", 17), ("safe_mode", 0)),
           dominant_mass=True, description="WHFast, corrector 17, safe_mode 0"),
    Method("rebound", "sabac4", "saba", (("type", "CL_4"), ("safe_mode", 0)),
           dominant_mass=True, description="SABAC4 (lazy corrector, REBOUND's CL_4), "
                                           "safe_mode 0"),
)
#: the REBOUND methods' names (kept: the report's original four come first)
REBOUND_METHODS = tuple(m.name for m in REBOUND_METHOD_LIST)

METHODS = {m.key: m for m in ENGINE_METHODS + REBOUND_METHOD_LIST}
#: the order of the methods in tables and plots
METHOD_ORDER = tuple(METHODS)


def metric(problem):
    """``"position"`` or ``"energy"``: a problem may say (``extra["metric"]``); the Pythagorean
    problem to t = 70 is measured by its energy error."""
    if "metric" in problem.extra:
        return problem.extra["metric"]
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
    """Interacting pairs per force evaluation: each particle with the centre when a fixed
    attractor is the only force (1 for a single particle), otherwise every pair."""
    if [kind for kind, _ in problem.forces] == ["point_mass"]:
        return max(1, problem.n)
    return max(1, problem.n * (problem.n - 1) // 2)


def too_much_work(problem, evaluations, level):
    """The sweep's deterministic cost cap: force evaluations times interacting pairs."""
    return evaluations * pairs(problem) > level.wp_work_cap


# -- force evaluations of the engine ---------------------------------------------------------------

def ias15_force_evaluations(sim):
    """The engine IAS15's force evaluations so far, read from its predictor memory.

    ``sim._ias15_memory`` is private: this helper is the only place that reads it, until the
    simulation counts its force evaluations itself (``sim.force_evaluations``)."""
    memory = getattr(sim, "_ias15_memory", None)
    if memory is None:
        return 0
    return engine.integrators.ias15.statistics(memory)["evaluations"]


def evaluations_per_step(method):
    """(per step, per ``step`` call) force evaluations of a fixed-step engine method: the
    table ``engine.integrators.FORCE_EVALUATIONS``, the SABA method's kicks (SABACn: n + 2),
    the janus order's stages, and whfast's corrector (two kicks per Z operator, applied and
    undone once per call)."""
    from engine.integrators import janus, wisdom_holman

    opts = dict(method.options)
    if method.integrator == "whfast":
        per_step = 2 if opts.get("kernel") == "lazy" else 1
        return per_step, 4 * len(wisdom_holman.corrector_table(opts.get("corrector", 0)))
    if method.integrator == "saba":
        _, kicks, cc = wisdom_holman.saba_scheme(opts.get("saba", wisdom_holman.DEFAULT_SABA))
        return int(np.count_nonzero(kicks)) + (2 if cc else 0), 0
    if method.integrator == "janus":
        return janus.FORCE_EVALUATIONS[opts.get("janus_order", 6)], 0
    return engine.integrators.FORCE_EVALUATIONS[method.integrator], 0


def engine_force_evaluations(sim, method):
    """Force evaluations of a finished engine run: ``sim.force_evaluations`` when the
    simulation counts them; otherwise IAS15's counter, 6 per accepted rk45 step (rejected
    attempts not seen) or the per-step figures of ``evaluations_per_step``."""
    counted = getattr(sim, "force_evaluations", None)
    if counted is not None:
        return int(counted)
    if method.integrator == "ias15":
        return ias15_force_evaluations(sim)
    if method.integrator == "rk45":
        return 6 * sim.steps
    per_step, per_call = evaluations_per_step(method)
    return per_step * sim.steps + (per_call if sim.steps else 0)


def dominant_mass_refusal(problem):
    """None if the engine's ``whfast`` takes ``problem``, else its reason (the ValueError)."""
    sim = make_sim(problem, "whfast", problem.t_end / 1000)
    try:
        sim.step(1)
    except ValueError as exc:
        return str(exc)
    return None


# -- references (untimed) --------------------------------------------------------------------------

def reference_job(problem):
    pos, vel = reference_states(problem, [problem.t_end])[0]
    sim = make_sim(problem, "leapfrog", 1.0)
    e0 = sim.energy()
    out = {"pos": pos, "vel": vel, "energy0": e0}
    out.update(reference_uncertainty(problem, problem.t_end))
    if "energy" in problem.extra:  # known exactly (the Pythagorean problem)
        out["energy0_exact"] = problem.extra["energy"]
    return out


def reference_jobs(level):
    return [Job(("wp_ref", p.key), "work_precision:reference_job", dict(problem=p), cost=50)
            for p in work_precision_set(level)]


# -- one run of each code (set up untimed, then the timed call) ------------------------------------

def engine_run(problem, method, setting):
    """``(sim, call)``: an engine simulation of ``problem`` for ``method`` at ``setting`` (step
    count, tolerance or epsilon), and the call to time."""
    opts = dict(method.options)
    if method.sweep in ("tolerance", "epsilon"):
        sim = make_sim(problem, method.integrator, problem.t_end / 1000, tolerance=setting,
                       options=opts)
        return sim, lambda: sim.integrate(problem.t_end)
    sim = make_sim(problem, method.integrator, problem.t_end / setting, options=opts)
    return sim, lambda: sim.step(setting)


def rebound_run(problem, method, setting, **counting):
    """``(run, call)``: the same for REBOUND (``counting``: ``RebRun``'s counting options)."""
    opts = dict(method.options)
    if method.sweep == "epsilon":
        run = RebRun(problem, method.integrator, epsilon=setting, options=opts, **counting)
        return run, lambda: run.integrate(problem.t_end)
    run = RebRun(problem, method.integrator, dt=problem.t_end / setting, options=opts,
                 **counting)
    return run, lambda: run.steps(setting)


def _timed_engine(problem, method, setting):
    sim, call = engine_run(problem, method, setting)
    status = "ok"
    t0 = time.perf_counter()
    try:
        call()
    except SimulationError as exc:
        status = f"SimulationError at t = {exc.time:.6g}"
    seconds = time.perf_counter() - t0
    return {"sim": sim, "status": status}, seconds


def _timed_rebound(problem, method, setting):
    run, call = rebound_run(problem, method, setting)
    status = "ok"
    t0 = time.perf_counter()
    try:
        call()
    except Exception as exc:  # REBOUND's own exception classes
        status = f"REBOUND error: {exc}"
    seconds = time.perf_counter() - t0
    return {"run": run, "status": status}, seconds


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


#: below this error a sweep whose error stops falling has reached round-off
ROUND_OFF_PLATEAU = 1e-8


def converged(points, floor):
    """Whether a sweep can stop after its last point: its error is below the reference's
    uncertainty (or 1e-14), or the last two errors are below ``ROUND_OFF_PLATEAU`` and neither
    improved on the one before it by a factor 1.4 (round-off: a method exact on the problem,
    e.g. ``whfast`` on Kepler orbits, would otherwise run to the cost cap with errors that
    only wander; a converging method gains at least that much from one step count to the
    next, and a single lucky error does not stop it)."""
    err = [p.get("error") for p in points]
    if err[-1] is None:
        return False
    if err[-1] < max(floor, 1e-14):
        return True
    if len(err) < 3 or any(e is None for e in err[-3:]):
        return False
    a, b, c = err[-3:]
    return b < ROUND_OFF_PLATEAU and c < ROUND_OFF_PLATEAU and b >= a / 1.4 and c >= b / 1.4


def _count_engine_ias15(problem, method, setting, cap):
    """Untimed: the engine IAS15's force evaluations to t_end, in chunks of 64 steps, stopping
    once past ``cap``. Returns (evaluations, stopped, t, steps)."""
    sim, _ = engine_run(problem, method, setting)
    while sim.t < problem.t_end:
        try:
            sim.step(64)
        except SimulationError:
            break  # the timed run meets it too and records it
        evaluations = engine_force_evaluations(sim, method)
        if evaluations > cap:
            return evaluations, True, sim.t, sim.steps
    return engine_force_evaluations(sim, method), False, sim.t, sim.steps


def _settings(method, problem, level):
    if method.sweep == "tolerance":
        return level.wp_tolerances
    if method.sweep == "epsilon":
        return level.wp_ias15_epsilons
    return step_counts(level, problem)


def sweep_engine(problem, method, ref, level):
    """Time the sweep of one engine method on one problem (runs in the main process).

    Returns ``{"points": [...], "skipped": None}``, or no points and the reason when the
    engine refuses the method on this problem (``whfast``/``saba`` without a dominant mass).
    """
    method = METHODS[f"engine:{method}"]
    warm = make_sim(problem, method.integrator, problem.t_end / 1000,
                    options=dict(method.options))
    try:
        warm.step(1)  # compile / load the cached machine code before timing
    except ValueError as exc:
        if not method.dominant_mass:
            raise
        return {"points": [], "skipped": str(exc)}
    floor = stop_floor(problem, ref)
    points = []
    fixed = method.sweep == "steps"
    per_step, per_call = evaluations_per_step(method) if fixed else (None, None)
    for setting in _settings(method, problem, level):
        if fixed and too_much_work(problem, per_step * setting + per_call, level):
            break
        if method.sweep == "epsilon":
            cap = level.wp_work_cap / pairs(problem)
            evaluations, stopped, t_stop, steps = _count_engine_ias15(problem, method, setting,
                                                                      cap)
            if stopped:
                points.append({"setting": setting, "steps": int(steps),
                               "evaluations": int(evaluations), "time_s": None,
                               "status": f"stopped at t = {t_stop:.6g}: over the cost cap of "
                                         f"{cap:.3g} force evaluations"})
                continue
        res, seconds, repeats = _median_time(
            lambda: _timed_engine(problem, method, setting), level)
        sim = res["sim"]
        point = {"setting": setting, "steps": sim.steps,
                 "evaluations": engine_force_evaluations(sim, method),
                 "time_s": seconds, "timing_repeats": repeats, "status": res["status"]}
        if res["status"] == "ok":
            point.update(_errors(problem, ref, sim.pos, sim.energy()))
        points.append(point)
        if res["status"] == "ok" and converged(points, floor):
            break
        if too_much_work(problem, point["evaluations"], level):
            break
    return {"points": points, "skipped": None}


def _rebound_evaluations(problem, method, dt):
    """REBOUND's force evaluations of a fixed-step run as (per run, per step), counted with a
    callback in two untimed runs of 10 and 20 steps (a corrector or a synchronisation costs
    per run, not per step)."""
    counts = []
    for n in (10, 20):
        counter = RebRun(problem, method.integrator, dt=dt, count_evaluations=True,
                         options=dict(method.options))
        counter.steps(n)
        counts.append(counter.evaluations)
    per_step = (counts[1] - counts[0]) / 10
    return max(0.0, counts[0] - 10 * per_step), per_step


def sweep_rebound(problem, method, ref, level):
    """The same for one REBOUND method (its corrected WHFast and SABAC4 are skipped where the
    engine finds no dominant mass)."""
    method = METHODS[f"rebound:{method}"]
    if method.dominant_mass:
        refusal = dominant_mass_refusal(problem)
        if refusal:
            return {"points": [], "skipped": "no dominant mass: not run where the engine "
                                             "refuses whfast and saba"}
    floor = stop_floor(problem, ref)
    points = []
    if method.sweep == "steps":
        per_run, per_step = _rebound_evaluations(problem, method, problem.t_end / 1000)
    for setting in _settings(method, problem, level):
        if method.sweep == "steps" and too_much_work(problem, per_run + per_step * setting,
                                                     level):
            break
        if method.sweep == "epsilon":
            # count first (untimed, with a cost cap): an adaptive run can need unbounded work
            cap = level.wp_work_cap / pairs(problem)
            counter, call = rebound_run(problem, method, setting, count_evaluations=True,
                                        max_evaluations=cap)
            call()
            evaluations = counter.evaluations
            if counter.stopped:
                points.append({"setting": setting, "steps": int(counter.sim.steps_done),
                               "evaluations": evaluations, "time_s": None,
                               "status": f"stopped at t = {counter.t:.6g}: over the cost cap of "
                                         f"{cap:.3g} force evaluations"})
                continue
        res, seconds, repeats = _median_time(
            lambda: _timed_rebound(problem, method, setting), level)
        run = res["run"]
        pos, _ = run.state()
        status = res["status"]
        if status == "ok" and not np.all(np.isfinite(pos)):
            status = "non-finite state"
        if method.sweep == "steps":
            evaluations = int(round(per_run + per_step * run.sim.steps_done))
        point = {"setting": setting, "steps": int(run.sim.steps_done), "evaluations": evaluations,
                 "time_s": seconds, "timing_repeats": repeats, "status": status}
        if run.warnings:
            point["rebound_warnings"] = run.warnings
        if status == "ok":
            point.update(_errors(problem, ref, pos, run.energy()))
        points.append(point)
        if status == "ok" and converged(points, floor):
            break
        if too_much_work(problem, evaluations, level):
            break
    return {"points": points, "skipped": None}


def timed_jobs(level):
    out = []
    for p in work_precision_set(level):
        for m in ENGINE_METHODS:
            out.append(Job(("wp", p.key, "engine", m.name), "work_precision:sweep_engine",
                           dict(problem=p, method=m.name)))
        if p.rebound:
            for m in REBOUND_METHOD_LIST:
                out.append(Job(("wp", p.key, "rebound", m.name), "work_precision:sweep_rebound",
                               dict(problem=p, method=m.name)))
    return out


# -- summary ---------------------------------------------------------------------------------------

def _summary(run):
    if run is None:
        return None
    return {"method": run["method"], "setting": run["setting_label"],
            "setting_value": run["setting"], "steps": run["steps"], "time_s": run["time_s"],
            "evaluations": run["evaluations"], "error": run["error"]}


def _reaching(runs, level):
    """The finished runs whose error is at most ``level``."""
    return [r for r in runs if r.get("error") is not None and r["error"] <= level
            and r.get("time_s") is not None]


def cheapest(runs, levels=ERROR_LEVELS, floor=0.0):
    """For each error level: the fastest run, the one with fewest force evaluations, and the
    fastest engine run, among runs whose error is at most the level."""
    table = []
    for lev in levels:
        ok = _reaching(runs, lev)
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


def versus(runs, levels=ERROR_LEVELS, floor=0.0):
    """"Engine best / REBOUND best": for each error level the fastest engine run and the
    fastest REBOUND run whose error is at most the level, and the ratio of their wall times
    (engine over REBOUND: below 1 the engine is faster). ``None`` where a side has no run that
    reaches the level. ``head_to_head`` later replaces the ratio by a side-by-side timing."""
    table = []
    for lev in levels:
        ok = _reaching(runs, lev)
        best = {}
        for code in ("engine", "rebound"):
            pool = [r for r in ok if r["code"] == code]
            best[code] = min(pool, key=lambda r: r["time_s"]) if pool else None
        ratio = None
        if best["engine"] is not None and best["rebound"] is not None:
            ratio = best["engine"]["time_s"] / best["rebound"]["time_s"]
        table.append({"level": lev, "below_reference_floor": lev < floor,
                      "engine": _summary(best["engine"]), "rebound": _summary(best["rebound"]),
                      "ratio": ratio, "sweep_ratio": ratio, "side_by_side": None})
    return table


def _one_step_call(problem, method, setting, code):
    """Wall time of a call that takes a single step (the fixed cost of a call, set-up
    excluded), fresh simulation each time, median of 3."""
    times = []
    for _ in range(3):
        if code == "engine":
            sim, _ = engine_run(problem, method, setting)
            t0 = time.perf_counter()
            sim.step(1)
        else:
            run, _ = rebound_run(problem, method, setting)
            t0 = time.perf_counter()
            run.steps(1)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def time_pair(problem, engine_best, rebound_best, level):
    """Time the engine's and REBOUND's runs again back to back, alternating, ``repeats`` times
    (as many as ``level.wp_pair_seconds`` allows, at most 4 ``level.wp_repeats``, at least
    one); the median times and the median of the per-repetition ratios engine / REBOUND, and
    each code's time for a call of one step (what a call costs besides its steps)."""
    e_method = METHODS[engine_best["method"]]
    r_method = METHODS[rebound_best["method"]]
    both = engine_best["time_s"] + rebound_best["time_s"]
    repeats = max(1, min(4 * level.wp_repeats, int(level.wp_pair_seconds / max(both, 1e-9))))
    t_engine, t_rebound, ratios = [], [], []
    for _ in range(repeats):
        res, a = _timed_engine(problem, e_method, engine_best["setting_value"])
        other, b = _timed_rebound(problem, r_method, rebound_best["setting_value"])
        if res["status"] != "ok" or other["status"] != "ok":
            return {"status": f"engine: {res['status']}; REBOUND: {other['status']}"}
        t_engine.append(a)
        t_rebound.append(b)
        ratios.append(a / b)
    return {"status": "ok", "engine_time_s": statistics.median(t_engine),
            "rebound_time_s": statistics.median(t_rebound), "ratio": statistics.median(ratios),
            "repeats": repeats,
            "engine_one_step_call_s": _one_step_call(problem, e_method,
                                                     engine_best["setting_value"], "engine"),
            "rebound_one_step_call_s": _one_step_call(problem, r_method,
                                                      rebound_best["setting_value"], "rebound")}


def head_to_head(level, section):
    """Re-time each "engine best / REBOUND best" pair side by side (``time_pair``; a pair shared
    by several error levels is timed once) and make that the table's ratio."""
    problems = {p.key: p for p in work_precision_set(level)}
    done = {}
    for key, entry in section.items():
        for row in entry.get("versus", []):
            e, r = row["engine"], row["rebound"]
            if e is None or r is None:
                continue
            pair = (key, e["method"], e["setting_value"], r["method"], r["setting_value"])
            if pair not in done:
                done[pair] = time_pair(problems[key], e, r, level)
            row["side_by_side"] = done[pair]
            if done[pair]["status"] == "ok":
                row["ratio"] = done[pair]["ratio"]
    return section


def setting_label(method, setting):
    if method.sweep == "tolerance":
        return f"tol {setting:g}"
    if method.sweep == "epsilon":
        return f"eps {setting:g}"
    return f"N = {setting}"


def assemble_problem(problem, ref, sweeps):
    """The section entry of one problem from its reference and its sweeps' results
    (``{("wp", key, code, name): result}``; other keys are ignored)."""
    p = problem
    runs = []
    skipped = []
    for key, result in sweeps.items():
        if key[0] != "wp" or key[1] != p.key:
            continue
        _, _, code, name = key
        method = METHODS[f"{code}:{name}"]
        if isinstance(result, list):  # a bare list of points
            result = {"points": result, "skipped": None}
        if result["skipped"]:
            skipped.append({"method": method.key, "reason": result["skipped"]})
        for pt in result["points"]:
            run = dict(pt)
            run.update({"method": method.key, "code": code, "integrator": name,
                        "description": method.description,
                        "setting_label": setting_label(method, pt["setting"])})
            runs.append(run)
    runs.sort(key=lambda r: (METHOD_ORDER.index(r["method"]), r["steps"]))
    skipped.sort(key=lambda s: METHOD_ORDER.index(s["method"]))
    floor = ref["floor"] if metric(p) == "position" else 0.0
    return {
        "title": p.title, "notes": p.notes, "t_end": p.t_end, "length": p.length,
        "at_rest": bool(np.all(p.vel == 0.0)),
        "length_name": p.length_name, "metric": metric(p), "n": p.n, "dim": p.dim,
        "rebound": p.rebound,
        "reference": {"description": ref["reference"], "checks": ref["checks"],
                      "floor": ref["floor"], "energy0": ref["energy0"]},
        "runs": runs, "skipped": skipped, "cheapest": cheapest(runs, floor=floor),
        "versus": versus(runs, floor=floor) if p.rebound else [],
    }


def assemble(level, references, sweeps):
    return {p.key: assemble_problem(p, references[("wp_ref", p.key)], sweeps)
            for p in work_precision_set(level)}
