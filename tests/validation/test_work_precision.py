"""Work-precision sweeps: the planetary integrators on both sides, the skips, and the
"engine best / REBOUND best" table."""
import math

import pytest

from validation import bench, report, work_precision
from validation.problems import figure_eight, kepler, outer_solar_system
from validation.settings import LEVELS

SMOKE = LEVELS["smoke"]


@pytest.fixture
def rebound():
    """REBOUND, for the tests that run it (through validation's sweeps and bench): imported
    here, not at module level, so that the others run without it."""
    return pytest.importorskip("rebound")


# -- the new methods in a sweep --------------------------------------------------------------------

def _sweep_all(problem, level=SMOKE):
    ref = work_precision.reference_job(problem)
    results = {}
    for m in work_precision.ENGINE_METHODS:
        results[("wp", problem.key, "engine", m.name)] = work_precision.sweep_engine(problem, m.name, ref,
                                                                              level)
    for m in work_precision.REBOUND_METHOD_LIST:
        results[("wp", problem.key, "rebound", m.name)] = work_precision.sweep_rebound(problem, m.name,
                                                                                ref, level)
    return work_precision.assemble_problem(problem, ref, results)


def test_new_methods_are_swept_on_both_sides(rebound):
    entry = _sweep_all(kepler(0.6, t_end_orbits=2.0))
    methods = {r["method"] for r in entry["runs"]}
    for name in ("whfast", "whfast_c11", "whfast_c17", "saba", "sabac4", "ias15", "janus"):
        assert f"engine:{name}" in methods
    for name in ("whfast", "whfast_c11", "whfast_c17", "saba", "sabac4", "ias15"):
        assert f"rebound:{name}" in methods
    assert entry["skipped"] == []
    by = {}
    for r in entry["runs"]:
        by.setdefault(r["method"], []).append(r)
    # a Kepler orbit about a fixed centre is whfast's drift alone: exact at any step
    assert by["engine:whfast_c11"][0]["error"] < 1e-11
    assert by["engine:whfast_c11"][0]["setting_label"] == "N = 100"
    # the adaptive methods sweep epsilon, and IAS15's force evaluations are counted, not assumed
    ias = by["engine:ias15"]
    assert [r["setting_label"] for r in ias] == [f"eps {e:g}" for e in SMOKE.wp_ias15_epsilons]
    assert ias[-1]["error"] < ias[0]["error"]
    assert all(r["evaluations"] > 8 * r["steps"] for r in ias)
    # SABAC4: four kicks and the lazy corrector's two per step
    sabac4 = by["engine:sabac4"][0]
    assert sabac4["evaluations"] == 6 * sabac4["steps"]
    # REBOUND's corrector costs per run, not per step: counted by its callback
    c11 = by["rebound:whfast_c11"][0]
    assert c11["evaluations"] - c11["steps"] == 40
    # the table has an engine and a REBOUND side at every level this short run reaches
    row = entry["versus"][1]  # 1e-4
    assert row["engine"] is not None and row["rebound"] is not None
    assert row["ratio"] == pytest.approx(row["engine"]["time_s"] / row["rebound"]["time_s"])


def test_whfast_and_saba_are_skipped_without_a_dominant_mass(rebound):
    p = figure_eight(periods=1.0)
    ref = {"floor": 1e-12}  # never read: the methods are refused before any run
    for name in ("whfast", "whfast_c11", "saba", "sabac4"):
        res = work_precision.sweep_engine(p, name, ref, SMOKE)
        assert res["points"] == []
        assert "dominant mass" in res["skipped"]
    for name in ("whfast_c11", "whfast_c17", "sabac4"):
        res = work_precision.sweep_rebound(p, name, ref, SMOKE)
        assert res["points"] == [] and "dominant mass" in res["skipped"]
    # a general method is not skipped, and a skip reaches the report
    results = {("wp", p.key, "engine", "whfast"): work_precision.sweep_engine(p, "whfast", ref, SMOKE),
               ("wp", p.key, "rebound", "sabac4"): work_precision.sweep_rebound(p, "sabac4", ref,
                                                                         SMOKE)}
    ref = work_precision.reference_job(p)
    results[("wp", p.key, "engine", "leapfrog")] = work_precision.sweep_engine(p, "leapfrog", ref, SMOKE)
    entry = work_precision.assemble_problem(p, ref, results)
    assert [s["method"] for s in entry["skipped"]] == ["engine:whfast", "rebound:sabac4"]
    assert {r["method"] for r in entry["runs"]} == {"engine:leapfrog"}
    text = report.skipped_text(entry["skipped"])
    assert "whfast (refused by the engine: needs a dominant mass" in text
    assert "REBOUND sabac4 (no dominant mass" in text


def test_a_problem_with_a_dominant_mass_is_not_refused():
    assert work_precision.dominant_mass_refusal(outer_solar_system(1e3)) is None
    assert "dominant mass" in work_precision.dominant_mass_refusal(figure_eight(periods=1.0))


# -- the table, from made-up points ----------------------------------------------------------------

def _run(code, name, time_s, error, evaluations=100, setting=100):
    return {"code": code, "method": f"{code}:{name}", "time_s": time_s, "error": error,
            "evaluations": evaluations, "setting": setting, "setting_label": f"N = {setting}",
            "steps": setting, "status": "ok" if error is not None else "SimulationError"}


