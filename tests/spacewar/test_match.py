"""Matches: determinism, bot loading in all three forms, fault isolation, replays."""
import json
import os
import textwrap

import pytest

from spacewar import replay
from spacewar.bots import BotLoadError, available, load_bot_class
from spacewar.arena.match import play_match
from spacewar.sandbox.limits import Limits

HERE = os.path.dirname(__file__)
TEST_BOTS = "tests.spacewar.bots_for_tests"


def test_same_seed_byte_identical_result():
    a, _, _ = play_match("chaser", "random", seed=5, rounds=2)
    b, _, _ = play_match("chaser", "random", seed=5, rounds=2)
    assert json.dumps(a, sort_keys=True) == json.dumps(b, sort_keys=True)
    c, _, _ = play_match("chaser", "random", seed=6, rounds=2)
    assert c["steps"] != a["steps"] or c["score"] != a["score"]


def test_result_fields():
    result, _, timing = play_match("idle", "idle", seed=1, rounds=1)
    for key in ("winner", "score", "rounds", "steps", "faults", "seed", "rules", "bots"):
        assert key in result
    assert result["rules"]["mode"] == "classic" and result["seed"] == 1
    assert timing["frames_per_second"] > 0


def test_load_by_name_module_and_file(tmp_path):
    assert {"idle", "random", "chaser", "sniper", "dodger"} <= set(available())
    assert load_bot_class("chaser").__name__ == "Chaser"
    assert load_bot_class(f"{TEST_BOTS}:Thruster").__name__ == "Thruster"
    path = tmp_path / "my_bot.py"
    path.write_text(textwrap.dedent("""
        from spacewar import Action
        class Spinner:
            def act(self, obs):
                return Action(turn=1, fire=True)
    """))
    assert load_bot_class(f"{path}:Spinner").__name__ == "Spinner"
    result, _, _ = play_match(f"{path}:Spinner", f"{TEST_BOTS}:Thruster", seed=2, rounds=1)
    assert result["faults"][0]["total"] == 0 and result["faults"][1]["total"] == 0


@pytest.mark.parametrize("spec, message", [
    ("nosuchbot", "unknown bot 'nosuchbot'; available: chaser, dodger, idle, random, sniper"),
    ("tests.spacewar.nothere:Bot", "cannot import module"),
    (f"{TEST_BOTS}:Missing", "has no class 'Missing'"),
    ("/nonexistent/bot.py:Bot", "does not exist"),
    ("spacewar.rules:Rules", "is not a bot"),
])
def test_bad_bot_specs_are_clear_errors(spec, message):
    with pytest.raises(BotLoadError, match=message.replace("(", r"\(").replace(")", r"\)")):
        load_bot_class(spec)


def test_unknown_bot_in_a_match_lists_the_available():
    with pytest.raises(BotLoadError, match="available: chaser"):
        play_match("nosuchbot", "idle")


# Budgets from act times measured on this 2-core machine while it ran other test suites
# (play_match(..., act_seconds=True), 1100-1200 actions a bot): a test bot in its own process
# answered in 0.13-0.19 ms at the median, 3.8-5.3 ms at the 99th percentile (10.6 ms at most);
# chaser in this process 0.33 ms at the median, 0.64 ms at the p99 (3.4 ms at most).
# ANSWERS: a budget over 100x the confined p99, and a bank besides: an answer is never late,
# so a bot that raises or returns garbage has faults of that kind and no other.
ANSWERS = Limits(budget=0.6, overage=5.0)
# LATE: 0.1 s, over 100x chaser's p99 (it must not fault), and a bank of 0.5 s for a stall;
# Slow sleeps 0.4 s an action, which no load can shorten: once its bank is spent (two
# actions), every action of it is late, however fast or slow the machine.
LATE = Limits(budget=0.1, overage=0.5)


@pytest.mark.parametrize("bot, kind, limits", [("Raising", "raised", ANSWERS),
                                               ("Garbage", "invalid", ANSWERS),
                                               ("Slow", "timeout", LATE)],
                         ids=["Raising", "Garbage", "Slow"])
