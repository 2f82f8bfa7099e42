"""The benchmark harness runs and measures what it says (no timing thresholds: speed lives in
the harness's report, not in tests)."""
import math

import numpy as np

from validation import bench


def test_small_n_engine_computes_what_the_plain_loop_computes():
    r = bench.bench_small_n(steps=2000, repeats=1)
    assert r["max_position_difference_vs_plain_after_1000_steps"] < 1e-10
    for key in ("engine_steps_per_second", "plain_loop_steps_per_second",
                "rebound_leapfrog_steps_per_second"):
        assert r[key] > 0 and math.isfinite(r[key])


def test_the_pair_kernel_and_the_both_ends_loop_it_is_timed_against_agree():
    kernel_ms, both_ends_ms, ratio, difference = bench.kernel_against_both_ends(300, 1)
    assert difference < 1e-12
    assert kernel_ms > 0 and both_ends_ms > 0 and ratio > 0


def test_nbody_state_has_zero_momentum():
    pos, vel, mass = bench.nbody_state()
    np.testing.assert_allclose((mass[:, None] * vel).sum(axis=0), 0.0, atol=1e-14)


def test_report_sections_and_markdown():
    report = bench.run(quick=True, sections=["terms", "spacewar"])
    text = bench.format_report(report)
    md = bench.format_markdown(report, "python -m validation bench --quick")
    assert "declared terms" in text and "Spacewar" in text
    assert md.startswith("# Performance") and "| declared terms |" in md
    assert report["spacewar"]["batch"]["match_frames_per_second"] > 0
    assert set(report["terms"]["seconds_per_step"]) == {
        "1: gravity", "2: + drag", "4: + uniform gravity, Coulomb"}


def test_targets_are_judged_from_the_figures():
    report = {
        "direct_sum": {"rows": [{"n": 256, "speedup_vs_rebound": 5.0,
                                 "kernel_speedup_vs_both_ends": 1.2},
                                {"n": 1024, "speedup_vs_rebound": 7.9,
                                 "kernel_speedup_vs_both_ends": 1.59}]},
        "small_n": {"engine_time_over_plain_loop": 1.29, "speedup_vs_rebound": 2.5},
        "scaling": {"direct_slope_large_n": 2.6, "test_particle_slope_large_n": 1.0},
        "terms": {"relative_to_gravity_alone": {"a": 1.0, "b": 1.2, "c": 2.0}},
    }
    verdicts = [met for _, _, met in bench.targets(report)]
    assert verdicts == [False, True, True, False, True]
    report["direct_sum"]["rows"][1]["kernel_speedup_vs_both_ends"] = 1.61
    report["terms"]["relative_to_gravity_alone"]["c"] = 0.5
    verdicts = [met for _, _, met in bench.targets(report)]
    assert verdicts == [True, True, True, False, False]
    assert "1.61x; the whole step 7.9x REBOUND's (5.0x at 256)" == bench.targets(report)[0][1]


def test_the_contact_section_solves_the_same_problem_as_rebound():
    from validation.bench import contact

    r = contact.measure((600,), repeats=1)
    (row,) = r["rows"]
    assert row["engine_contacts_per_step"] > 1
    # the same gas, seen by two codes: about the same number of contacts a step
    assert abs(row["engine_contacts_per_step"] / row["rebound_contacts_per_step"] - 1) < 0.35
    report = {"contact": r}
    assert contact.targets(report) == []  # below 10^4, one size: no target judged
    assert "12. Contact" in contact.format_contact(report)
    assert contact.markdown_contact(report)[0].startswith("## 12. Contact")
