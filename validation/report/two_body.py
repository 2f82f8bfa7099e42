"""Section 2: two-body orbits against the Kepler solution and REBOUND IAS15 (the runs:
``validation.two_body``)."""
import math
import os

import engine

from .. import plots as draw
from .. import two_body
from .text import f, table

NAME = "two_body"
CONTENTS = "2. two-body orbits"
PHASE = "untimed"
FIGURES = {"convergence": "two_body_convergence.png", "growth": "two_body_growth.png"}
jobs = two_body.jobs  # its untimed runs


def gather(level, results, progress):
    return two_body.assemble(level, results)


def middle_steps(level):
    """The steps per orbit the findings, the growth plot and the glance quote: the second
    setting (the only one at a level with one)."""
    return level.tb_steps_per_orbit[min(1, len(level.tb_steps_per_orbit) - 1)]


def plots(sec, level, out_dir):
    draw.two_body_convergence(sec, os.path.join(out_dir, FIGURES["convergence"]))
    draw.two_body_growth(sec, os.path.join(out_dir, FIGURES["growth"]), middle_steps(level))
    return dict(FIGURES)


def markdown(sec, level, figs):
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
    lines.append(f"![position error after {cp} P against steps per P]({figs['convergence']})")
    lines.append("")
    lines.append(f"![position error against time]({figs['growth']})")
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
    lines.append(findings(sec, level))
    lines.append("")
    return "\n".join(lines)


def _err_at(entry, method, setting_key, setting, idx, ref="kepler"):
    for run in entry["runs"]:
        if run["method"] == method and run.get(setting_key) == setting:
            vals = run[f"pos_err_{ref}"]
            return vals[idx] if idx < len(vals) else None
    return None


def findings(sec, level):
    n_mid = middle_steps(level)
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


def glance(sec, level):
    e = sec.get("kepler_e0.5")
    if not e:
        return [], []
    n_mid = middle_steps(level)
    idx = min(1, len(e["checkpoints"]) - 1)
    cells = []
    for name in engine.integrators.GENERAL:
        key, val = ("tolerance", level.tb_tolerances[len(level.tb_tolerances) // 2]) \
            if name == "rk45" else ("steps_per_orbit", n_mid)
        err = _err_at(e, f"engine:{name}", key, val, idx)
        cells.append(f"{name} {f(err)}" + (f" (tol {val:g})" if name == "rk45" else ""))
    return [f"- **Kepler e = 0.5**, relative position error after "
            f"{e['checkpoints'][idx]} orbits at {n_mid} steps per orbit: "
            + ", ".join(cells) + " (section 2)."], []
