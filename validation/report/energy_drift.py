"""Section 3: the energy error against time and its growth exponent (the runs:
``validation.energy_drift``)."""
import os

import engine

from .. import energy_drift
from .. import plots as draw
from .text import expo, f, g, label_of, table

NAME = "energy_drift"
CONTENTS = "3. energy drift"
PHASE = "untimed"
FIGURES = {"drift": "energy_drift.png"}
jobs = energy_drift.jobs  # its untimed runs


def gather(level, results, progress):
    return energy_drift.assemble(level, results)


def plots(sec, level, out_dir):
    draw.energy_drift(sec, os.path.join(out_dir, FIGURES["drift"]))
    return dict(FIGURES)


def markdown(sec, level, figs):
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
        f"last {energy_drift.FIT_DECADES:g} decades of the run (ending where the error first "
        f"passes {energy_drift.DESTROYED:g}: the orbit is then no longer the one it started "
        "on). Classes: < 0.25 bounded; 0.25-0.75 a "
        "round-off random walk if the error is below 1e-11 (Brouwer's law, t^1/2), otherwise "
        "sublinear growth; 0.75-1.25 linear drift; > 1.25 faster than linear; too short to fit "
        "when the error passes the threshold before the window spans a decade.")
    lines.append("")
    lines.append(f"![energy error against time]({figs['drift']})")
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
    lines.append(findings(sec))
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


def findings(sec):
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
                             f"{energy_drift.DESTROYED:g} at t = {when} "
                             f"{entry['time_unit_name']}s; its fit ends there.")
    return "**Findings.** " + " ".join(parts)


def glance(sec, level):
    k = sec.get("kepler")
    if not k:
        return [], []
    cells = [f"{label_of(r['method'])} ({r['setting']}) {expo(r['growth_exponent'])} "
             f"{r['class']}" for r in k["runs"]]
    return ["- **Energy-error growth exponents**, Kepler e = 0.6 over "
            f"{level.drift_orbits:g} orbits: " + "; ".join(cells) + " (section 3)."], []
