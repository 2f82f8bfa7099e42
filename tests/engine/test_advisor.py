"""engine.advise: on the four problems of the issue (the outer solar system over 1e5 days, Kepler
e = 0.9 over 100 orbits, a star with 200 test particles over 20 orbits, the Pythagorean problem
to t = 30), at several error levels, with all candidates and with those that take any scene
(no whfast, saba), the advised setting run to t_end must reach the requested error (within 2x;
documented: 1.9x) at a cost within 1.3x (documented: 1.22x) of the cheapest setting a small full
sweep finds.

The sweep runs every candidate method to t_end at step counts 1, 2, 4, 8, ... over the span
(adaptive methods at tolerances 1e-3, 1e-4, ...), from coarse to fine, and keeps the first
that meets the error: the cheapest of those over all methods is the sweep's best. Cost is the
advisor's deterministic work (force evaluations times pairs, plus Kepler drifts for whfast
and saba: ``engine.advisor.run_work``), never wall time. The error at t_end is measured
against the closed form (Kepler) or against ``ias15`` at epsilon 1e-12 (the others), with the
same metric the advisor is given.
"""
import math

import numpy as np
import pytest

import engine
from engine import SimulationError, analytic
from engine.advisor import CANDIDATES, SEARCH_ORDER, advise, clone_simulation, run_work
from validation import advise as cli
from validation import problems

SWEEP_TOLERANCES = tuple(10.0 ** -k for k in range(3, 15))


@pytest.fixture(autouse=True, scope="module")
def one_thread():
    """The 200-particle scene takes the engine's parallel pair kernel; on a machine shared
    with other jobs its threads wait on each other (a run measured 20 times slower), and
    nothing here depends on the thread count (costs are counted, not timed)."""
    import numba

    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    yield
    numba.set_num_threads(threads)
MAX_SWEEP_STEPS = 2 ** 22


def _error(sim, ref_pos, e0, metric, length):
    if metric == "energy":
        return abs(sim.energy() - e0) / abs(e0)
    d = sim.pos - ref_pos
    return float(np.sqrt((d * d).sum(axis=1)).max()) / length


def _run(base, method, options, t_end, dt=None, tolerance=None):
    sim = clone_simulation(base, method, dt=dt if dt is not None else (t_end - base.t) / 1000,
                           **options)
    if tolerance is not None:
        sim.tolerance = tolerance
    try:
        sim.integrate(t_end)
    except SimulationError:
        return None
    return sim


def sweep(base, t_end, target, ref_pos, metric, length, methods=None):
    """The cheapest (work, label, setting, error) meeting ``target`` over the sweep."""
    e0 = base.energy()
    span = t_end - base.t
    best = (math.inf, None, None, None)
    by_label = {engine.advisor.label(m, o): (m, o) for m, o in CANDIDATES}
    for label in SEARCH_ORDER:
        method, options = by_label[label]
        if methods is not None and method not in methods:
            continue
        probe = clone_simulation(base, method, dt=span / 1000, **options)
        try:
            probe.step(1)
        except ValueError:
            continue  # no dominant mass: this candidate cannot run the scene
        if method in engine.ADAPTIVE_INTEGRATORS:
            for tol in SWEEP_TOLERANCES:
                sim = _run(base, method, options, t_end, tolerance=tol)
                if sim is None:
                    continue
                work = run_work(sim)
                if work >= best[0]:
                    break
                err = _error(sim, ref_pos, e0, metric, length)
                if err <= target:
                    best = (work, label, tol, err)
                    break
            continue
        per_step = engine.advisor.step_work(probe, method, options)
        n = 1
        while n <= MAX_SWEEP_STEPS and n * per_step < best[0]:
            sim = _run(base, method, options, t_end, dt=span / n)
            if sim is not None:
                err = _error(sim, ref_pos, e0, metric, length)
                if err <= target:
                    best = (run_work(sim), label, span / n, err)
                    break
            n *= 2
    return best


def reference(problem, base, t_end):
    if problem.reference == "kepler":
        r, _ = analytic.kepler(problem.pos[0], problem.vel[0], problem.extra["mu"], t_end)
        return np.array([r])
    ref = clone_simulation(base, "ias15", dt=(t_end - base.t) / 1e4, tolerance=1e-12)
    ref.integrate(t_end)
    return ref.pos.copy()


