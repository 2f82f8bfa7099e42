"""Batch bots from files: one confined process answers for all of a bot's matches at once,
with results identical to the same bot played as an object or one match at a time, and
hostile batch bots (tests/spacewar/hostile_batch_bots.py) that cost their own matches only."""
import json
import sys

import numpy as np
import pytest

from spacewar import Rules
from spacewar.arena.batch_match import batch_seed, play_matches
from spacewar.author.check import check_bot
from spacewar.cli import main
from spacewar.arena.match import play_match
from spacewar.sandbox.limits import Limits
from spacewar.arena.tournament import (batch_files_of, group_jobs, make_jobs, run_tournament,
                                       schedule)
from spacewar.arena.jobs import play_job as tournament_play

from . import hostile_batch_bots  # the same classes, played as objects
from .test_untrusted_bots import FAST, LONG, ROOMY, SHORT, nothing_left_running  # noqa: F401


B = "tests.spacewar.hostile_batch_bots"

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"),
                                reason="the bot sandbox's checks here are Linux's")


def _same(a, b, skip=("bots", "winner", "forfeit", "output")):
    return {k: v for k, v in a.items() if k not in skip} == \
        {k: v for k, v in b.items() if k not in skip}


def _jobs_with(bot):
    """Its matches (three, seats 0, 1, 0) and one match it is not in."""
    return [(bot, "random", 1), ("idle", bot, 2), ("idle", "random", 3), (bot, "idle", 4)]


def test_a_batch_bot_from_a_file_answers_for_all_its_matches_in_one_process():
    spec = f"{B}:Steady"
    jobs = _jobs_with(spec)
    confined = play_matches(jobs, rounds=1, rules=SHORT, limits=ROOMY)
    rows = [(0, 0), (1, 1), (3, 0)]
    seed = batch_seed(rows, jobs)
    bot = hostile_batch_bots.Steady(seed=seed)
    as_object = play_matches([tuple(bot if x == spec else x for x in job[:2]) + (job[2],)
                              for job in jobs], rounds=1, rules=SHORT, limits=ROOMY)
    for (a, _), (b, _) in zip(confined, as_object):
        assert _same(a, b) and a["faults"][0]["total"] == a["faults"][1]["total"] == 0
    for m, s in rows:  # one process: asked for three rows, every frame, made with one seed
        assert confined[m][0]["output"][s]["text"] == f"rows 3 seed {seed}\n"
    assert bot.calls == max(confined[m][0]["steps"] for m, _ in rows)
    assert confined[2][0]["output"] == [{"text": "", "bytes": 0, "truncated": False}] * 2


def test_a_tournament_plays_a_batch_bot_s_pairings_together_with_the_same_table():
    bots = [f"{B}:Steady", "idle", "random"]
    assert batch_files_of(bots) == {f"{B}:Steady"}
    jobs = group_jobs(schedule(bots, 2, 1), "auto", batch_files_of(bots))
    assert [(len(m), t) for m, t in jobs] == [(4, True), (4, True)] + [(1, False)] * 4
    runs = [run_tournament(bots, games=2, seed=1, rounds=1, rules=SHORT, workers=w,
                           progress=False, limits=ROOMY)[0] for w in (1, 2)]
    assert json.dumps(runs[0], sort_keys=True) == json.dumps(runs[1], sort_keys=True)
    for match in runs[0]["matches"]:  # each as it plays alone, asked with K = 1
        if f"{B}:Steady" in (match["p1"], match["p2"]):
            alone, _, _ = play_match(match["p1"], match["p2"], seed=match["seed"], rounds=1,
                                     rules=SHORT, limits=ROOMY)
            assert [alone[k] for k in ("score", "steps", "winner")] == \
                [match[k] for k in ("score", "steps", "winner")]


@pytest.mark.parametrize("bot, kind", [("WrongCount", "invalid"), ("Raises", "raised")])
def test_bad_batch_answers_are_faults_of_its_own_matches(bot, kind):
    spec = f"{B}:{bot}"
    results = [r for r, _ in play_matches(_jobs_with(spec), rounds=1, rules=SHORT,
                                          limits=ROOMY, max_faults=5)]
    for m, s in [(0, 0), (1, 1), (3, 0)]:
        f = results[m]["faults"][s]
        assert f[kind] == f["total"] == 5 and results[m]["forfeits"][s]
        assert results[m]["steps"] == 4
    honest = play_matches([("idle", "random", 3)], rounds=1, rules=SHORT)[0][0]
    assert _same(results[2], honest)