@pytest.mark.parametrize("isolation", ["inline", "process"])
def test_faulty_bot_loses_turns_is_reported_and_forfeits(bot, kind, limits, isolation):
    from tests.spacewar import bots_for_tests

    # inline: a bot object of the caller's own; process: the same class named by a string
    spec = getattr(bots_for_tests, bot)() if isolation == "inline" else f"{TEST_BOTS}:{bot}"
    result, _, _ = play_match(spec, "chaser", seed=1, rounds=1, limits=limits, max_faults=4)
    faults = result["faults"][0]
    # every fault is of the bot's kind, and it forfeits at max_faults of them
    assert faults[kind] == faults["total"] == 4, faults
    assert {ex["kind"] for ex in faults["examples"]} == {kind} and faults["examples"][0]["message"]
    name = f"tests.spacewar.bots_for_tests.{bot}" if isolation == "inline" else f"{TEST_BOTS}:{bot}"
    assert result["forfeit"] == name and result["winner"] == "chaser"
    assert result["faults"][1]["total"] == 0


def test_hanging_bot_in_a_process_only_loses_turns():
    result, _, _ = play_match(f"{TEST_BOTS}:Hanging", "idle", seed=1, rounds=1, budget=0.02,
                              max_faults=4, isolation="process")
    f = result["faults"][0]
    # all its faults are timeouts: whether it reaches max_faults or is stopped first for
    # hanging past stop_after depends on how long the waits took, so their number is not asked
    assert f["timeout"] == f["total"] >= 1 and result["forfeits"] == [True, False], f
    assert result["winner"] == "idle"


def test_crashing_bot_process_is_reported():
    result, _, _ = play_match(f"{TEST_BOTS}:Dies", "idle", seed=1, rounds=1, limits=ANSWERS,
                              max_faults=5, isolation="process")
    f = result["faults"][0]
    assert f["crashed"] == f["total"] == 1 and result["forfeit"] == f"{TEST_BOTS}:Dies", f
    assert f["last"]["frame"] == 3  # it exits on frame 3, answering frames 0 to 2 in time


def test_occasional_faults_cost_turns_but_not_the_match():
    result, _, _ = play_match(f"{TEST_BOTS}:SometimesRaising", "idle", seed=3, rounds=1,
                              limits=ANSWERS)
    f = result["faults"][0]
    assert f["raised"] == f["total"] == 3 and result["forfeit"] is None, f
    assert [ex["frame"] for ex in f["examples"]] == [5, 6, 7]
    assert result["rounds"] >= 1


def test_replay_round_trip_and_check(tmp_path):
    result, rep, _ = play_match("chaser", "random", seed=9, rounds=2, record=True)
    path = tmp_path / "match.json"
    replay.save(path, rep)
    loaded = replay.load(path)
    assert loaded["result"] == json.loads(json.dumps(result))
    ok, details = replay.check(loaded)
    assert ok, details
    assert details["replayed"]["steps"] == result["steps"]
    assert not [p for p in os.listdir(tmp_path) if p.startswith(".replay-")]


def test_tampered_replay_fails_the_check(tmp_path):
    _, rep, _ = play_match("chaser", "random", seed=9, rounds=1, record=True)
    codes = replay.actions(rep)
    codes[10, 0] = (codes[10, 0] + 6) % 48  # flip the fire button on one frame
    import base64
    rep["actions"] = base64.b64encode(codes.astype("uint8").tobytes()).decode()
    ok, details = replay.check(rep)
    assert not ok and "final_state_sha256" in details["mismatches"]


def test_replay_of_a_forfeited_match_checks(tmp_path):
    result, rep, _ = play_match(f"{TEST_BOTS}:Raising", "chaser", seed=1, rounds=1,
                                max_faults=3, record=True)
    assert result["forfeit"] and replay.check(rep)[0]


@pytest.mark.parametrize("content, message", [
    ("not json", "not a JSON replay"),
    ('{"format": "other"}', "not a spacewar replay"),
    ('{"format": "spacewar-replay", "version": 99}', "version 99"),
    ('{"format": "spacewar-replay", "version": 1, "seed": 1}', "lacks the field"),
])
def test_bad_replay_files_are_refused(tmp_path, content, message):
    path = tmp_path / "bad.json"
    path.write_text(content)
    with pytest.raises(replay.ReplayError, match=message):
        replay.load(path)
