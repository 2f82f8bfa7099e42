"""Section 5: hard cases, which integrators stay stable, become inaccurate or blow up (the
runs: ``validation.hard_cases``)."""
import math
import os

import engine

from .. import hard_cases
from .. import plots as draw
from .text import f, g, table

NAME = "hard_cases"
CONTENTS = "5. hard cases"
PHASE = "untimed"
FIGURES = {"spring": "spring_limits.png"}
jobs = hard_cases.jobs  # its untimed runs


def gather(level, results, progress):
    return hard_cases.assemble(level, results)


def plots(sec, level, out_dir):
    draw.spring_limits(sec["spring_limits"], os.path.join(out_dir, FIGURES["spring"]))
    return dict(FIGURES)


def markdown(sec, level, figs):
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
        lines.append(findings(case, sec))
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
    lines.append(f"![stiff spring stability limits]({figs['spring']})")
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
    lines.append(findings("spring", sec))
    lines.append("")
    return "\n".join(lines)


def findings(case, sec):
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


def glance(sec, level):
    """A line of the stiff spring's limits, and a table of the outcomes per integrator."""
    cells = []
    for name, v in sec["spring_limits"].items():
        ms = [m["limit"] for m in v["measured"].values() if m.get("limit")]
        if ms and v["theory"] is not None:
            cells.append(f"{name} {g(min(ms), 6)} (theory {g(v['theory'], 6)})")
    line = ("- **Stiff spring, largest stable omega dt** (smallest over the stiffnesses "
            "tried): " + ", ".join(cells) + "; so dt < 2/omega for leapfrog, Verlet and "
            "symplectic Euler (section 5).")
    cases = [c for c in ("e099", "pythagorean", "figure_eight", "flyby", "coincident")
             if c in sec["tables"]]
    rows = []
    for name in engine.integrators.GENERAL:
        cells = [name]
        for c in cases:
            tab = sec["tables"][c]
            runs = list(tab["fixed"].get(name, {}).values())
            if name == "rk45":
                runs += [r for r in tab["adaptive"].values() if r.get("integrator") == "rk45"]
            counts = {}
            for r in runs:
                counts[r["outcome"]] = counts.get(r["outcome"], 0) + 1
            cells.append(", ".join(f"{v} {k}" for k, v in sorted(counts.items())) or "—")
        out = sec["spring_outcomes"].get(name, {})
        cells.append(", ".join(f"k={k:g}: {v['outcome']}" for k, v in sorted(out.items())))
        rows.append(cells)
    tables = ["**Hard cases** (number of runs per outcome over the settings of section 5):", ""]
    tables.append(table(["integrator"] + [sec["cases"][c]["title"] for c in cases]
                        + [f"stiff spring, dt = {sec['spring_dt']:g}"], rows))
    tables.append("")
    return [line], tables
