"""Tournaments (same table whatever the workers) and the command line."""
import json
import math
import subprocess
import sys

import numpy as np
import pytest

from spacewar.cli import main
from spacewar.arena.ratings import bradley_terry_elo
from spacewar.arena.tournament import run_tournament, schedule


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
    assert even["a"] == even["b"] == 1500.0  # a fixed point of the iteration: exact


# -- the ratings' values against an independent Bradley-Terry fit ------------------------------
def newton_bradley_terry(names, results):
    """The maximum-likelihood fit of spacewar.arena.tournament's model, by Newton's method on the
    log-strengths (not the project's MM iteration): P(i beats j) = s_i / (s_i + s_j), each bot
    one virtual draw against an anchor of strength 1, ratings 1500 + 400 log10(s)."""
    k = len(names)
    index = {n: i for i, n in enumerate(names)}
    wins = np.zeros((k, k))
    for p1, p2, outcome in results:
        wins[index[p1], index[p2]] += outcome
        wins[index[p2], index[p1]] += 1.0 - outcome
    games = wins + wins.T
    theta = np.zeros(k)
    for _ in range(100):
        p = 1.0 / (1.0 + np.exp(theta[None, :] - theta[:, None]))  # P(i beats j)
        q = 1.0 / (1.0 + np.exp(-theta))  # P(i beats the anchor)
        gradient = wins.sum(axis=1) + 0.5 - (games * p).sum(axis=1) - q
        curvature = games * p * (1.0 - p)
        hessian = curvature - np.diag(curvature.sum(axis=1) + q * (1.0 - q))
        step = np.linalg.solve(hessian, -gradient)
        theta += step
        if np.abs(step).max() < 1e-13:
            break
    else:  # pragma: no cover
        raise AssertionError("Newton's method did not converge")
    return {n: 1500.0 + 400.0 * theta[index[n]] / math.log(10.0) for n in names}


def two_players_symmetric(won, games):
    """Two bots, one won ``won`` of their ``games``: by the symmetry of the anchor the fit has
    theta_b = -theta_a, and theta_a solves won + 1/2 = games sigma(2 theta) + sigma(theta)
    (monotone in theta): bisection, the ratings 1500 +- 400 theta / ln 10."""
    def sigma(x):
        return 1.0 / (1.0 + math.exp(-x))

    lo, hi = -50.0, 50.0
    while hi - lo > 1e-15 * max(1.0, abs(hi)) and (lo + hi) / 2 not in (lo, hi):
        mid = (lo + hi) / 2
        if games * sigma(2 * mid) + sigma(mid) < won + 0.5:
            lo = mid
        else:
            hi = mid
    delta = 400.0 * (lo + hi) / 2 / math.log(10.0)
    return {"a": 1500.0 + delta, "b": 1500.0 - delta}


def elo_deviation(got, want):
    """The largest difference, in Elo points, of one set of ratings from another."""
    assert set(got) == set(want)
    return max(abs(got[n] - want[n]) for n in want)


RATING_CASES = {
    # name: (bots, results, bound on the deviation in Elo points). Measured on this machine:
    # the project's MM stops (relative step below 1e-12) 8.1e-6 Elo from the fit with perfect
    # records (slow linear convergence there), 5.0e-9 and 3.1e-9 on the others.
    "perfect records": (["a", "b", "c"], [("a", "b", 1.0)] * 10 + [("b", "c", 1.0)] * 10
                        + [("a", "c", 1.0)] * 10, 3e-5),
    "mixed, with draws": (["a", "b", "c", "d"],
                          [("a", "b", 1.0)] * 7 + [("b", "a", 1.0)] * 3 + [("a", "c", 0.5)] * 4
                          + [("c", "d", 1.0)] * 5 + [("d", "c", 1.0)] * 2
                          + [("b", "d", 0.0)] * 3 + [("d", "a", 1.0)], 2e-8),
    "two bots, 6 of 8": (["a", "b"], [("a", "b", 1.0)] * 6 + [("b", "a", 1.0)] * 2, 1e-8),
}


@pytest.mark.parametrize("case", RATING_CASES)
def test_the_ratings_are_the_bradley_terry_fit(case):
    names, results, bound = RATING_CASES[case]
    elo = bradley_terry_elo(names, results)
    want = newton_bradley_terry(names, results)
    assert elo_deviation(elo, want) < bound, (elo, want)
    # the fit is a stationary point in the documented Elo formula: each bot's expected score,
    # P(i beats j) = 1 / (1 + 10^((R_j - R_i) / 400)), equals its score (its virtual draw with
    # the 1500 anchor included); measured residuals 8.2e-9 (perfect records), below 1e-11
    expected = dict.fromkeys(names, 0.0)
    scored = dict.fromkeys(names, 0.5)
    for p1, p2, outcome in results:
        e = 1.0 / (1.0 + 10.0 ** ((elo[p2] - elo[p1]) / 400.0))
        expected[p1] += e
        expected[p2] += 1.0 - e
        scored[p1] += outcome
        scored[p2] += 1.0 - outcome
    for n in names:
        expected[n] += 1.0 / (1.0 + 10.0 ** ((1500.0 - elo[n]) / 400.0))
        assert expected[n] == pytest.approx(scored[n], abs=5e-8), n


def test_two_bots_are_rated_symmetrically_about_the_anchor_in_closed_form():
    elo = bradley_terry_elo(["a", "b"], RATING_CASES["two bots, 6 of 8"][1])
    want = two_players_symmetric(6.0, 8)
    # measured: 3.1e-9 Elo from the closed form, and a sum 6.0e-9 below 3000
    assert elo_deviation(elo, want) < 1e-8
    assert abs(elo["a"] + elo["b"] - 3000.0) < 2e-8
    assert want == pytest.approx(newton_bradley_terry(["a", "b"],
                                                      RATING_CASES["two bots, 6 of 8"][1]),
                                 abs=1e-9)


@pytest.mark.parametrize("case", RATING_CASES)
def test_the_rating_check_fails_on_an_unconverged_fit_and_on_the_wrong_scale(case):
    """Positive control: the same comparison on a broken rating. Measured: 5 MM iterations
    are 337, 24 and 18 Elo away; natural logarithms instead of base 10 are 699, 242 and 115
    Elo away."""
    names, results, bound = RATING_CASES[case]
    want = newton_bradley_terry(names, results)
    unconverged = bradley_terry_elo(names, results, iterations=5)
    assert elo_deviation(unconverged, want) > 1000 * bound
    right = bradley_terry_elo(names, results)
    natural_log = {n: 1500.0 + (r - 1500.0) * math.log(10.0) for n, r in right.items()}
    assert elo_deviation(natural_log, want) > 1000 * bound


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
    import spacewar.arena.match

    played = []
    monkeypatch.setattr(spacewar.arena.match, "play_match", lambda *a, **k: played.append(1))
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
