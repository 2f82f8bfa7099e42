"""Section 9: the planetary integrators on the outer solar system (Sun, four giants and Pluto):
time per step of the engine's ``whfast`` with corrector 11 and of ``ias15`` (epsilon 1e-9)
against REBOUND's, side by side."""
import numpy as np

from .timing import per_step_side_by_side, repeats

NAME = "planets"
KEYS = ("planets",)
NEEDS = ("rebound",)


def run(quick):
    return {"planets": bench_planets(20_000 if quick else 100_000, 2e5 if quick else 1e6,
                                     repeats(quick))}


#: whfast's step on the outer solar system, in days (about 1/217 of Jupiter's period)
PLANETS_DT = 20.0
PLANETS_EPSILON = 1e-9


def _relative_difference(sim, run):
    """Largest position difference of the two codes' states over the largest coordinate."""
    pos, _ = run.state()
    return float(np.abs(sim.pos - pos).max() / np.abs(pos).max())


def bench_planets(steps, span_days, repeats):
    """The outer solar system of the report's work-precision section (Hairer, Lubich & Wanner;
    AU, days, solar masses), in both codes from the same heliocentric state.

    - ``whfast`` with corrector 11, dt = 20 days: ``sim.step(steps)`` against REBOUND's WHFast
      (corrector 11, Jacobi coordinates, ``safe_mode = 0``) ``steps(steps)`` followed by
      ``synchronize()``: both apply the corrector and synchronise once per call, REBOUND's
      fastest use of it (with ``safe_mode = 1`` it applies the corrector at every step);
    - ``ias15`` at epsilon 1e-9: ``sim.integrate(t + span)`` against REBOUND's
      ``integrate(t + span)``, per step each code took (their adaptive steps differ slightly).
    """
    from validation.problems import make_sim, outer_solar_system
    from validation.reference import RebRun

    p = outer_solar_system()
    rows = {}
    sim = make_sim(p, "whfast", PLANETS_DT, options={"corrector": 11})
    run = RebRun(p, "whfast", dt=PLANETS_DT, options={"corrector": 11, "safe_mode": 0})
    sim.step(10)  # compiled code loaded
    run.steps(10)

    def engine_whfast():
        sim.step(steps)
        return steps

    def rebound_whfast():
        run.steps(steps)
        return steps

    ours, ref, ratio = per_step_side_by_side(engine_whfast, rebound_whfast, repeats)
    rows["whfast_c11"] = {
        "method": "whfast, corrector 11", "dt_days": PLANETS_DT, "steps_per_call": steps,
        "engine_us_per_step": 1e6 * ours, "rebound_us_per_step": 1e6 * ref,
        "time_over_rebound": ratio, "steps_engine": sim.steps,
        "steps_rebound": int(run.sim.steps_done),
        "relative_position_difference": _relative_difference(sim, run)}

    sim = make_sim(p, "ias15", PLANETS_DT, tolerance=PLANETS_EPSILON)
    run = RebRun(p, "ias15", epsilon=PLANETS_EPSILON)
    sim.integrate(10 * PLANETS_DT)
    run.integrate(10 * PLANETS_DT)

    def engine_ias15():
        before = sim.steps
        sim.integrate(sim.t + span_days)
        return sim.steps - before

    def rebound_ias15():
        before = run.sim.steps_done
        run.integrate(run.t + span_days)
        return run.sim.steps_done - before

    ours, ref, ratio = per_step_side_by_side(engine_ias15, rebound_ias15, repeats)
    rows["ias15"] = {
        "method": f"ias15, epsilon {PLANETS_EPSILON:g}", "span_days_per_call": span_days,
        "engine_us_per_step": 1e6 * ours, "rebound_us_per_step": 1e6 * ref,
        "time_over_rebound": ratio, "steps_engine": sim.steps,
        "steps_rebound": int(run.sim.steps_done), "t_days": sim.t,
        "relative_position_difference": _relative_difference(sim, run)}
    return {"problem": "outer solar system (Sun, Jupiter, Saturn, Uranus, Neptune, Pluto)",
            "rows": rows}


def text(r):
    lines = []
    pl = r["planets"]
    lines.append(f"\n9. planetary integrators, {pl['problem']} (time per step, median of "
                 "side-by-side repetitions)")
    lines.append(f"{'method':<24}{'engine us/step':>16}{'REBOUND us/step':>17}"
                 f"{'engine/REBOUND':>16}{'same state to':>15}")
    for row in pl["rows"].values():
        lines.append(f"{row['method']:<24}{row['engine_us_per_step']:>16.2f}"
                     f"{row['rebound_us_per_step']:>17.2f}{row['time_over_rebound']:>16.2f}"
                     f"{row['relative_position_difference']:>15.1e}")
    return lines


def markdown(r):
    out = []
    pl = r["planets"]
    out += [f"## 9. Planetary integrators ({pl['problem']})", "",
            "Time per step, engine against REBOUND, from the same heliocentric state: "
            f"`whfast` with corrector 11 at dt = {PLANETS_DT:g} days (`sim.step(n)` against "
            "REBOUND's WHFast with corrector 11 in `safe_mode = 0`, `steps(n)` then "
            "`synchronize()`: both apply the corrector and synchronise once per call), and "
            f"`ias15` at epsilon {PLANETS_EPSILON:g} (`integrate` over the same span, per "
            "step each code took). The last column is the largest difference of the two "
            "codes' final positions over the largest coordinate.", "",
            "| method | engine us/step | REBOUND us/step | engine / REBOUND | same state to |",
            "|---|---|---|---|---|"]
    out += [f"| {row['method']} | {row['engine_us_per_step']:.2f} | "
            f"{row['rebound_us_per_step']:.2f} | {row['time_over_rebound']:.2f} | "
            f"{row['relative_position_difference']:.1e} |" for row in pl["rows"].values()]
    out.append("")
    return out


def targets(r):
    rows = []
    for key, row in r.get("planets", {}).get("rows", {}).items():
        rows.append((f"outer solar system, {row['method']}: time per step at most 0.5 of "
                     "REBOUND's", f"{row['time_over_rebound']:.2f} of REBOUND's "
                     f"({row['engine_us_per_step']:.2f} us vs {row['rebound_us_per_step']:.2f} us)",
                     row["time_over_rebound"] <= 0.5))
    return rows