@pytest.mark.parametrize("bot, message", [
    ("ForgedCount", "answered 4 codes for a batch of 3"),
    ("ForgedRange", "broke the protocol: answered"),  # ahead, or for the call before
    ("StaleCall", "answered call 1000, asked 0"),
    ("HugeText", "exceeds 1024"),
    ("Flood", "without being asked"),
    ("ReadyAgain", "status 'ready' during play"),
    ("DiesLater", "exited (code 9)"),
])
def test_a_breach_or_a_death_forfeits_all_its_live_matches_and_no_other(bot, message):
    spec = f"{B}:{bot}"
    results = [r for r, _ in play_matches(_jobs_with(spec), rounds=1, rules=SHORT,
                                          limits=ROOMY, max_faults=1000)]
    for m, s in [(0, 0), (1, 1), (3, 0)]:
        r = results[m]
        assert r["forfeits"][s] and not r["forfeits"][1 - s] and r["winner_seat"] == 1 - s
        assert message in r["faults"][s]["last"]["message"], r["faults"][s]
    if bot == "ForgedRange":  # its forged answer was judged first: out of range, invalid
        assert "action code 200 out of range" in results[0]["faults"][0]["examples"][0]["message"]
    if bot == "DiesLater":
        assert results[0]["steps"] == 10
    honest = play_matches([("idle", "random", 3)], rounds=1, rules=SHORT)[0][0]
    assert _same(results[2], honest)


@pytest.mark.parametrize("bot, message", [
    ("NoCodes", "answered 0 codes for a batch of 3 with status 'ok'"),
    ("OneCodeShort", "answered 2 codes for a batch of 3 with status 'ok'"),
    ("OneCodeOver", "answered 4 codes for a batch of 3 with status 'ok'"),
    ("RaisedWithCodes", "answered 3 codes for a batch of 3 with status 'raised'"),
])
def test_a_count_of_codes_other_than_k_is_a_breach_that_forfeits_the_batch(bot, message):
    """Found by a red team: status OK with no code was an invalid fault a match, not the
    documented breach. Each bot answers every call itself (its host's answer never arrives),
    so one breach is one fault and the forfeit of every live match at frame 0."""
    results = [r for r, _ in play_matches(_jobs_with(f"{B}:{bot}"), rounds=1, rules=SHORT,
                                          limits=ROOMY, max_faults=1000)]
    for m, s in [(0, 0), (1, 1), (3, 0)]:
        f = results[m]["faults"][s]
        assert results[m]["forfeits"][s] and results[m]["winner_seat"] == 1 - s
        assert f["invalid"] == f["total"] == 1 and results[m]["steps"] == 0, f
        assert f["last"]["message"].startswith(f"broke the protocol: {message}"), f
    honest = play_matches([("idle", "random", 3)], rounds=1, rules=SHORT)[0][0]
    assert _same(results[2], honest)


def test_k_codes_with_one_out_of_range_are_invalid_faults_and_play_goes_on():
    results = [r for r, _ in play_matches(_jobs_with(f"{B}:OneBadCode"), rounds=1,
                                          rules=SHORT, limits=ROOMY, max_faults=1000)]
    honest = [r for r, _ in play_matches(_jobs_with(f"{B}:Steady"), rounds=1, rules=SHORT,
                                         limits=ROOMY, max_faults=1000)]
    for m, s in [(0, 0), (1, 1), (3, 0)]:
        f = results[m]["faults"][s]
        assert not any(results[m]["forfeits"]) and f["invalid"] == f["total"] == 1, f
        assert f["last"] == {"frame": 0, "kind": "invalid",
                             "message": "action code 200 out of range [0, 48)"}
        assert results[m]["steps"] > 1 and honest[m]["faults"][s]["total"] == 0
    assert _same(results[2], honest[2])