def check_problem(problem, t_end, target, metric, methods=None):
    base = cli.make_sim(problem)
    length = problem.length
    ref_pos = reference(problem, base, t_end)
    advice = advise(base, t_end, target, metric=metric,
                    length=length if metric == "position" else None, methods=methods)
    assert advice.reached, advice.table()
    run = clone_simulation(base, **advice.simulation_options())
    run.integrate(t_end)
    actual_error = _error(run, ref_pos, base.energy(), metric, length)
    actual_work = run_work(run)
    best_work, best_label, best_setting, best_error = sweep(base, t_end, target, ref_pos,
                                                           metric, length, methods)
    figures = (f"{problem.key}: advisor {advice.label} setting "
               f"{advice.tolerance or advice.dt:.4g} work {actual_work:.4g} error "
               f"{actual_error:.3g} (predicted {advice.error:.3g}); sweep best {best_label} "
               f"{best_setting:.4g} work {best_work:.4g} error {best_error:.3g}; advisor "
               f"{advice.advisor_seconds:.2f} s work {advice.advisor_work:.4g}\n"
               + advice.table())
    print(figures)
    # docs/engine.md and engine/advisor.py: at most 1.9 (1.86) times the requested error, at
    # 0.62 to 1.22 times the sweep's cheapest work, over the 31 cases of the advisor's harness.
    # Measured on the development machine in this file's 11 cases: error/target 0.0 to 1.86 (the
    # outer solar system at 1e-5), work/best 0.62 to 1.05. Bounded at the documented figures
    # with small margins (costs are counted work, never time: these are deterministic).
    assert actual_error <= 2.0 * target, figures
    assert actual_work <= 1.3 * best_work, figures
    return advice


ANY_SCENE = engine.integrators.ANY_SCENE  # without whfast and saba


@pytest.mark.parametrize("error, methods", [(1e-5, None), (1e-9, None), (1e-3, ANY_SCENE)])
def test_outer_solar_system_1e5_days(error, methods):
    """Sun, the four giants and Pluto over 1e5 days (23 Jupiter orbits); pilots over 4."""
    problem = problems.outer_solar_system(1.0e5)
    check_problem(problem, problem.t_end, error, "position", methods)


@pytest.mark.parametrize("error, methods", [(1e-6, None), (1e-5, ANY_SCENE),
                                            (1e-9, ANY_SCENE)])
def test_kepler_e09_100_orbits(error, methods):
    """whfast is exact on a two-body problem (one step over the whole span); without it the
    pilots' errors (over 4 orbits) are extrapolated 25 times."""
    problem = problems.kepler(0.9, 100.0)
    check_problem(problem, problem.t_end, error, "position", methods)


@pytest.mark.parametrize("error, methods", [(1e-6, None), (1e-3, ANY_SCENE),
                                            (1e-7, ANY_SCENE)])
def test_star_with_200_test_particles_20_orbits(error, methods):
    problem = cli.star_with_test_particles(200, 20.0)
    check_problem(problem, problem.t_end, error, "position", methods)


@pytest.mark.parametrize("error", [1e-3, 1e-7])
def test_pythagorean_to_30(error):
    """Close encounters up to t = 30 (the scout finds them): the pilots run the whole span.
    The positions are chaotic, the energy error is compared (as in the validation report)."""
    advice = check_problem(problems.pythagorean(30.0), 30.0, error, "energy")
    assert advice.pilot_span == 30.0
    assert any("close encounters" in note for note in advice.notes)


# -- the pieces --------------------------------------------------------------------------------

def test_time_scale_is_the_osculating_period():
    kepler = cli.make_sim(problems.kepler(0.9))  # starts at pericentre, r = 0.1
    assert engine.advisor.time_scale(kepler) == pytest.approx(2.0 * math.pi, rel=1e-12)
    solar = cli.make_sim(problems.outer_solar_system())
    assert engine.advisor.time_scale(solar) == pytest.approx(4332.59, rel=0.02)  # Jupiter


def test_default_length_is_the_extent_of_the_orbit():
    """Without ``length`` the position error is relative to the scene's extent, here the
    apocentre distance 1 + e = 1.9 that the reference passes through."""
    sim = cli.make_sim(problems.kepler(0.9))
    advice = advise(sim, 10 * 2 * math.pi, 1e-4)
    assert advice.length == pytest.approx(1.9, rel=1e-6)


def test_methods_without_a_dominant_mass_are_skipped_with_the_reason():
    sim = cli.make_sim(problems.pythagorean(5.0))
    advice = advise(sim, 5.0, 1e-4, metric="energy", methods=["whfast", "ias15", "saba"])
    labels = [c.label for c in advice.candidates]  # in the order of engine.INTEGRATORS
    assert labels == ["whfast corrector=0", "whfast corrector=11", "whfast corrector=17",
                      "saba SABA(10,6,4)", "ias15"]
    for c in advice.candidates[:4]:
        assert c.skipped is not None and "dominant mass" in c.skipped
        assert not c.verified and math.isnan(c.work)
    assert advice.method == "ias15" and advice.reached and advice.chosen.verified
    assert advice.candidates[4].skipped is None
    assert "skipped: whfast needs a dominant mass" in advice.table()


