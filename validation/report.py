"""``python -m validation report --out DIR [--quick]``: run every comparison, write the report.

Writes ``DIR/report.md`` (tables, embedded plots, findings), the PNG plots and
``DIR/results.json`` (every figure in the report; deterministic except the keys named
``time_s``, ``wall_s``, the wall-time-based "fastest" entries, and the tree section's times
and speed-ups: its keys ending in ``_s``, ``speedup`` and ``repeats``).

The untimed work (errors, energies, stability) runs on ``--workers`` processes; the timed
work-precision sweeps then run one at a time in this process, and last the Barnes-Hut tree
section (``tree_bench``: errors and times of the engine's tree, pytreegrav's and REBOUND's).
"""
import argparse
import json
import math
import os
import platform
import sys
import time

import numpy as np

import engine
from engine.atomic import OutputPathError, atomic_write, check_output_dir, check_output_path

from . import contact, energy_drift, hard_cases, plots, tree_bench, two_body, work_precision
from .jobs import Job, run_jobs
from .problems import kepler, make_sim
from .reference import rebound_version
from .settings import LEVELS

SECTIONS = ("crosscheck", "two_body", "energy_drift", "work_precision", "hard_cases", "tree",
            "contact")


# -- running ---------------------------------------------------------------------------------------

def warm_up():
    """Compile (or load from numba's on-disk cache) everything the runs call, in this process,
    before the workers start: the workers then only read the cache, never write it at the same
    time (numba's cache files are not safe against two processes compiling into them at once).
    """
    p = kepler(0.5)
    for name in engine.integrators.GENERAL:
        sim = make_sim(p, name, 0.01)
        sim.step(2)
        sim.integrate(0.05)
    sim.energy()
    sim.momentum()
    sim.angular_momentum()
    sim.center_of_mass()
    engine.analytic.kepler(p.pos[0], p.vel[0], 1.0, 1.0)
    engine.analytic.kepler(p.pos[0], p.vel[0], 1.0, np.array([1.0, 2.0]))


def collect(level, workers=2, progress=True, sections=SECTIONS, scheduler=None):
    """Run the report's work; the untimed runs on ``workers`` processes, or on the Dask
    cluster at ``scheduler`` (``engine.cluster.scheduler_address``: an address, ``"local"``,
    or the ``DASK_SCHEDULER_ADDRESS`` variable); the timed sweeps always here, one at a time."""
    from engine.cluster import scheduler_address

    scheduler = scheduler_address(scheduler)
    t_start = time.perf_counter()
    warm_up()
    jobs = []
    if "crosscheck" in sections:
        jobs.append(Job(("crosscheck",), "crosscheck:run", dict(orbits=level.cross_orbits),
                        cost=level.cross_orbits * 2000))
    if "two_body" in sections:
        jobs += two_body.jobs(level)
    if "energy_drift" in sections:
        jobs += energy_drift.jobs(level)
    if "hard_cases" in sections:
        jobs += hard_cases.jobs(level)
    if "work_precision" in sections:
        jobs += work_precision.reference_jobs(level)
    if "contact" in sections:
        jobs += contact_jobs(level)
    t_a = time.perf_counter()
    results, _ = run_jobs(jobs, workers=workers, desc="untimed runs", disable=not progress,
                          scheduler=scheduler)
    phase_a = time.perf_counter() - t_a

    out = {"meta": meta(level, workers, scheduler)}
    if "crosscheck" in sections:
        out["crosscheck"] = results[("crosscheck",)]
    if "two_body" in sections:
        out["two_body"] = two_body.assemble(level, results)
    if "energy_drift" in sections:
        out["energy_drift"] = energy_drift.assemble(level, results)
    phase_b = 0.0
    if "work_precision" in sections:
        t_b = time.perf_counter()
        timed = work_precision.timed_jobs(level)
        for job in timed:
            job.kwargs.update(ref=results[("wp_ref", job.key[1])], level=level)
        sweep_results, _ = run_jobs(timed, workers=1, desc="timed sweeps", disable=not progress)
        out["work_precision"] = work_precision.assemble(level, results, sweep_results)
        work_precision.head_to_head(level, out["work_precision"])
        phase_b = time.perf_counter() - t_b
    if "hard_cases" in sections:
        out["hard_cases"] = hard_cases.assemble(level, results)
    if "contact" in sections:
        out["contact"] = {"gas": {f"{dim}-D": results[("contact", "gas", dim)]
                                  for dim in contact.GAS},
                          "accretion": results[("contact", "accretion")]}
    phase_c = 0.0
    if "tree" in sections:  # timed: alone in this process, after everything else
        t_c = time.perf_counter()
        say = (lambda text: print(f"tree: {text}", file=sys.stderr)) if progress else None
        out["tree"] = tree_bench.measure(tree_bench.SIZES[level.name], progress=say,
                                         energy_spec=tree_bench.ENERGY[level.name])
        phase_c = time.perf_counter() - t_c
    out["timings"] = {"wall_s": time.perf_counter() - t_start, "untimed_phase_wall_s": phase_a,
                      "timed_phase_wall_s": phase_b, "tree_phase_wall_s": phase_c}
    return out


def contact_jobs(level):
    """The contact section's runs: the two gases and the accretion disk (untimed)."""
    relax, span = contact.GAS_TIMES[level.name]
    n, steps, dt, radius = contact.ACCRETION[level.name]
    jobs = [Job(("contact", "gas", dim), "contact:gas_run",
                dict(dim=dim, n=n_gas, packing=packing, relax=relax, span=span),
                cost=n_gas * (relax + span) * 4000)
            for dim, (n_gas, packing) in contact.GAS.items()]
    jobs.append(Job(("contact", "accretion"), "contact:accretion_run",
                    dict(n=n, steps=steps, dt=dt, radius=radius), cost=n * steps * 3))
    return jobs


def meta(level, workers, scheduler=None):
    import numba
    return {
        "level": level.name, "engine_version": engine.__version__,
        "rebound_version": rebound_version(), "numpy_version": np.__version__,
        "numba_version": numba.__version__, "python_version": platform.python_version(),
        "machine": platform.machine(), "cpu_count": os.cpu_count(), "workers": workers,
        "scheduler": scheduler,
        "integrators": list(engine.integrators.GENERAL),
        "work_precision_methods": {m.key: m.description for m in work_precision.METHODS.values()},
        "force_evaluations_per_step": dict(engine.integrators.FORCE_EVALUATIONS),
    }


# -- JSON ------------------------------------------------------------------------------------------