def test_a_slow_batch_is_late_for_every_match_and_a_silent_one_is_stopped():
    slow = [r for r, _ in play_matches([(f"{B}:Slow", "idle", 1), ("idle", f"{B}:Slow", 2)],
                                       rounds=1, rules=SHORT, max_faults=3,
                                       limits=Limits(budget=0.05, overage=0.1, stop_after=5.0,
                                                     startup=60.0))]
    for s, r in enumerate(slow):
        assert r["faults"][s]["timeout"] == r["faults"][s]["total"] == 3 and r["forfeits"][s]
    # frames go on while it is busy (the match never waits on it), until it is stopped
    hang = [r for r, _ in play_matches([(f"{B}:Hang", "idle", 1), ("idle", f"{B}:Hang", 2)],
                                       rounds=1, rules=LONG, limits=FAST, max_faults=10 ** 6)]
    for s, r in enumerate(hang):
        f = r["faults"][s]
        assert r["forfeits"][s] and f["timeout"] == f["total"] == r["steps"] + 1 >= 2
        assert f["last"]["message"].startswith("stopped: no answer to call 0")


def test_a_confined_bot_saying_it_raised_is_still_charged_its_time():
    results = [r for r, _ in play_matches([(f"{B}:ThinksThenRaises", "idle", 1),
                                           ("idle", f"{B}:ThinksThenRaises", 2)],
                                          rounds=1, rules=SHORT, limits=FAST, max_faults=25)]
    for s, r in enumerate(results):  # 0.4 s a call against 0.1 s of budget: its bank is spent
        f = r["faults"][s]
        assert r["forfeits"][s] and f["raised"] >= 1 and f["timeout"] >= 20, f


def test_check_sees_a_batch_bot_play_as_a_tournament_plays_it():
    """Found by a red team: ``spacewar check`` asked every batch bot with K = 1, which a
    tournament never does against a built-in bot, so a bot could idle under check alone."""
    spec = f"{B}:IdlesAlone"
    seen = []
    report = check_bot(spec, opponents=["chaser"], games=1, rules=SHORT, limits=ROOMY,
                       on_match=seen.append)
    matches = [(spec, "chaser", 0), ("chaser", spec, 0)]
    job, = make_jobs(matches, 1, SHORT, ROOMY, 25, "auto", batch_files_of([spec]))
    in_tournament = [r for r, _ in tournament_play(job)]  # the tournament's own path
    checked = [m for m in seen if not m.get("repeat")]
    assert len(checked) == len(report.matches) == 2
    for record, result in zip(checked, in_tournament):
        s = record["seat"]
        assert record["frames"] == result["steps"]
        assert record["score"] == [result["score"][s], result["score"][1 - s]]
    alone = [play_match(p1, p2, seed=seed, rounds=1, rules=SHORT, limits=ROOMY)[0]
             for p1, p2, seed in matches]  # asked alone, it idles: another play
    assert [r["steps"] for r in alone] != [r["steps"] for r in in_tournament]
    assert report.settings["together"] == [2] and report.deterministic is True


def test_check_replays_a_batch_bot_s_whole_group_to_judge_its_determinism():
    report = check_bot(f"{B}:FromTheClock", opponents=["idle"], games=2, rules=SHORT,
                       limits=ROOMY)
    assert report.deterministic is False and not report.passed
    assert report.determinism.startswith("the 4 matches against idle (seeds 0 to 1, both "
                                         "seats), played together twice: seed ")
    assert "the first time" in report.determinism


def test_a_bot_that_loses_act_batch_when_made_is_a_start_up_fault():
    results = [r for r, _ in play_matches(_jobs_with(f"{B}:Pretender"), rounds=1, rules=SHORT,
                                          limits=ROOMY)]
    for m, s in [(0, 0), (1, 1), (3, 0)]:
        f = results[m]["faults"][s]
        assert f["startup"] == 1 and "no callable act_batch" in f["examples"][0]["message"]
        assert results[m]["steps"] == 0 and results[m]["forfeits"][s]