def test_advice_is_deterministic():
    """Ranked by work (the default), the same scene gets the same advice."""
    sim = cli.make_sim(problems.kepler(0.5))
    a = advise(sim, 20 * 2 * math.pi, 1e-5, methods=engine.integrators.GENERAL)
    b = advise(sim, 20 * 2 * math.pi, 1e-5, methods=engine.integrators.GENERAL)
    assert (a.method, a.dt, a.tolerance, a.work, a.error) == \
        (b.method, b.dt, b.tolerance, b.work, b.error)
    assert [(c.label, c.setting, c.work, c.error, c.pilots) for c in a.candidates] == \
        [(c.label, c.setting, c.work, c.error, c.pilots) for c in b.candidates]


def _snapshot(sim):
    return (sim.pos.tobytes(), sim.vel.tobytes(), sim.mass.tobytes(), sim.charge.tobytes(),
            sim.radius.tobytes(), np.asarray(sim.active).tobytes(), sim.t, sim.dt, sim.steps,
            sim.integrator, sim.tolerance, sim.corrector, sim.kernel, sim.saba,
            sim.janus_order, sim.janus_lattice, sim.G, sim.n, tuple(map(id, sim.forces)),
            tuple(map(repr, sim.forces)), sim.potential_energy_terms().tobytes())


def test_the_users_simulation_is_unchanged():
    problem = problems.outer_solar_system()
    sim = cli.make_sim(problem, "whfast", 50.0, corrector=11)
    sim.step(7)
    twin = clone_simulation(sim)
    before = _snapshot(sim)
    advise(sim, sim.t + 5000.0, 1e-5, length=problem.length)
    assert _snapshot(sim) == before
    # and it steps on exactly as an untouched copy does
    sim.step(20)
    twin.step(20)
    assert sim.pos.tobytes() == twin.pos.tobytes() and sim.vel.tobytes() == twin.vel.tobytes()


@pytest.mark.parametrize("kwargs, field, value", [
    ({"error": -1e-6}, "error", "-1e-06"),
    ({"error": 0.0}, "error", "0.0"),
    ({"error": math.nan}, "error", "nan"),
    ({"t_end": math.inf}, "t_end", "inf"),
    ({"t_end": -math.inf}, "t_end", "-inf"),
    ({"t_end": math.nan}, "t_end", "nan"),
    ({"t_end": 0.0}, "t_end", "0.0"),
    ({"metric": "phase"}, "metric", "'phase'"),
    ({"rank": "speed"}, "rank", "'speed'"),
    ({"length": -1.0}, "length", "-1.0"),
    ({"methods": ["leapfrog", "rk5"]}, "methods", "'rk5'"),
])
def test_bad_input_names_the_field_and_value(kwargs, field, value):
    sim = cli.make_sim(problems.kepler(0.5))
    before = _snapshot(sim)
    args = {"t_end": 10.0, "error": 1e-6, **kwargs}
    with pytest.raises(ValueError) as info:
        advise(sim, args.pop("t_end"), args.pop("error"), **args)
    assert field in str(info.value) and value in str(info.value)
    assert _snapshot(sim) == before


def test_energy_metric_needs_conservative_forces():
    sim = cli.make_sim(problems.kepler(0.5))
    sim.add_force(engine.forces.Drag(linear=0.01))
    with pytest.raises(ValueError, match="metric='energy'.*Drag"):
        advise(sim, 10.0, 1e-6, metric="energy")


def test_rank_by_time_picks_the_fastest_measured():
    sim = cli.make_sim(problems.kepler(0.5))
    advice = advise(sim, 20 * 2 * math.pi, 1e-5, rank="time")
    verified = [c for c in advice.candidates if c.verified]
    assert advice.chosen.verified and math.isfinite(advice.seconds)
    assert advice.seconds == min(c.seconds for c in verified)


def test_command_line_prints_the_table(capsys, tmp_path):
    import json

    from validation.__main__ import main
    out_json = tmp_path / "advice.json"
    assert main(["advise", "--problem", "kepler_e0.9", "--t-end", str(20 * 2 * math.pi),
                 "--error", "1e-6", "--json", str(out_json)]) == 0
    data = json.loads(out_json.read_text())
    assert data["method"] == "whfast" and data["reached"] is True
    assert len(data["candidates"]) == len(CANDIDATES)
    out = capsys.readouterr().out
    assert "recommended: whfast" in out
    for label, _ in ((engine.advisor.label(m, o), o) for m, o in CANDIDATES):
        assert label in out
    with pytest.raises(SystemExit):
        main(["advise", "--problem", "no_such_problem", "--error", "1e-6"])
    with pytest.raises(SystemExit):
        main(["advise", "--problem", "kepler_e0.9", "--error", "-1"])
    assert "error must be > 0, got -1.0" in capsys.readouterr().err