def jsonable(x):
    if isinstance(x, dict):
        return {str(k): jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        return jsonable(x.tolist())
    if isinstance(x, (np.floating, float)):
        x = float(x)
        return x if math.isfinite(x) else ("inf" if x > 0 else "-inf" if x < 0 else "nan")
    if isinstance(x, (np.integer,)):
        return int(x)
    if isinstance(x, np.bool_):
        return bool(x)
    return x


# -- formatting ------------------------------------------------------------------------------------

def f(x, digits=2):
    """A number in scientific notation for tables; a dash for missing values."""
    if x is None:
        return "—"
    if isinstance(x, str):
        return x
    if not math.isfinite(x):
        return "inf" if x > 0 else "nan"
    if x == 0:
        return "0"
    return f"{x:.{digits - 1}e}"


def g(x, digits=3):
    return "—" if x is None else f"{x:.{digits}g}"


def expo(x):
    """A growth exponent: two decimals (no '-0.00')."""
    if x is None:
        return "—"
    return f"{0.0 if abs(x) < 0.005 else x:.2f}"


def table(header, rows):
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    out += ["| " + " | ".join(str(c).replace("|", "\\|") for c in row) + " |" for row in rows]
    return "\n".join(out)


def seconds(s):
    return f"{s:.3g} s" if s < 100 else f"{s / 60:.1f} min"


# -- sections --------------------------------------------------------------------------------------

def section_crosscheck(res):
    lines = ["## 1. Same algorithm, two codes: engine `leapfrog` against REBOUND `leapfrog`", ""]
    lines.append(
        "Both are drift-kick-drift with one force evaluation per step. Each case is set up "
        "identically in both codes (G = 1, same masses, positions and velocities; neither code "
        "moves anything to the centre of mass, and the two massive bodies' centre of mass is "
        "off the origin and moving) and stepped with the same dt; the states are compared about "
        "six times per orbit, at every phase. *Relative difference* = max over samples and "
        "components of |x_engine - x_REBOUND| / (size of the configuration: the largest distance "
        "from the centre of mass, or from the fixed centre), the same for velocities with the "
        "largest velocity relative to the centre of mass. The last two columns compare each "
        "code with the same "
        "algorithm run in 80-bit extended precision (numpy `longdouble`), which shows each "
        "code's own rounding error.")
    lines.append("")
    rows = []
    worst = 0.0
    for key, c in res.items():
        worst = max(worst, c["max_rel_pos_difference"], c["max_rel_vel_difference"])
        rows.append([c["problem"], c["steps"], g(c["orbits"]), g(c["dt"], 6),
                     f(c["max_rel_pos_difference"]), f(c["max_rel_vel_difference"]),
                     f(c.get("max_rel_pos_engine_vs_extended")),
                     f(c.get("max_rel_pos_rebound_vs_extended"))])
    lines.append(table(["case", "steps", "orbits", "dt", "max rel. position difference",
                        "max rel. velocity difference", "engine vs 80-bit", "REBOUND vs 80-bit"],
                       rows))
    lines.append("")
    own = [max(c.get("max_rel_pos_engine_vs_extended", 0),
               c.get("max_rel_pos_rebound_vs_extended", 0)) for c in res.values()]
    ratio = max(c["max_rel_pos_difference"] / max(own_i, 1e-300)
                for c, own_i in zip(res.values(), own))
    lines.append(
        f"**Findings.** The largest difference seen between the two codes is {f(worst)} "
        f"(relative), over runs of up to {max(c['steps'] for c in res.values())} steps. It is "
        f"round-off: each code differs from the extended-precision run of the same algorithm by "
        f"up to {f(max(own))}, and the two codes differ from each other by at most "
        f"{ratio:.2g} times that. The difference grows with the number of steps (the rounding "
        "errors of a leapfrog orbit accumulate as a phase error), so it is smallest on short runs: "
        "the tests assert agreement to 1e-12 over 256 steps.")
    lines.append("")
    return "\n".join(lines)


def section_two_body(sec, level, fig_conv, fig_growth):
    first = next(iter(sec.values()))
    cps = first["checkpoints"]
    lines = ["## 2. Two-body orbits against the Kepler solution and REBOUND", ""]
    lines.append(
        "A test particle about a fixed mu = 1 centre (`forces.PointMass`; in REBOUND a central "
        "mass 1 and a massless particle), a = 1, started at pericentre (Hairer, Lubich & Wanner's "
        "initial conditions) for e = 0, 0.5, 0.9, 0.99, and a hyperbolic flyby (a = -1, e = 2, "
        "started half a time unit before pericentre). The time unit is P = 2 pi (the orbital "
        f"period of the ellipses). Every method runs with `integrate(k P)` to k = "
        f"{', '.join(str(c) for c in cps)}. Fixed-step methods take "
        f"{', '.join(str(n) for n in level.tb_steps_per_orbit)} steps per P; `rk45` runs at "
        f"tolerances {', '.join(f'{t:g}' for t in level.tb_tolerances)}; REBOUND's `whfast` and "
        "`leapfrog` take the same steps as the engine. Errors are relative, but never to less "
        "than the orbit's scale: |r - r_ref| / max(|r_ref|, |a|) and |v - v_ref| / "
        "max(|v_ref|, sqrt(mu/|a|)) (so a phase error at the pericentre of e = 0.99, where "
        "|r| = 0.01, is not inflated a hundredfold; far out on the hyperbola they are plain "
        "relative errors).")
    lines.append("")
    # reference agreement
    rows = []
    for entry in sec.values():
        agree = entry["ias15_vs_kepler"]
        rows.append([entry["title"]]
                    + [f"{f(p)} / {f(v)}" for p, v in zip(agree["pos"], agree["vel"])])
    lines.append("**The two references agree.** REBOUND IAS15 (epsilon 1e-11) against "
                 "`engine.analytic.kepler`, position / velocity:")
    lines.append("")
    lines.append(table(["problem"] + [f"t = {c} P" for c in cps], rows))
    lines.append("")
    rel = []
    for e in sec.values():
        for run in e["runs"]:
            for a, b in zip(run["pos_err_kepler"], run["pos_err_ias15"]):
                if a is not None and b is not None and min(a, b) > 1e-8:
                    rel.append(abs(a - b) / max(a, b))
    lines.append(
        "So the errors below, measured against the closed form, are also the errors against "
        "IAS15: an error and the same error measured against IAS15 differ by at most the "
        "references' disagreement in the table above, and for every error above 1e-8 by at "
        f"most {f(max(rel) if rel else None)} of its size (both are in `results.json`).")
    lines.append("")
    cp = cps[min(1, len(cps) - 1)]
    lines.append(f"![position error after {cp} P against steps per P]({fig_conv})")
    lines.append("")
    lines.append(f"![position error against time]({fig_growth})")
    lines.append("")
    for entry in sec.values():
        lines.append(f"### {entry['title']}")
        lines.append("")
        lines.append("Position / velocity error against the Kepler solution.")
        lines.append("")
        rows = []
        for run in entry["runs"]:
            cells = []
            for p_, v_ in zip(run["pos_err_kepler"], run["vel_err_kepler"]):
                cells.append("—" if p_ is None else f"{f(p_)} / {f(v_)}")
            name = run["integrator"] if run["code"] == "engine" else f"REBOUND {run['integrator']}"
            status = "" if run["status"] == "ok" else f" ({run['status']})"
            rows.append([name + status, run["setting"], run["steps"]] + cells)
        lines.append(table(["method", "setting", "steps"] + [f"t = {c} P" for c in cps], rows))
        lines.append("")
    lines.append(two_body_findings(sec, level))
    lines.append("")
    return "\n".join(lines)


def _err_at(entry, method, setting_key, setting, idx, ref="kepler"):
    for run in entry["runs"]:
        if run["method"] == method and run.get(setting_key) == setting:
            vals = run[f"pos_err_{ref}"]
            return vals[idx] if idx < len(vals) else None
    return None


def two_body_findings(sec, level):
    n_mid = level.tb_steps_per_orbit[min(1, len(level.tb_steps_per_orbit) - 1)]
    first = next(iter(sec.values()))
    idx = min(1, len(first["checkpoints"]) - 1)
    last = len(first["checkpoints"]) - 1
    cp, cp_last = first["checkpoints"][idx], first["checkpoints"][last]
    parts = []
    e05 = sec.get("kepler_e0.5")
    if e05:
        errs = {run["integrator"]: run["pos_err_kepler"][idx] for run in e05["runs"]
                if run["code"] == "engine" and run.get("steps_per_orbit") == n_mid}
        errs = {k: v for k, v in errs.items() if v is not None}
        if errs:
            lo = min(errs, key=errs.get)
            hi = max(errs, key=errs.get)
            parts.append(
                f"At e = 0.5 with {n_mid} steps per orbit, the position error after {cp} orbits "
                f"ranges from {f(errs[lo])} ({lo}) to {f(errs[hi])} ({hi}); the fourth-order "
                f"methods (rk4 {f(errs.get('rk4'))}, yoshida4 {f(errs.get('yoshida4'))}, pefrl "
                f"{f(errs.get('pefrl'))}) beat the second-order ones (leapfrog "
                f"{f(errs.get('leapfrog'))}, verlet {f(errs.get('verlet'))}) by orders of "
                "magnitude.")
    # leapfrog engine vs REBOUND
    ratios, lost = [], []
    for entry in sec.values():
        for n in level.tb_steps_per_orbit:
            for k in range(len(entry["checkpoints"])):
                a = _err_at(entry, "engine:leapfrog", "steps_per_orbit", n, k)
                b = _err_at(entry, "rebound:leapfrog", "steps_per_orbit", n, k)
                if a is None or b is None:
                    continue
                if 1e-10 < a < 0.1 and 1e-10 < b < 0.1:
                    ratios.append(abs(a / b - 1.0))
                elif a >= 0.1 or b >= 0.1:
                    lost.append(abs(a / b - 1.0))
    if ratios:
        parts.append(
            f"The engine's leapfrog and REBOUND's leapfrog have matching errors wherever the "
            f"orbit is followed (errors between 1e-10 and 0.1: the two errors differ by at most "
            f"{f(max(ratios))} of their size).")
    if lost and max(lost) > 1e-3:
        parts.append(
            f"Where the orbit is lost (error above 0.1, mostly e = 0.99 with a step comparable to "
            f"the pericentre passage), the two codes' errors differ by up to {f(max(lost))} of "
            "their size: an unresolved pericentre passage amplifies their different rounding.")
    wh = {key: max(v for run in e["runs"] if run["method"] == "rebound:whfast"
                   for v in run["pos_err_kepler"] if v is not None)
          for key, e in sec.items()}
    if wh:
        parts.append(
            "REBOUND's WHFast advances a two-body orbit with a Kepler solver, so its error is "
            "not a truncation error of the step (it does not shrink as the step does): largest "
            "error over every step and time "
            + ", ".join(f"{f(v)} ({sec[k]['title']})" for k, v in wh.items())
            + "; none of the engine's generic integrators is exact on this problem.")
    orders = measured_orders(sec, level)
    if orders:
        parts.append(
            "Measured order of convergence (hyperbolic flyby, max of the position and velocity "
            "errors after 1 P, between the finest two step counts above round-off): "
            + ", ".join(f"{n} {o:.2f} ({n1}-{n2} steps/P; nominal {engine.ORDERS[n]})"
                        for n, (o, n1, n2) in orders.items())
            + ". (Over whole periods from pericentre, as in the ellipse tables, symplectic "
            "Euler's first-order position error cancels and it looks second order.)")
    e99 = sec.get("kepler_e0.99")
    if e99:
        n_hi = level.tb_steps_per_orbit[-1]
        vals = {run["integrator"]: run["pos_err_kepler"][idx] for run in e99["runs"]
                if run["code"] == "engine" and run.get("steps_per_orbit") == n_hi}
        bad = sorted(k for k, v in vals.items() if v is None or v > 0.1)
        good = sorted(k for k, v in vals.items() if v is not None and v <= 0.1)
        parts.append(
            f"e = 0.99 is hard for every fixed step: with {n_hi} steps per orbit, after {cp} "
            f"orbits the position error exceeds 10% for {', '.join(bad) or 'none'}"
            + (f" and stays below it only for {', '.join(good)}" if good else "") + ".")
        tol_runs = [r for r in e99["runs"] if r["integrator"] == "rk45"]
        if tol_runs:
            best = min(tol_runs, key=lambda r: r["tolerance"])
            parts.append(
                f"rk45, which shortens its steps at pericentre, has at tolerance "
                f"{best['tolerance']:g} a position error of {f(best['pos_err_kepler'][idx])} after "
                f"{cp} orbits and {f(best['pos_err_kepler'][last])} after {cp_last} orbits "
                f"({best['steps']} steps, {best['steps'] / cp_last:.0f} per orbit).")
    hyp = sec.get("hyperbolic")
    if hyp:
        pairs = [(run["pos_err_kepler"][0], run["pos_err_kepler"][last]) for run in hyp["runs"]
                 if run["code"] == "engine" and run["pos_err_kepler"][last] is not None
                 and run["pos_err_kepler"][0]]
        if pairs:
            growth = max(b / a for a, b in pairs)
            parts.append(
                f"On the hyperbolic flyby the relative errors are made during the pericentre "
                f"passage and hardly change afterwards: from t = 1 P to t = {cp_last} P no engine "
                f"run's error grows by more than a factor {growth:.2g} (errors at the end between "
                f"{f(min(b for _, b in pairs))} and {f(max(b for _, b in pairs))}).")
    return "**Findings.** " + " ".join(parts)


def measured_orders(sec, level):
    """Empirical order of each fixed-step integrator on the hyperbolic flyby after 1 P, from
    the finest pair of step settings whose errors are both above 1e-11 (round-off floor).

    The error is max(position error, velocity error). The flyby is used because runs over a
    whole number of periods from pericentre cancel part of the error (symplectic Euler's
    first-order position error cancels there)."""
    e = sec.get("hyperbolic")
    steps = list(level.tb_steps_per_orbit)
    if not e or len(steps) < 2:
        return {}
    out = {}
    for name in engine.integrators.GENERAL:
        if name == "rk45":
            continue
        errs = {}
        for run in e["runs"]:
            if run["method"] == f"engine:{name}" and run.get("steps_per_orbit") in steps:
                p, v = run["pos_err_kepler"][0], run["vel_err_kepler"][0]
                if p is not None:
                    errs[run["steps_per_orbit"]] = max(p, v)
        for n1, n2 in reversed(list(zip(steps[:-1], steps[1:]))):
            a, b = errs.get(n1), errs.get(n2)
            if a and b and a > 1e-11 and b > 1e-11:
                out[name] = (math.log(a / b) / math.log(n2 / n1), n1, n2)
                break
    return out


def section_drift(sec, level, fig):
    lines = ["## 3. Energy drift", ""]
    lines.append(
        "Relative energy error |E(t) - E0| / |E0| sampled at log-spaced times (`sim.step(n)` in "
        "chunks for fixed steps, `integrate(t)` for rk45 and IAS15). Kepler problem e = 0.6 "
        f"for {level.drift_orbits:g} orbits at {level.drift_steps_per_orbit} steps per orbit "
        f"(explicit Euler also at {level.drift_euler_steps_per_orbit} steps per orbit for "
        f"{level.drift_euler_orbits:g} orbits; these Kepler Euler runs stop once their error "
        "passes 1), rk45 "
        f"at tolerance {level.drift_tolerance:g}; the outer solar system for "
        f"{level.drift_solar_days:g} days with dt = {level.drift_solar_dt:g} days; REBOUND IAS15 "
        "(default epsilon) and WHFast (same step) for comparison.")
    lines.append("")
    lines.append(
        "**Growth exponent**: slope of log(running maximum of the error) against log(t) over the "
        f"last {energy_drift.FIT_DECADES:g} decades of the run (ending where the error first passes "
        f"{energy_drift.DESTROYED:g}: the orbit is then no longer the one it started on). Classes: < 0.25 "
        "bounded; 0.25-0.75 a "
        "round-off random walk if the error is below 1e-11 (Brouwer's law, t^1/2), otherwise "
        "sublinear growth; 0.75-1.25 linear drift; > 1.25 faster than linear; too short to fit "
        "when the error passes the threshold before the window spans a decade.")
    lines.append("")
    lines.append(f"![energy error against time]({fig})")
    lines.append("")
    for key, entry in sec.items():
        rows = []
        for run in entry["runs"]:
            name = run["integrator"] if run["code"] == "engine" else f"REBOUND {run['integrator']}"
            win = run["fit_window"]
            unit = entry["time_unit"]
            win_s = "—" if win is None else f"{g(win[0] / unit)}-{g(win[1] / unit)}"
            note = "" if run["destroyed_at"] is None else \
                f"error > {energy_drift.DESTROYED:g} from t = {g(run['destroyed_at'] / unit)}"
            if run["status"] != "ok":
                note = (note + "; " if note else "") + run["status"]
            rows.append([name, run["setting"], run["steps"], f(run["final_error"]),
                         expo(run["growth_exponent"]), run["class"], win_s, note])
        lines.append(f"**{entry['title']}** (time in {entry['time_unit_name']}s)")
        lines.append("")
        lines.append(table(["method", "setting", "steps", "final error", "growth exponent",
                            "class", "fit window", "notes"], rows))
        lines.append("")
    lines.append(drift_findings(sec))
    lines.append("")
    return "\n".join(lines)


EXPECTED_DRIFT = {
    "symplectic": ("bounded",),
    "engine:rk4": ("linear drift",),
    "engine:rk45": ("linear drift",),
    "engine:euler": ("linear drift", "sublinear growth", "faster than linear"),
    "rebound:ias15": ("random walk (round-off)", "bounded"),
    "rebound:whfast": ("bounded", "random walk (round-off)"),
}


def _expected(method):
    if method.split(":")[1] in engine.SYMPLECTIC and method.startswith("engine"):
        return EXPECTED_DRIFT["symplectic"]
    return EXPECTED_DRIFT.get(method, ())


def drift_findings(sec):
    parts = []
    for key, entry in sec.items():
        runs = entry["runs"]
        sym = [r for r in runs if r["code"] == "engine" and r["integrator"] in engine.SYMPLECTIC]
        other = [r for r in runs if r not in sym]
        desc = lambda r: (f"{label_of(r['method'])} {expo(r['growth_exponent'])} "  # noqa: E731
                          f"({r['class']}, final {f(r['final_error'])})")
        text = (f"{entry['title']}: symplectic methods {', '.join(desc(r) for r in sym)}; "
                f"{', '.join(desc(r) for r in other)}.")
        off = [label_of(r["method"]) for r in runs if _expected(r["method"])
               and r["class"] not in _expected(r["method"]) and r["class"] != "too short to fit"]
        text += (" Every fitted class is the one theory predicts (bounded for symplectic "
                 "methods, linear drift for rk4 and rk45, growth for Euler, a round-off floor "
                 "for IAS15)."
                 if not off else
                 f" Fitted classes that differ from the textbook expectation: {', '.join(off)}"
                 " (see the table and the plot).")
        parts.append(text)
        for eu in (r for r in runs if r["method"] == "engine:euler"):
            if eu["destroyed_at"]:
                when = g(eu["destroyed_at"] / entry["time_unit"])
                parts.append(f"Explicit Euler at {eu['setting']} passes an energy error of "
                             f"{energy_drift.DESTROYED:g} at t = {when} {entry['time_unit_name']}s; its "
                             "fit ends there.")
    return "**Findings.** " + " ".join(parts)


def label_of(method):
    code, name = method.split(":")
    return name if code == "engine" else f"REBOUND {name}"


def section_work_precision(sec, figs):
    lines = ["## 4. Work-precision: speed against error", ""]
    lines.append(
        "For each problem every method runs a sweep (fixed-step methods: N steps of dt = t_end / "
        "N; rk45: tolerances; IAS15 of either code: epsilon). x = error at t_end against a "
        "high-accuracy reference (max over bodies of |r - r_ref| / L; for the Pythagorean "
        "problem to t = 70 the relative energy error against the exact E0 = -769/60, because no "
        "double precision solution is known there to better than about 1e-2 in position, see "
        "below); "
        "y = wall time of `sim.step`/`sim.integrate` alone (median of repeats for short runs, "
        "numba compilation excluded by a warm-up) and force evaluations (the engine's "
        "`sim.force_evaluations`, or `engine.integrators.FORCE_EVALUATIONS` per step where "
        "the simulation does not count them; REBOUND's counted with an "
        "`additional_forces` callback in untimed runs). Sweeps go from coarse to fine and stop "
        "at the reference's uncertainty (dotted vertical line), once the error stops falling "
        "below 1e-8 (round-off: two step counts in a row without a gain of 1.4), or at a fixed "
        "cost cap (force evaluations times interacting pairs), so the set of runs does not "
        "depend on the "
        "machine. Points with an error above 100 are not drawn. Timings are from this machine "
        "and change from run to run; the force-evaluation counts do not.")
    lines.append("")
    lines.append("Methods: " + "; ".join(
        f"`{label_of(m.key)}` = {m.description}" for m in work_precision.METHODS.values()
        if m.name != m.description) + ". The engine's `whfast` and `saba` need a dominant mass "
        "or a fixed attractor: elsewhere the engine refuses them and they are listed as "
        "skipped, as are REBOUND's corrected WHFast and SABAC4 (REBOUND's uncorrected WHFast "
        "and SABA(10,6,4) still run everywhere, as before). REBOUND's WHFast and SABA run in "
        "`safe_mode = 0` with one `synchronize()` at the end of the run, their fastest use "
        "(with `safe_mode = 1` REBOUND applies the corrector at every step, 20-50 times "
        "slower per step with corrector 11 or 17).")
    lines.append("")
    lines.append(section_versus(sec))
    rows = []
    for key, e in sec.items():
        ref = e["reference"]
        checks = "; ".join(f"{k}: {f(v)}" for k, v in ref["checks"].items())
        rows.append([e["title"], f"{e['n']} bodies, {e['dim']}-D", g(e["t_end"]), e["length_name"],
                     ref["description"], checks])
    lines.append(table(["problem", "size", "t_end", "L", "reference", "reference checked against "
                        "(same error measure)"], rows))
    lines.append("")
    for key, e in sec.items():
        lines.append(f"### {e['title']}")
        lines.append("")
        lines.append(e["notes"] + ".")
        lines.append("")
        lines.append(f"![work-precision {e['title']}]({figs[key]})")
        lines.append("")
        rows = []
        for row in e["cheapest"]:
            cells = [f(row["level"], 1)
                     + (" (below reference floor)" if row["below_reference_floor"] else "")]
            for name in ("fastest", "fewest_evaluations", "fastest_engine"):
                best = row[name]
                if best is None:
                    cells.append("none reached")
                else:
                    cells.append(f"{label_of(best['method'])} {best['setting']}: "
                                 f"{seconds(best['time_s'])}, {best['evaluations']} evals")
            rows.append(cells)
        lines.append("Cheapest run reaching each error level:")
        lines.append("")
        lines.append(table(["error at most", "fastest", "fewest force evaluations",
                            "fastest engine integrator"], rows))
        lines.append("")
        if e.get("versus"):
            lines.append("Engine best / REBOUND best: the fastest run of each code that reaches "
                         "the level, timed again side by side (ratio = engine time / REBOUND "
                         "time, median of alternating repetitions):")
            lines.append("")
            lines.append(table(["error at most", "engine best", "REBOUND best",
                                "engine / REBOUND"], versus_rows(e)))
            lines.append("")
        if e.get("skipped"):
            lines.append("Skipped here: " + skipped_text(e["skipped"]) + ".")
            lines.append("")
        failures = sorted({label_of(r["method"]) for r in e["runs"] if r["status"] != "ok"})
        lines.append(wp_findings(e, failures))
        lines.append("")
    return "\n".join(lines)


def _best_cell(best):
    if best is None:
        return "none reached"
    return (f"{label_of(best['method'])} {best['setting']}: {seconds(best['time_s'])}, "
            f"{best['evaluations']} evals, error {f(best['error'])}")


def ratio_cell(row):
    """The ratio of one level, or which side did not reach the level."""
    e, r = row["engine"], row["rebound"]
    if e is None and r is None:
        text = "neither reached"
    elif e is None:
        text = "engine: not reached"
    elif r is None:
        text = "REBOUND: not reached"
    else:
        text = f"{row['ratio']:.2f}"
        if row["ratio"] > 1.0:
            text = f"**{text}**"
    if row["below_reference_floor"]:
        text += " (below reference floor)"
    return text


def versus_rows(e):
    rows = []
    for row in e["versus"]:
        cell = ratio_cell(row)
        sbs = row.get("side_by_side")
        if sbs and sbs.get("status") == "ok":
            cell += (f" (side by side: {seconds(sbs['engine_time_s'])} / "
                     f"{seconds(sbs['rebound_time_s'])}, {sbs['repeats']} "
                     f"repetition{'s' if sbs['repeats'] != 1 else ''}; in the "
                     f"sweeps {row['sweep_ratio']:.2f})")
        elif sbs:
            cell += f" (sweep timing; side by side failed: {sbs['status']})"
        rows.append([f(row["level"], 1), _best_cell(row["engine"]), _best_cell(row["rebound"]),
                     cell])
    return rows


def versus_why(rows):
    """Why the engine's best is slower, for the error levels ``rows`` that share one pair of
    runs: the engine's share of force evaluations and of time per evaluation (the ratio is
    their product)."""
    row = rows[0]
    e, r = row["engine"], row["rebound"]
    sbs = row.get("side_by_side") or {}
    t_e = sbs.get("engine_time_s", e["time_s"])
    t_r = sbs.get("rebound_time_s", r["time_s"])
    ev = e["evaluations"] / max(r["evaluations"], 1)
    per = (t_e / max(e["evaluations"], 1)) / (t_r / max(r["evaluations"], 1))
    same = e["method"].split(":")[1] == r["method"].split(":")[1]
    levels = sorted(x["level"] for x in rows)
    where = (f"error <= {f(levels[0], 1)}" if len(levels) == 1 else
             f"errors <= {f(levels[-1], 1)} to {f(levels[0], 1)}")
    return (f"{where}: engine {label_of(e['method'])} {e['setting']} against REBOUND "
            f"{r['method'].split(':')[1]} {r['setting']}"
            + (" (the same method)" if same else "")
            + f", ratio {row['ratio']:.2f} = {ev:.2f}x the force evaluations times {per:.2f}x "
              "the time per evaluation"
            + (f" (a call of one step: engine {seconds(sbs['engine_one_step_call_s'])}, "
               f"REBOUND {seconds(sbs['rebound_one_step_call_s'])})"
               if "engine_one_step_call_s" in sbs else ""))


def _pairs(rows):
    """``rows`` grouped by their pair of runs (levels that picked the same two runs)."""
    groups = {}
    for row in rows:
        key = (row["engine"]["method"], row["engine"]["setting"], row["rebound"]["method"],
               row["rebound"]["setting"])
        groups.setdefault(key, []).append(row)
    return list(groups.values())


def skipped_text(skipped):
    """The skipped methods, grouped by their reason."""
    groups = {}
    for sk in skipped:
        reason = sk["reason"]
        if sk["method"].startswith("engine:"):
            name = sk["method"].split(":")[1]
            integ = "saba" if name.startswith("saba") else "whfast"
            reason = "refused by the engine: " + reason.replace(f"{integ} needs", "needs", 1)
        groups.setdefault(reason, []).append(label_of(sk["method"]))
    return "; ".join(f"{', '.join(names)} ({reason})" for reason, names in groups.items())


def section_versus(sec):
    """The summary table of "engine best / REBOUND best" over the problems REBOUND runs."""
    entries = {k: e for k, e in sec.items() if e.get("versus")}
    if not entries:
        return ""
    levels = [row["level"] for row in next(iter(entries.values()))["versus"]]
    rows = [[e["title"]] + [ratio_cell(row) for row in e["versus"]] for e in entries.values()]
    lines = ["### Engine best / REBOUND best", ""]
    lines.append(
        "Per problem and error level: the wall time of the fastest engine run that reaches the "
        "level over the wall time of the fastest REBOUND run that reaches it (any method of "
        "either code; both picked from the sweeps, then timed again side by side, alternating, "
        "in this process: the median of the per-repetition ratios). Below 1 the engine is "
        "faster; bold: REBOUND is faster. The goal is at most 1 everywhere: the engine's best at least as fast as REBOUND's best.")
    lines.append("")
    lines.append(table(["problem"] + [f"error <= {f(l, 1)}" for l in levels], rows))
    lines.append("")
    others = [e["title"] for k, e in sec.items() if not e.get("rebound")]
    compared = [row for e in entries.values() for row in e["versus"]
                if row["ratio"] is not None and not row["below_reference_floor"]]
    over = [(e, row) for e in entries.values() for row in e["versus"]
            if row["ratio"] is not None and row["ratio"] > 1.0
            and not row["below_reference_floor"]]
    parts = [f"{len(compared) - len(over)} of {len(compared)} compared cells (above the "
             "reference floors) are at most 1."]
    if over:
        by_problem = {}
        for e, row in over:
            by_problem.setdefault(e["title"], []).append(row)
        parts.append("Where REBOUND is faster: " + " ".join(
            f"{title}: {'; '.join(versus_why(group) for group in _pairs(rows))}."
            for title, rows in by_problem.items()))
    unreached = [f"{e['title']} at {f(row['level'], 1)} ({ratio_cell(row)})"
                 for e in entries.values() for row in e["versus"]
                 if row["ratio"] is None and (row["engine"] or row["rebound"])]
    if unreached:
        parts.append("Reached by one code only: " + "; ".join(unreached) + ".")
    if others:
        parts.append(f"Not compared ({', '.join(others)}): REBOUND has no such force terms.")
    lines.append("**Findings.** " + " ".join(parts))
    lines.append("")
    return "\n".join(lines)


def wp_findings(e, failures):
    parts = []
    engine_runs = [r for r in e["runs"] if r["code"] == "engine" and r.get("error") is not None]
    if engine_runs:
        best = min(engine_runs, key=lambda r: r["error"])
        parts.append(f"Smallest engine error: {f(best['error'])} ({best['integrator']}, "
                     f"{best['setting_label']}, {seconds(best['time_s'])}).")
    for row in e["cheapest"]:
        if row["fastest_engine"] and row["level"] in (1e-4, 1e-8):
            b = row["fastest_engine"]
            parts.append(f"To reach {f(row['level'], 1)} the fastest engine choice is "
                         f"{b['method'].split(':')[1]} ({seconds(b['time_s'])}).")
    if e["metric"] == "position":
        parts.append(f"The reference is trusted to {f(e['reference']['floor'])}.")
    # symplectic Euler from rest is leapfrog half a step later: say so when it shows
    se = {r["setting"]: r["error"] for r in engine_runs if r["integrator"] == "symplectic_euler"}
    lf = {r["setting"]: r["error"] for r in engine_runs if r["integrator"] == "leapfrog"}
    common = sorted(set(se) & set(lf))
    if (common and e.get("at_rest") and e["metric"] == "position"
            and abs(se[common[-1]] / lf[common[-1]] - 1.0) < 0.1):
        parts.append(
            "Every particle starts at rest here, and then symplectic Euler's positions are exactly "
            "leapfrog's positions half a step later (the kick-drift sequence started from rest "
            "is the drift-kick-drift sequence seen at its half steps), so its position error is "
            "leapfrog's plus h v / 2: the two lines nearly coincide although symplectic Euler is "
            "first order (its energy error is not; see `results.json`).")
    if failures:
        parts.append(f"Methods with runs that did not finish (SimulationError, non-finite state "
                     f"or, for IAS15, over the cost cap), at their coarsest settings: "
                     f"{', '.join(failures)}.")
    return "**Findings.** " + " ".join(parts)


def section_hard_cases(sec, fig_spring):
    lines = ["## 5. Hard cases: numerical stability", ""]
    lines.append(
        "Outcomes: **stable** = the run finishes, meets the case's accuracy criterion and "
        "reproduces the known outcome; **inaccurate** = finishes but misses either; **blows up** = "
        "the engine detected a non-finite state and raised `SimulationError` (it never carries on "
        "from one silently).")
    lines.append("")
    for case, spec in sec["cases"].items():
        if case == "spring":
            continue
        tab = sec["tables"].get(case)
        if not tab:
            continue
        lines.append(f"### {spec['title']}")
        lines.append("")
        lines.append(f"Literature: {spec['literature']}. Criterion: {spec['criterion']}.")
        lines.append("")
        fixed, adaptive = tab["fixed"], tab["adaptive"]
        if case == "coincident":
            cols = [(r["key"], f"{r['label']} (dt {r['dt']:g})") for r in sec["coincident_rows"]]
        else:
            settings = {}
            for cells in fixed.values():
                for lab, res in cells.items():
                    settings[lab] = res["setting"]
            # coarse to fine: step counts ascending, step sizes descending
            steps_like = case in ("e099", "figure_eight")
            cols = [(lab, lab) for lab in sorted(settings, key=lambda l: settings[l],
                                                 reverse=not steps_like)]
        extra = ["adaptive step"] if adaptive else []
        rows = []
        order = list(engine.integrators.GENERAL)
        for name in sorted(fixed, key=order.index):
            cells = fixed[name]
            rows.append([name] + [("—" if c not in cells else
                                   f"**{cells[c]['outcome']}**: {cells[c]['detail']}")
                                  for c, _ in cols] + [""] * len(extra))
        for lab, res in adaptive.items():
            rows.append([lab] + [""] * len(cols)
                        + [f"**{res['outcome']}**: {res['detail']}, {res['steps']} steps"])
        lines.append(table(["integrator"] + [lab for _, lab in cols] + extra, rows))
        lines.append("")
        lines.append(hard_findings(case, sec))
        lines.append("")
    # stiff spring
    spec = sec["cases"]["spring"]
    lines.append(f"### {spec['title']}")
    lines.append("")
    lines.append(
        f"Literature: {spec['literature']}. Two unit masses joined by a zero-rest-length spring "
        "(force k d: a linear oscillator at every amplitude), omega = sqrt(2k). **Measured "
        "limit**: the largest omega dt at which the energy stays below 1e6 times its start "
        f"over {sec['spring_steps']} steps (grid scan, then bisection); **theory**: the first "
        "omega dt at which the scheme's one-step matrix for x'' = -omega^2 x stops being stable, "
        "computed from the published coefficients (not from the engine).")
    lines.append("")
    ks = sorted({k for v in sec["spring_limits"].values() for k in v["measured"]})
    rows = []
    for name, v in sec["spring_limits"].items():
        if name == "rk45":
            continue
        cells = [name, g(v["theory"], 6)]
        for k in ks:
            m = v["measured"].get(k) or {}
            cells.append(g(m.get("limit"), 7))
        if name in ("symplectic_euler", "leapfrog", "verlet"):
            lims = [v["measured"][k]["limit"] for k in ks if v["measured"].get(k, {}).get("limit")]
            cells.append(f"{min(lims) / 2:.7f} - {max(lims) / 2:.7f}" if lims else "—")
        else:
            cells.append("")
        rows.append(cells)
    lines.append(table(["integrator", "theory omega dt"] + [f"measured, k = {k:g}" for k in ks]
                       + ["measured / 2 (the dt < 2/omega rule)"], rows))
    lines.append("")
    lines.append(f"![stiff spring stability limits]({fig_spring})")
    lines.append("")
    out = sec["spring_outcomes"]
    ks_o = sorted({k for v in out.values() for k in v})
    rows = []
    for name in engine.integrators.GENERAL:
        if name not in out:
            continue
        rows.append([name] + [f"**{out[name][k]['outcome']}**: {out[name][k]['detail']}"
                              for k in ks_o])
    lines.append(f"The lecture's k -> infinity at a fixed dt = {sec['spring_dt']:g} for 10000 "
                 "steps "
                 "(rk45 with tolerance 1e-9 over the same time, dt as its first step):")
    lines.append("")
    heads = [f"k = {k:g} (omega dt = {math.sqrt(2 * k) * sec['spring_dt']:.3g})" for k in ks_o]
    lines.append(table(["integrator"] + heads, rows))
    lines.append("")
    lines.append(hard_findings("spring", sec))
    lines.append("")
    return "\n".join(lines)


def hard_findings(case, sec):
    tab = sec["tables"].get(case, {})
    parts = []
    if case == "spring":
        lim = sec["spring_limits"]
        rel = []
        for name in ("symplectic_euler", "leapfrog", "verlet", "rk4", "yoshida4", "pefrl"):
            th = lim[name]["theory"]
            for k, m in lim[name]["measured"].items():
                if m.get("limit") and th:
                    rel.append(abs(m["limit"] / th - 1.0))
        eu = [m.get("limit") for m in lim["euler"]["measured"].values() if m.get("limit")]
        parts.append(
            f"Every measured limit matches its theory to {f(max(rel) if rel else None)} (relative) "
            "for every stiffness: the limit is a fixed omega dt, so dt_max = c / omega = "
            "c / sqrt(2k) -> 0 as k -> infinity. Leapfrog, Verlet and symplectic Euler share "
            "c = 2 (dt < 2/omega); RK4 reaches 2 sqrt 2, PEFRL about 2.99, while Yoshida's "
            "triple jump, with its backward substep, is stable only to about 1.57.")
        if eu:
            parts.append(
                f"Explicit Euler has no stable step at all: its energy grows by (1 + omega^2 dt^2) "
                f"per step, so the 'limit' measured ({g(min(eu), 3)}-{g(max(eu), 3)}) only says "
                "how "
                f"small omega dt must be for the growth to stay below 1e6 over "
                f"{sec['spring_steps']} steps, and it shrinks as the run gets longer.")
        parts.append("Beyond the limit the amplitude grows exponentially until it overflows, which "
                     "the engine reports as SimulationError (the k = 1e6 column); rk45 stays "
                     "stable at any stiffness by taking more steps.")
        out = sec["spring_outcomes"]
        mid = [k for k in sorted(out.get("rk4", {}))
               if 1.0 < math.sqrt(2 * k) * sec["spring_dt"] < 2.0]
        if mid:
            k = mid[0]
            wdt = math.sqrt(2 * k) * sec["spring_dt"]
            lf = out.get("leapfrog", {}).get(k, {})
            vv = out.get("verlet", {}).get(k, {})
            rk = out["rk4"][k]
            parts.append(
                f"Inside the limits, at omega dt = {wdt:.3g}, the methods fail differently: RK4 "
                f"damps the oscillation (its amplification factor is below 1; |dE/E| = "
                f"{f(rk['energy_error'])}: the energy drains away), while leapfrog and Verlet keep "
                f"it but their energy swings by up to a factor 1/(1 - (omega dt/2)^2) = "
                f"{1 / (1 - (wdt / 2) ** 2):.3g} (measured |dE/E|: leapfrog "
                f"{f(lf.get('energy_error'))}, Verlet {f(vv.get('energy_error'))}).")
        return "**Findings.** " + " ".join(parts)
    everything = [r for cells in tab["fixed"].values() for r in cells.values()]
    everything += list(tab["adaptive"].values())
    counts = {}
    for res in everything:
        counts[res["outcome"]] = counts.get(res["outcome"], 0) + 1
    summary = ", ".join(f"{v} {k}" for k, v in sorted(counts.items()))
    parts.append(f"Outcomes over all {len(everything)} runs: {summary}.")
    stable_fixed = sorted({f"{n} ({lab})" for n, cells in tab["fixed"].items()
                           for lab, r in cells.items() if r["outcome"] == "stable"})
    if case in ("e099", "pythagorean", "figure_eight", "flyby"):
        parts.append("Fixed-step runs that are stable: " + (", ".join(stable_fixed) or "none")
                     + ".")
        ad = [f"{lab}: {r['outcome']}" for lab, r in tab["adaptive"].items()]
        if ad:
            parts.append("Adaptive: " + "; ".join(ad) + ".")
    if case == "pythagorean":
        for lab, res in tab["adaptive"].items():
            if res["integrator"] != "ias15":
                continue
            parts.append(
                f"REBOUND IAS15 reproduces the known outcome (m = "
                f"{g(res.get('escaper_mass'))} escapes, energy error {f(res['energy_error'])}); "
                f"its closest approach, checked at every IAS15 step, is "
                f"{f(res.get('closest_approach'), 3)} at t = "
                f"{g(res.get('closest_approach_time'), 4)}.")
        repro = [f"{n} ({lab}, |dE/E0| {f(res['energy_error'])})"
                 for n, cells in tab["fixed"].items() for lab, res in cells.items()
                 if res.get("reproduced")]
        repro += [f"{lab} (|dE/E0| {f(res['energy_error'])})"
                  for lab, res in tab["adaptive"].items()
                  if res.get("reproduced") and res["integrator"] == "rk45"]
        parts.append(f"Engine runs in which the m = 3 body escapes: {', '.join(repro) or 'none'}; "
                     "a run with a large energy error that shows the escape has it by chance. "
                     "The problem is chaotic: a run whose error is too large at the close "
                     "encounters ends with a different body escaping, or none yet by t = 70.")
    if case == "coincident":
        parts.append("Exactly coincident bodies without softening make every integrator raise "
                     "SimulationError at the first step, as the engine promises; with softening "
                     "the same start is harmless.")
    return "**Findings.** " + " ".join(parts)


def section_tree(sec, fig_error, fig_time):
    """Section 6: the engine's tree gravity (FMM and Barnes-Hut) against pytreegrav's and
    REBOUND's trees."""
    lines = ["## 6. Tree gravity: error and speed against pytreegrav and REBOUND", ""]
    lines.append(
        "`NBodyGravity(method=\"tree\", theta, order=2)` sums near pairs directly and far "
        "cells by their multipoles to the quadrupole (Barnes & Hut 1986), walking the tree "
        "from its root for every group of targets; `method=\"fmm\"` (what `\"auto\"` uses) "
        "walks the same tree once, cells acting on cells through local expansions passed "
        "down to the groups (a fast multipole method: Greengard & Rokhlin 1987, Dehnen "
        "2002), so that its cost grows as N rather than N log N; pytreegrav and "
        "REBOUND are the references (pytreegrav with its monopole and with its quadrupole "
        "walk; REBOUND's pip build has the monopole tree on one core). The error of a body "
        "is |a - a_exact| / |a_exact|, a_exact summing every other body exactly. The opening "
        "angles of the three codes mean different things (the engine takes a cell whole when "
        "its size is below theta times its distance from a leaf's group of targets; REBOUND "
        "when its width is below theta times the distance from one target to the cell's "
        "centre of mass; pytreegrav has a criterion of its own), so the codes are compared at "
        "equal error, each at the theta its curve gives for a median error of "
        f"{sec['target_error']:g}, not at equal theta.")
    lines.append("")
    lines.append(f"![relative force error against theta]({fig_error})")
    lines.append("")
    lines.append(f"![time of one force evaluation against N]({fig_time})")
    lines.append("")
    lines += tree_bench.markdown_tree(sec)
    lines.append("")
    if "energy" in sec:
        lines += tree_bench.markdown_energy(sec["energy"])
        lines.append("")
    lines.append(tree_findings(sec))
    lines.append("")
    return "\n".join(lines)


def tree_findings(sec):
    """The section's findings, from its figures (and its targets, met or not)."""
    parts = []
    curves = sec["error"]["curves"]
    for code, curve in curves.items():
        at = {round(r["theta"], 6): r for r in curve["rows"]}
        if 0.5 in at:
            parts.append(f"At theta = 0.5 the median error of {sec['labels'][code]} is "
                         f"{f(at[0.5]['median'])} (99th percentile {f(at[0.5]['p99'])}).")
    rows = [r for r in sec["compare"] if r.get("speedup")]
    if rows:
        big = rows[-1]
        cells = ", ".join(f"{big['speedup'][c]:.1f}x against {sec['labels'][c]}"
                          for c in big["speedup"])
        parts.append(f"At N = {big['n']:.0e} and equal median error, the engine FMM's "
                     f"speed-up (the other code's time over the engine's; below 1x the engine "
                     f"is slower): {cells}.")
    e = sec.get("energy")
    if e:
        fmm, direct = e["fmm"], e["direct"]
        parts.append(
            f"Over {fmm['steps']} leapfrog steps of a {e['n']}-body Plummer sphere the FMM's "
            f"largest energy error is {f(max(abs(x) for x in fmm['dE']))} against the direct "
            f"sum's {f(max(abs(x) for x in direct['dE']))} over its {direct['steps']}; the "
            f"FMM's momentum drifts to {f(max(fmm['dP']))} of sum m|v| (its forces are not "
            f"antisymmetric pair by pair), the direct sum's to {f(max(direct['dP']))}.")
    for name, measured, met in tree_bench.targets(sec):
        parts.append(f"Target: {name}: {measured}, {'met' if met else 'not met'}.")
    return "**Findings.** " + " ".join(parts)


def section_contact(sec, fig):
    """Section 7: contact against statistical mechanics and against REBOUND."""
    lines = ["## 7. Contact: a hard-sphere gas and an accreting disk", ""]
    lines.append(
        "`sim.collisions = engine.Collisions(...)` finds every pair whose spheres touch during "
        "a step along the bodies' paths and resolves each at the moment of contact "
        "(`docs/engine.md`, \"Contact\"). **The gas**: equal hard disks (2-D) and hard spheres "
        "(3-D) in a periodic box, started at one speed in random directions, elastic. Their "
        "speeds should relax to the Maxwell-Boltzmann law of the dimension (Rayleigh in 2-D, "
        "Maxwell in 3-D: a Kolmogorov-Smirnov test, whose p-value at the start is the "
        "control), and the compressibility Z = PV/NkT from the collisional virial "
        "(Allen & Tildesley, *Computer Simulation of Liquids*, section 2.4) should match "
        "Henderson's hard-disk equation of state (1975) and Carnahan & Starling's "
        "hard-sphere one (1969).")
    lines.append("")
    lines.append(f"![speeds of the gas, and merges in the disk]({fig})")
    lines.append("")
    rows = []
    for name, g in sec["gas"].items():
        rows.append([name, g["n"], g["packing"], f"{g['contacts_per_sphere']:.0f}",
                     f(g["start_p"]), ", ".join(f(p) for p in g["p_values"]),
                     f"{g['z']:.4f}", f"{g['z_expected']:.4f} ({g['z_law']})",
                     f"{100 * (g['z'] / g['z_expected'] - 1):+.2f}%", f(g["energy_error"])])
    lines.append(table(["gas", "spheres", "packing", "contacts a sphere", "KS p at start",
                        "KS p after relaxing", "Z measured", "Z expected", "difference",
                        "energy error"], rows))
    lines.append("")
    a = sec["accretion"]
    lines.append(
        f"**The accretion disk**: a star and {a['n']} planetesimals (mass 1e-6, radius "
        f"{a['radius']:g}, a in [0.8, 1.2], e < 0.05, inclination < 0.01, none touching at "
        f"the start, G = 1), {a['steps']} leapfrog steps of {a['dt']:g} "
        f"({a['steps'] * a['dt'] / (2 * math.pi):.1f} orbits at a = 1), merging on contact, "
        "three ways: REBOUND's `collision = \"line\"` with its merge (a Python "
        "`collision_resolve` that does what `reb_collision_resolve_merge` does and logs the "
        "pair); the engine with `resolve_at=\"end\"` (REBOUND's way: pairs whose segments "
        "traced back from the end of the step come within reach, approaching or not, merged "
        "with their end-of-step state); the engine's default (each contact at the moment of "
        "touching, approaching pairs only). The disk is chaotic, so the runs can agree merge "
        "for merge only until round-off has grown; a merge counts as identical when the "
        "same body is absorbed in the same step.")
    lines.append("")
    rows = []
    for name, run in a["runs"].items():
        same = {"rebound": "—", "end": a["identical_end"],
                "contact": a["identical_contact"]}[name]
        picks = [run["merges_by_step"][k] for k in range(4, len(a["marks"]), 10)]
        rows.append([plots.ACCRETION_STYLE[name][0], run["merges"], same,
                     ", ".join(map(str, picks)), run["bodies_left"],
                     f"{run['largest_planetesimal'] / 1e-6:.0f}"])
    marks = [a["marks"][k] for k in range(4, len(a["marks"]), 10)]
    lines.append(table(["run", "merges", "first merges identical to REBOUND's",
                        f"merges by step {', '.join(map(str, marks))}", "bodies left",
                        "largest planetesimal (initial masses)"], rows))
    lines.append("")
    rows = []
    for name in ("end", "contact"):
        k = a[name + "_conservation"]
        rows.append([plots.ACCRETION_STYLE[name][0], f(k["mass"]), f(k["momentum"]),
                     f(k["charge"]), f(k["energy_without_ledger"]), f(k["energy_with_ledger"])])
    lines.append(table(["engine run", "mass", "momentum (of sum m|v|)", "charge",
                        "energy", "energy + ledger"], rows))
    lines.append("")
    lines.append(contact_findings(sec))
    lines.append("")
    return "\n".join(lines)


def contact_findings(sec):
    """The contact section's findings, from its figures."""
    parts = []
    for name, g in sec["gas"].items():
        parts.append(
            f"The {name} gas relaxes from KS p = {f(g['start_p'])} to p >= "
            f"{f(min(g['p_values']))} against {'Rayleigh' if g['dim'] == 2 else 'Maxwell'}; "
            f"its Z is {g['z']:.4f} against {g['z_expected']:.4f} "
            f"({100 * (g['z'] / g['z_expected'] - 1):+.2f}%), energy kept to "
            f"{f(g['energy_error'])}.")
    a = sec["accretion"]
    theirs = a["runs"]["rebound"]["merges"]
    parts.append(
        f"In the disk REBOUND merges {theirs} times; the engine's end-of-step run shares the "
        f"first {a['identical_end']} of them and its default run the first "
        f"{a['identical_contact']}"
        + (" (found at the moment of contact, a merge can fall a step earlier than REBOUND's "
           "end-of-step search finds it, and from then on the chaotic disk goes its own way)"
           if a["identical_contact"] < theirs else "")
        + "; merges over the whole run: "
        f"{', '.join(str(r['merges']) for r in a['runs'].values())} (REBOUND, end, "
        f"contact). Through them mass is kept to {f(a['contact_conservation']['mass'])}, "
        f"momentum to {f(a['contact_conservation']['momentum'])} and charge to "
        f"{f(a['contact_conservation']['charge'])}; the energy plus the ledger to "
        f"{f(a['contact_conservation']['energy_with_ledger'])} (leapfrog's own error) where "
        f"the energy alone changes by {f(a['contact_conservation']['energy_without_ledger'])}.")
    return "**Findings.** " + " ".join(parts)


def section_glance(res, level):
    """The headline numbers, each taken from the sections below."""
    lines = ["## At a glance", ""]
    if "crosscheck" in res:
        c = res["crosscheck"]
        worst = max(max(v["max_rel_pos_difference"], v["max_rel_vel_difference"])
                    for v in c.values())
        lines.append(f"- **Same algorithm, two codes**: the engine's `leapfrog` and REBOUND's "
                     f"`leapfrog` agree to {f(worst)} (largest relative difference, up to "
                     f"{max(v['steps'] for v in c.values())} steps; round-off, section 1).")
    if "two_body" in res:
        e = res["two_body"].get("kepler_e0.5")
        n_mid = level.tb_steps_per_orbit[min(1, len(level.tb_steps_per_orbit) - 1)]
        if e:
            idx = min(1, len(e["checkpoints"]) - 1)
            cells = []
            for name in engine.integrators.GENERAL:
                key, val = ("tolerance", level.tb_tolerances[len(level.tb_tolerances) // 2]) \
                    if name == "rk45" else ("steps_per_orbit", n_mid)
                err = _err_at(e, f"engine:{name}", key, val, idx)
                cells.append(f"{name} {f(err)}" + (f" (tol {val:g})" if name == "rk45" else ""))
            lines.append(f"- **Kepler e = 0.5**, relative position error after "
                         f"{e['checkpoints'][idx]} orbits at {n_mid} steps per orbit: "
                         + ", ".join(cells) + " (section 2).")
    if "energy_drift" in res:
        k = res["energy_drift"].get("kepler")
        if k:
            cells = [f"{label_of(r['method'])} ({r['setting']}) {expo(r['growth_exponent'])} "
                     f"{r['class']}" for r in k["runs"]]
            lines.append("- **Energy-error growth exponents**, Kepler e = 0.6 over "
                         f"{level.drift_orbits:g} orbits: " + "; ".join(cells) + " (section 3).")
    if "hard_cases" in res:
        lim = res["hard_cases"]["spring_limits"]
        cells = []
        for name, v in lim.items():
            ms = [m["limit"] for m in v["measured"].values() if m.get("limit")]
            if ms and v["theory"] is not None:
                cells.append(f"{name} {g(min(ms), 6)} (theory {g(v['theory'], 6)})")
        lines.append("- **Stiff spring, largest stable omega dt** (smallest over the stiffnesses "
                     "tried): " + ", ".join(cells) + "; so dt < 2/omega for leapfrog, Verlet and "
                     "symplectic Euler (section 5).")
    if "contact" in res:
        a = res["contact"]["accretion"]
        zs = ", ".join(f"{name} Z {g['z']:.3f} against {g['z_expected']:.3f}"
                       for name, g in res["contact"]["gas"].items())
        lines.append(f"- **Contact**: hard-sphere gases relax to Maxwell-Boltzmann, {zs}; an "
                     f"accreting disk merges as REBOUND's line search does, the first "
                     f"{a['identical_end']} of {a['runs']['rebound']['merges']} merges identical "
                     f"(section 7).")
    lines.append("")
    if "work_precision" in res:
        wp = res["work_precision"]
        levels = [row["level"] for row in next(iter(wp.values()))["cheapest"]]
        rows = []
        for key, e in wp.items():
            cells = [e["title"]]
            for row in e["cheapest"]:
                b = row["fastest_engine"]
                cells.append("—" if b is None else f"{b['method'].split(':')[1]} "
                             f"({b['setting']}, {seconds(b['time_s'])})")
            rows.append(cells)
        lines.append("**Which engine integrator to choose**: the fastest engine run that reached "
                     "each error level in the work-precision sweeps (section 4; the error measure "
                     "of each problem is defined there, — = no engine run got there):")
        lines.append("")
        lines.append(table(["problem"] + [f"error <= {f(l, 1)}" for l in levels], rows))
        lines.append("")
        cells = [(e["title"], row) for e in wp.values() for row in e.get("versus", [])
                 if row["ratio"] is not None and not row["below_reference_floor"]]
        if cells:
            worst_title, worst = max(cells, key=lambda c: c[1]["ratio"])
            best_title, best = min(cells, key=lambda c: c[1]["ratio"])
            lines.append(
                f"**Engine best / REBOUND best** (wall time of the fastest engine run reaching an "
                f"error level over REBOUND's fastest, side by side; section 4): at most 1 in "
                f"{sum(1 for _, r in cells if r['ratio'] <= 1.0)} of {len(cells)} cells; from "
                f"{best['ratio']:.2f} ({best_title}, error <= {f(best['level'], 1)}) to "
                f"{worst['ratio']:.2f} ({worst_title}, error <= {f(worst['level'], 1)}).")
            lines.append("")
    if "hard_cases" in res:
        hc = res["hard_cases"]
        cases = [c for c in ("e099", "pythagorean", "figure_eight", "flyby", "coincident")
                 if c in hc["tables"]]
        rows = []
        for name in engine.integrators.GENERAL:
            cells = [name]
            for c in cases:
                tab = hc["tables"][c]
                runs = list(tab["fixed"].get(name, {}).values())
                if name == "rk45":
                    runs += [r for r in tab["adaptive"].values() if r.get("integrator") == "rk45"]
                counts = {}
                for r in runs:
                    counts[r["outcome"]] = counts.get(r["outcome"], 0) + 1
                cells.append(", ".join(f"{v} {k}" for k, v in sorted(counts.items())) or "—")
            out = hc["spring_outcomes"].get(name, {})
            cells.append(", ".join(f"k={k:g}: {v['outcome']}" for k, v in sorted(out.items())))
            rows.append(cells)
        lines.append("**Hard cases** (number of runs per outcome over the settings of section 5):")
        lines.append("")
        lines.append(table(["integrator"] + [hc["cases"][c]["title"] for c in cases]
                           + [f"stiff spring, dt = {hc['spring_dt']:g}"], rows))
        lines.append("")
    return "\n".join(lines)


# -- writing ---------------------------------------------------------------------------------------

def write(out_dir, res, level):
    os.makedirs(out_dir, exist_ok=True)
    figs = {}
    if "two_body" in res:
        n_mid = level.tb_steps_per_orbit[min(1, len(level.tb_steps_per_orbit) - 1)]
        plots.two_body_convergence(res["two_body"],
                                   os.path.join(out_dir, "two_body_convergence.png"))
        plots.two_body_growth(res["two_body"], os.path.join(out_dir, "two_body_growth.png"), n_mid)
    if "energy_drift" in res:
        plots.energy_drift(res["energy_drift"], os.path.join(out_dir, "energy_drift.png"))
    if "work_precision" in res:
        for key, entry in res["work_precision"].items():
            name = f"work_precision_{key}.png"
            plots.work_precision(entry, os.path.join(out_dir, name))
            figs[key] = name
    if "hard_cases" in res:
        plots.spring_limits(res["hard_cases"]["spring_limits"],
                            os.path.join(out_dir, "spring_limits.png"))
    if "tree" in res:
        plots.tree_error(res["tree"], os.path.join(out_dir, "tree_error.png"))
        plots.tree_time(res["tree"], os.path.join(out_dir, "tree_time.png"))
    if "contact" in res:
        plots.contact(res["contact"], os.path.join(out_dir, "contact.png"))
    atomic_write(os.path.join(out_dir, "results.json"), json.dumps(jsonable(res), indent=1) + "\n")
    atomic_write(os.path.join(out_dir, "report.md"), markdown(res, level, figs))


def output_files(sections=SECTIONS):
    """The files ``write`` produces in the output directory, with their kinds."""
    files = {"report.md": "markdown", "results.json": "json"}
    if "two_body" in sections:
        files["two_body_convergence.png"] = "png"
        files["two_body_growth.png"] = "png"
    if "energy_drift" in sections:
        files["energy_drift.png"] = "png"
    if "hard_cases" in sections:
        files["spring_limits.png"] = "png"
    if "tree" in sections:
        files["tree_error.png"] = "png"
        files["tree_time.png"] = "png"
    if "contact" in sections:
        files["contact.png"] = "png"
    return files


def check_outputs(out_dir, sections=SECTIONS):
    """Raise OutputPathError now if the report could not be written to ``out_dir`` later."""
    check_output_dir(out_dir)
    if os.path.isdir(out_dir):
        for name, kind in output_files(sections=sections).items():
            check_output_path(os.path.join(out_dir, name), kind)


def markdown(res, level, figs):
    m = res["meta"]
    t = res["timings"]
    parts = ["# Engine validation report", ""]
    parts.append(
        f"Generated by `python -m validation report` at level **{m['level']}** in "
        f"{seconds(t['wall_s'])} of wall time ({_untimed_where(m)} for the untimed "
        f"runs, then the timed sweeps one at a time). engine {m['engine_version']}, REBOUND "
        f"{m['rebound_version']}, numpy {m['numpy_version']}, numba {m['numba_version']}, Python "
        f"{m['python_version']}, {m['machine']}, {m['cpu_count']} cores. Every number below is "
        "in `results.json`.")
    parts.append("")
    parts.append("Contents: at a glance; 1. leapfrog cross-check with REBOUND; 2. two-body orbits; "
                 "3. energy drift; 4. work-precision (choosing an integrator); 5. hard cases; "
                 "6. Tree gravity (FMM and Barnes-Hut); 7. Contact: a hard-sphere gas and an "
                 "accreting disk.")
    parts.append("")
    parts.append(section_glance(res, level))
    if "crosscheck" in res:
        parts.append(section_crosscheck(res["crosscheck"]))
    if "two_body" in res:
        parts.append(section_two_body(res["two_body"], level, "two_body_convergence.png",
                                      "two_body_growth.png"))
    if "energy_drift" in res:
        parts.append(section_drift(res["energy_drift"], level, "energy_drift.png"))
    if "work_precision" in res:
        parts.append(section_work_precision(res["work_precision"], figs))
    if "hard_cases" in res:
        parts.append(section_hard_cases(res["hard_cases"], "spring_limits.png"))
    if "tree" in res:
        parts.append(section_tree(res["tree"], "tree_error.png", "tree_time.png"))
    if "contact" in res:
        parts.append(section_contact(res["contact"], "contact.png"))
    parts.append("## Reproducing")
    parts.append("")
    parts.append("```\npython -m validation report --out docs/validation          # this report\n"
                 "python -m validation report --out /tmp/validation --quick  # a few minutes\n```")
    parts.append("")
    return "\n".join(parts)


def _untimed_where(m):
    if m.get("scheduler"):
        return f"the Dask cluster at {m['scheduler']}"
    return f"{m['workers']} worker processes"


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="python -m validation report",
        description="Validate the engine against REBOUND and closed forms; write DIR/report.md, "
                    "its PNG plots and DIR/results.json.")
    parser.add_argument("--out", required=True, metavar="DIR", help="output directory")
    parser.add_argument("--quick", action="store_true",
                        help="shorter runs and sweeps: one to two minutes on 2 cores, and "
                             "a few more for the tree section (--only to leave it out)")
    parser.add_argument("--smoke", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--workers", type=int, default=2,
                        help="processes for the untimed runs (default 2)")
    parser.add_argument("--scheduler", default=None, metavar="ADDRESS",
                        help="run the untimed runs on a Dask cluster: its scheduler's address, or "
                             "'local' for a LocalCluster of this machine (default: "
                             "$DASK_SCHEDULER_ADDRESS, else --workers local processes); the "
                             "timed sweeps run here; needs the [cluster] extra")
    parser.add_argument("--only", default=",".join(SECTIONS),
                        help=f"comma-separated sections to run (default all: {','.join(SECTIONS)})")
    parser.add_argument("--no-progress", action="store_true", help="no progress bars")
    args = parser.parse_args(argv)
    level = LEVELS["smoke" if args.smoke else "quick" if args.quick else "full"]
    sections = tuple(s.strip() for s in args.only.split(",") if s.strip())
    unknown = set(sections) - set(SECTIONS)
    if unknown:
        parser.error(f"unknown section(s) {', '.join(sorted(unknown))}; "
                     f"choose from {', '.join(SECTIONS)}")
    try:
        check_outputs(args.out, sections)  # fail now, not after the runs
    except (OutputPathError, TypeError) as exc:
        parser.error(str(exc))
    from engine.cluster import CodeMismatch, SchedulerUnreachable

    try:
        res = collect(level, workers=max(1, args.workers), progress=not args.no_progress,
                      sections=sections, scheduler=args.scheduler)
    except (CodeMismatch, SchedulerUnreachable, ImportError) as exc:
        parser.exit(2, f"python -m validation report: error: {exc}\n")
    write(args.out, res, level)
    print(f"wrote {os.path.join(args.out, 'report.md')} ({seconds(res['timings']['wall_s'])})",
          file=sys.stderr)
    return 0