def test_versus_picks_the_fastest_run_of_each_code_that_reaches_the_level():
    runs = [
        _run("engine", "leapfrog", 0.001, 1e-3),       # fastest engine run, but only 1e-3
        _run("engine", "whfast", 0.004, 1e-7, setting=200),
        _run("engine", "whfast_c11", 0.003, 1e-9, setting=300),   # cheaper AND better
        _run("engine", "rk4", 0.0001, None),           # failed: never picked
        _run("rebound", "whfast", 0.002, 5e-7),
        _run("rebound", "ias15", 0.006, 1e-11, setting=1e-9),
        _run("rebound", "leapfrog", 0.0005, float("nan")),  # non-finite error: never picked
    ]
    rows = {row["level"]: row for row in work_precision.versus(runs, levels=(1e-2, 1e-6, 1e-8, 1e-10,
                                                                     1e-12), floor=1e-11)}
    r = rows[1e-2]
    assert r["engine"]["method"] == "engine:leapfrog"
    assert r["rebound"]["method"] == "rebound:whfast"
    assert r["ratio"] == pytest.approx(0.5)
    r = rows[1e-6]
    assert r["engine"]["method"] == "engine:whfast_c11" and r["engine"]["setting_value"] == 300
    assert r["rebound"]["method"] == "rebound:whfast"
    assert r["ratio"] == pytest.approx(1.5)
    r = rows[1e-8]
    assert (r["engine"]["method"], r["rebound"]["method"]) == ("engine:whfast_c11",
                                                               "rebound:ias15")
    assert r["ratio"] == pytest.approx(0.5)
    r = rows[1e-10]  # the engine does not get there
    assert r["engine"] is None and r["rebound"]["method"] == "rebound:ias15"
    assert r["ratio"] is None and not r["below_reference_floor"]
    assert report.ratio_cell(r) == "engine: not reached"
    r = rows[1e-12]
    assert r["engine"] is None and r["rebound"] is None and r["below_reference_floor"]
    assert report.ratio_cell(r) == "neither reached (below reference floor)"
    assert report.ratio_cell(rows[1e-6]) == "**1.50**"
    assert report.ratio_cell(rows[1e-8]) == "0.50"


def test_head_to_head_times_each_pair_once_and_keeps_the_sweep_ratio(monkeypatch, rebound):
    p = kepler(0.6, t_end_orbits=1.0)
    p_key = "kepler_e0.6"
    runs = [_run("engine", "leapfrog", 1.0, 1e-3, setting=200),
            _run("rebound", "leapfrog", 2.0, 1e-3, setting=200)]
    section = {p_key: {"versus": work_precision.versus(runs, levels=(1e-2, 1e-1))}}
    calls = []
    real = work_precision.time_pair

    def counting(problem, e, r, level):
        calls.append((problem.key, e["method"], r["method"]))
        return real(p, e, r, level)

    monkeypatch.setattr(work_precision, "time_pair", counting)
    work_precision.head_to_head(SMOKE, section)
    assert calls == [(p_key, "engine:leapfrog", "rebound:leapfrog")]
    for row in section[p_key]["versus"]:
        assert row["sweep_ratio"] == pytest.approx(0.5)
        sbs = row["side_by_side"]
        assert sbs["status"] == "ok" and sbs["repeats"] >= 1
        assert row["ratio"] == sbs["ratio"] and math.isfinite(row["ratio"]) and row["ratio"] > 0


# -- the bench rows -------------------------------------------------------------------------------

def test_planet_bench_compares_the_same_computation(rebound):
    r = bench.bench_planets(steps=200, span_days=2000.0, repeats=1)
    for key in ("whfast_c11", "ias15"):
        row = r["rows"][key]
        assert row["engine_us_per_step"] > 0 and row["rebound_us_per_step"] > 0
        assert row["time_over_rebound"] == pytest.approx(
            row["engine_us_per_step"] / row["rebound_us_per_step"])
        # same algorithm, same start: the two codes end in the same state
        assert row["relative_position_difference"] < 1e-9
    assert r["rows"]["whfast_c11"]["steps_engine"] == r["rows"]["whfast_c11"]["steps_rebound"]


def test_planet_targets_are_judged_from_the_figures():
    rows = {"whfast_c11": {"method": "whfast, corrector 11", "time_over_rebound": 0.45,
                           "engine_us_per_step": 0.45, "rebound_us_per_step": 1.0},
            "ias15": {"method": "ias15, epsilon 1e-09", "time_over_rebound": 0.55,
                      "engine_us_per_step": 5.5, "rebound_us_per_step": 10.0}}
    got = bench.targets({"planets": {"problem": "outer", "rows": rows}})
    assert [met for _, _, met in got] == [True, False]
    assert "at most 0.5 of REBOUND's" in got[0][0]
    assert got[1][1].startswith("0.55 of REBOUND's")


def test_a_sweep_stops_at_its_round_off_plateau_not_at_a_lucky_error():
    def points(*errors):
        return [{"error": e} for e in errors]

    floor = 1e-12
    assert work_precision.converged(points(1e-3, 5e-13), floor)  # below the reference's uncertainty
    assert not work_precision.converged(points(1e-3, 1e-5, 1e-7), floor)  # converging
    # one lucky error, then the trend again: go on
    assert not work_precision.converged(points(1e-6, 1e-10, 1e-8), floor)
    assert not work_precision.converged(points(1e-10, 1e-8, 1e-9), floor)
    # two step counts in a row without a gain, below 1e-8: round-off, stop
    assert work_precision.converged(points(2.9e-10, 3.2e-10, 7.7e-10), floor)
    # the same above 1e-8 is an orbit not yet followed (errors of order 1 wander): go on
    assert not work_precision.converged(points(1.5, 1.8, 1.7), floor)
    assert not work_precision.converged(points(1e-9, None, 1e-9), floor)  # a failed run in between
