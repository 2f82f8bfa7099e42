"""Section 4: work-precision, every method's error against its cost, and the engine's best
against REBOUND's best (the sweeps: ``validation.work_precision``)."""
import os

from .. import plots as draw
from .. import work_precision
from ..jobs import run_jobs
from .text import f, g, label_of, seconds, table

NAME = "work_precision"
CONTENTS = "4. work-precision (choosing an integrator)"
PHASE = "timed"
FIGURES = {}  # one a problem, named after it: ``plots``


def jobs(level):
    """The untimed part: each problem's reference solution."""
    return work_precision.reference_jobs(level)


def gather(level, results, progress):
    """The timed sweeps, one at a time in this process, from the references in ``results``;
    then the engine's best and REBOUND's best timed again side by side."""
    timed = work_precision.timed_jobs(level)
    for job in timed:
        job.kwargs.update(ref=results[("wp_ref", job.key[1])], level=level)
    sweep_results, _ = run_jobs(timed, workers=1, desc="timed sweeps", disable=not progress)
    sec = work_precision.assemble(level, results, sweep_results)
    work_precision.head_to_head(level, sec)
    return sec


def plots(sec, level, out_dir):
    figs = {}
    for key, entry in sec.items():
        name = f"work_precision_{key}.png"
        draw.work_precision(entry, os.path.join(out_dir, name))
        figs[key] = name
    return figs


def markdown(sec, level, figs):
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
    lines.append(versus_summary(sec))
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
        lines.append(findings(e, failures))
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


def versus_summary(sec):
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
        "faster; bold: REBOUND is faster. The goal is at most 1 everywhere: the engine's best "
        "at least as fast as REBOUND's best.")
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


def findings(e, failures):
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


def glance(sec, level):
    """No line of its own; the table of the fastest engine run per error level, and the span of
    the engine best / REBOUND best ratios."""
    levels = [row["level"] for row in next(iter(sec.values()))["cheapest"]]
    rows = []
    for key, e in sec.items():
        cells = [e["title"]]
        for row in e["cheapest"]:
            b = row["fastest_engine"]
            cells.append("—" if b is None else f"{b['method'].split(':')[1]} "
                         f"({b['setting']}, {seconds(b['time_s'])})")
        rows.append(cells)
    lines = ["**Which engine integrator to choose**: the fastest engine run that reached "
             "each error level in the work-precision sweeps (section 4; the error measure "
             "of each problem is defined there, — = no engine run got there):"]
    lines.append("")
    lines.append(table(["problem"] + [f"error <= {f(l, 1)}" for l in levels], rows))
    lines.append("")
    cells = [(e["title"], row) for e in sec.values() for row in e.get("versus", [])
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
    return [], lines
