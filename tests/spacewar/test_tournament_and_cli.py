"""Tournaments (same table whatever the workers) and the command line."""
import json
import subprocess
import sys

import pytest

from spacewar.cli import main
from spacewar.tournament import bradley_terry_elo, run_tournament, schedule


def test_schedule_both_seat_orders_same_seeds():
    s = schedule(["a", "b", "c"], games=2, seed=1)
    assert len(s) == 3 * 2 * 2
    assert s[0][:2] == ("a", "b") and s[1][:2] == ("b", "a") and s[0][2] == s[1][2]
    assert len({x[2] for x in s}) == 6


def test_elo_orders_by_strength_and_is_finite_for_perfect_records():
    results = [("a", "b", 1.0)] * 10 + [("b", "c", 1.0)] * 10 + [("a", "c", 1.0)] * 10
    elo = bradley_terry_elo(["a", "b", "c"], results)
    assert elo["a"] > elo["b"] > elo["c"]
    assert all(abs(v - 1500) < 1500 for v in elo.values())
    even = bradley_terry_elo(["a", "b"], [("a", "b", 0.5)] * 4)
    assert even["a"] == pytest.approx(even["b"])


def test_same_table_whatever_the_number_of_workers():
    kw = dict(games=2, seed=4, rounds=1, progress=False)
    one, _ = run_tournament(["idle", "random", "chaser"], workers=1, **kw)
    two, _ = run_tournament(["idle", "random", "chaser"], workers=2, **kw)
    assert json.dumps(one, sort_keys=True) == json.dumps(two, sort_keys=True)
    rows = {r["bot"]: r for r in one["table"]}
    assert sum(r["wins"] for r in rows.values()) == sum(r["losses"] for r in rows.values())
    assert all(r["played"] == 8 for r in rows.values())


def test_faulty_bot_does_not_take_the_tournament_down():
    report, _ = run_tournament(["tests.spacewar.bots_for_tests:Raising", "idle"], games=1,
                               seed=1, rounds=1, workers=1, progress=False, max_faults=3)
    rows = {r["bot"]: r for r in report["table"]}
    assert rows["idle"]["wins"] == 2 and rows["tests.spacewar.bots_for_tests:Raising"]["forfeits"] == 2


def test_cli_match_json_is_byte_identical(capsys, tmp_path):
    args = ["match", "--p1", "chaser", "--p2", "random", "--seed", "7", "--rounds", "2", "--json"]
    assert main(args) == 0
    first = capsys.readouterr().out
    assert main(args + ["--replay", str(tmp_path / "r.json")]) == 0
    assert capsys.readouterr().out == first
    data = json.loads(first)
    assert data["seed"] == 7 and data["bots"] == ["chaser", "random"]
    assert main(["replay", str(tmp_path / "r.json"), "--check"]) == 0
    assert capsys.readouterr().out.startswith("OK")


def test_cli_errors_are_messages_not_tracebacks(capsys):
    assert main(["match", "--p1", "nosuch", "--p2", "idle"]) == 2
    err = capsys.readouterr().err
    assert "unknown bot 'nosuch'" in err and "Traceback" not in err
    assert main(["replay", "/nonexistent.json", "--check"]) == 2


def test_cli_bots_and_help():
    out = subprocess.run([sys.executable, "-m", "spacewar", "bots"], capture_output=True,
                         text=True, check=True).stdout
    for name in ("idle", "random", "chaser", "sniper", "dodger"):
        assert name in out
    help_text = subprocess.run([sys.executable, "-m", "spacewar", "--help"], capture_output=True,
                               text=True, check=True).stdout
    for command in ("bots", "match", "replay", "tournament", "play"):
        assert command in help_text


@pytest.mark.parametrize("option, value, message", [
    ("--budget-ms", "nan", "must be finite"), ("--budget-ms", "inf", "must be finite"),
    ("--budget-ms", "0", "must be > 0"), ("--overage-ms", "-1", "must be >= 0"),
    ("--rounds", str(10 ** 20), "must be in [1, 1000000]"), ("--seed", "-3", "must be in [0,"),
])
def test_cli_numbers_are_checked(capsys, option, value, message):
    with pytest.raises(SystemExit) as stop:
        main(["match", "--p1", "idle", "--p2", "idle", option, value])
    assert stop.value.code == 2 and message in capsys.readouterr().err


def test_cli_bad_replay_path_fails_before_the_match(capsys, monkeypatch, tmp_path):
    import spacewar.match

    played = []
    monkeypatch.setattr(spacewar.match, "play_match", lambda *a, **k: played.append(1))
    assert main(["match", "--p1", "idle", "--p2", "idle", "--replay",
                 str(tmp_path / "missing" / "r.json")]) == 2
    assert "does not exist" in capsys.readouterr().err and played == []
    (tmp_path / "game.gif").write_bytes(b"GIF89a" + b"\0" * 20)
    assert main(["match", "--p1", "idle", "--p2", "idle", "--replay",
                 str(tmp_path / "game.gif")]) == 2  # a GIF is not replaced by a replay
    assert played == [] and (tmp_path / "game.gif").read_bytes().startswith(b"GIF89a")


def test_help_of_every_command_shows_the_defaults():
    for command in ("match", "tournament", "replay", "play", "sandbox"):
        text = subprocess.run([sys.executable, "-m", "spacewar", command, "--help"],
                              capture_output=True, text=True, check=True).stdout
        if command in ("match", "tournament"):
            assert "(default: 50.0)" in text and "(default: 1000.0)" in text


def test_every_subcommand_s_help_shows_its_options_defaults():
    """``spacewar CMD --help`` prints "(default: ...)" for every option that has a default."""
    import argparse

    from spacewar.cli import build_parser

    parser = build_parser()
    commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    missing = []
    for name, sub in commands.choices.items():
        text = " ".join(sub.format_help().split())
        for action in sub._actions:
            if (not action.option_strings or action.help == argparse.SUPPRESS
                    or action.default in (None, False, argparse.SUPPRESS)):
                continue
            shown = " ".join(f"(default: {action.default})".split())
            if shown not in text:
                missing.append(f"{name} {action.option_strings[0]} (default {action.default!r})")
    assert not missing, "defaults not shown in --help: " + ", ".join(missing)
