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
