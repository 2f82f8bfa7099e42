"""The Spacewar section of the bench reports a confined match that went differently (a bot
that faulted or could not start) instead of crashing the whole run."""
import spacewar.arena.match
from validation import bench


def test_a_faulting_confined_bot_is_reported_not_fatal(monkeypatch):
    real = spacewar.arena.match.play_match

    def play_match(p1, p2, **kwargs):
        if kwargs.get("isolation") != "process":
            return real(p1, p2, **kwargs)
        result, _, _ = real(p1, p2, **{**kwargs, "rounds": 1})
        result = dict(result, steps=0, score=[0, 0], forfeits=[True, False])
        result["faults"] = [dict(result["faults"][0], total=1, timeout=1), result["faults"][1]]
        return result, None, {"wall_seconds": 0.5, "frames_per_second": 0.0,
                              "startup_seconds": 0.5, "play_seconds": 0.0,
                              "play_frames_per_second": 0.0}

    monkeypatch.setattr(spacewar.arena.match, "play_match", play_match)
    report = {"spacewar": bench.bench_spacewar(matches=2, frames=5, repeats=1)}
    conf = report["spacewar"]["one_match_confined_bots"]
    assert conf["agrees_with_inline"] is False
    assert conf["faults"] == [1, 0] and conf["fault_kinds"][0] == {"timeout": 1}
    assert conf["slowdown"] is None and conf["forfeits"] == [True, False]
    assert conf["over_inline"] == 0.0 and conf["startup_seconds"] == 0.5
    assert set(report["spacewar"]["confined_bot_ready_seconds"]) == {"idle", "chaser", "sniper"}
    report["machine"] = {"cpu": "cpu", "cores": 1, "numba": "-", "numba_threads": 1,
                         "numpy": "-", "python": "-"}
    text = bench.format_report(report)
    assert "DIFFERS from the inline match" in text and "timeout 1" in text
    assert "no frame played" in bench.format_markdown(report, "python -m validation bench")