# serial (docs/testing.md): a worker process per core of its own and confined hostile bots,
# while the honest bot is held to a wall-clock budget
@pytest.mark.serial
def test_a_tournament_of_hostile_batch_bots_finishes_with_an_honest_table(capsys):
    """500 ms a frame: over 100x the p99 act time of both honest bots (measured on this 2-core
    machine while it ran other suites: sniper in this process 2.4-4.2 ms, Steady's share of a
    batch call in its own process 2.9 ms, 1197 and 2394 actions), so neither is ever late
    however loaded the machine, and no timeout can decide a match between them."""
    hostile = ["Steady", "Hang", "DiesLater", "ForgedCount", "Flood", "WrongCount"]
    bots = [f"{B}:{b}" for b in hostile] + ["sniper"]
    args = ["tournament", "--bots", ",".join(bots), "--games", "1", "--rounds", "1",
            "--workers", "2", "--json", "--budget-ms", "500", "--overage-ms", "200"]
    assert main(args) == 0
    report = json.loads(capsys.readouterr().out)
    rows = {r["bot"]: r for r in report["table"]}
    assert rows["sniper"]["wins"] == rows["sniper"]["played"] == 12
    assert rows[f"{B}:Steady"]["forfeits"] == 0
    assert rows["sniper"]["faults"] == rows[f"{B}:Steady"]["faults"] == 0  # no turn lost
    honest = {"sniper", f"{B}:Steady"}
    against_honest = [m for m in report["matches"] if len({m["p1"], m["p2"]} & honest) == 1]
    assert len(against_honest) == 2 * 2 * 5
    for m in against_honest:  # each hostile bot forfeits every match it plays an honest one
        assert m["forfeit"] not in honest and m["forfeit"] in (m["p1"], m["p2"]), m


def test_the_class_body_decides_what_plays_as_a_batch_bot(tmp_path):
    from spacewar.bots import declares_act_batch

    path = tmp_path / "kinds.py"
    path.write_text("class Base:\n    def act_batch(self, obs):\n        return [0] * len(obs)\n"
                    "class Inherits(Base):\n    pass\n"
                    "class Assigned:\n    act_batch = Base.act_batch\n"
                    "class Nested:\n    class Inner:\n        def act_batch(self, obs): pass\n"
                    "    def act(self, obs):\n        act_batch = 1\n"
                    "class Twice:\n    def act_batch(self, obs): pass\n"
                    "class Twice:\n    def act(self, obs): pass\n")
    found = {name: declares_act_batch(f"{path}:{name}")
             for name in ("Base", "Inherits", "Assigned", "Nested", "Twice", "Missing")}
    assert found == {"Base": True, "Inherits": False, "Assigned": True, "Nested": False,
                     "Twice": False, "Missing": False}
    (tmp_path / "bad.py").write_text("class Base:\n  def act_batch(self):\n pass\n")
    huge = tmp_path / "huge.py"
    huge.write_bytes(b"class Base:\n    def act_batch(self, obs): pass\n" + b"#" * (1 << 20))
    assert not declares_act_batch(f"{tmp_path / 'bad.py'}:Base")  # does not tokenize
    assert not declares_act_batch(f"{huge}:Base")  # over the cap: read no further
    assert not declares_act_batch("chaser") and not declares_act_batch(f"{tmp_path}/no.py:X")


def test_sources_made_to_hang_or_crash_the_reading_are_read_as_no_batch_bot(tmp_path):
    """Found by a red team: a codec cookie that is no text encoding (LookupError), a line
    on which the tokenizer takes quadratic time, a FIFO that never gives its bytes."""
    import os

    from spacewar.bots import declares_act_batch

    body = b"class B:\n    def act_batch(self, obs):\n        return [0] * len(obs)\n"
    (tmp_path / "rot13.py").write_bytes(b"# coding: rot13\n" + body)
    (tmp_path / "slow.py").write_bytes(body + b"x = '" + b"\\'" * 100_000 + b"\n")
    os.mkfifo(tmp_path / "fifo.py")
    for name in ("rot13", "slow", "fifo"):
        assert not declares_act_batch(f"{tmp_path / name}.py:B"), name
    (tmp_path / "plain.py").write_bytes(body)
    assert declares_act_batch(f"{tmp_path / 'plain.py'}:B")
    with pytest.raises(ValueError, match="plays with play_match"):
        play_matches([(f"{tmp_path / 'fifo.py'}:B", "idle", 1)], rounds=1, rules=SHORT)
