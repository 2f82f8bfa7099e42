"""Leagues (``spacewar.arena.league``): pairings, ratings with uncertainty, and resuming from the
results file after an interruption with the same end as a run straight through."""
import json
import os
from pathlib import Path

import numpy as np
import pytest

from spacewar.arena import league, ratings
from spacewar.bots import bots_in
from spacewar.rules import Rules
from spacewar.sandbox.limits import Limits
from spacewar.arena.ratings import bradley_terry_elo

BOTS = ["chaser", "sniper", "dodger", "random", "idle"]  # odd: a bye every round
QUICK = dict(games=1, match_rounds=1, workers=1, progress=False, bootstrap=40)


def _config(bots, pairing="swiss", games=1):
    return league.league_config(bots, games, pairing, 7, 1, Rules(), Limits(), 25, "auto")


@pytest.mark.parametrize("pairing", league.PAIRINGS)
def test_every_bot_plays_once_a_round_and_byes_go_round(pairing):
    bots = [f"b{i}" for i in range(7)]
    config = _config(bots, pairing)
    met, byes = {}, {}
    for index in range(7):
        pairs, bye = league.pair_round(config, index, bots[::-1], met, byes)
        seated = [b for p in pairs for b in p] + [bye]
        assert sorted(seated) == sorted(bots)
        byes[bye] = byes.get(bye, 0) + 1
        for a, b in pairs:
            key = tuple(sorted((a, b)))
            met[key] = met.get(key, 0) + 1
    assert sorted(byes.values()) == [1] * 7  # seven rounds, seven different byes
    if pairing == "swiss":  # six rounds of seven bots can avoid every rematch but one
        assert max(met.values()) <= 2


def test_swiss_pairs_neighbours_in_the_standings_it_is_given():
    bots = [f"b{i}" for i in range(8)]
    pairs, bye = league.pair_round(_config(bots), 1, bots, {}, {})
    assert bye is None and pairs == [("b0", "b1"), ("b2", "b3"), ("b4", "b5"), ("b6", "b7")]
    pairs, _ = league.pair_round(_config(bots), 1, bots, {("b0", "b1"): 1}, {})
    assert pairs[0] == ("b0", "b2")  # no rematch while another opponent is left


def test_the_sparse_bradley_terry_fit_is_the_tournaments():
    rng = np.random.default_rng(3)
    bots = [f"b{i}" for i in range(6)]
    matches = []
    for _ in range(80):
        a, b = rng.choice(6, 2, replace=False)
        winner = [None, bots[a], bots[b]][rng.integers(3)]
        matches.append({"p1": bots[a], "p2": bots[b], "winner": winner})
    sparse = ratings.bradley_terry_intervals(bots, matches, 200, np.random.default_rng(1))
    dense = bradley_terry_elo(bots, [(m["p1"], m["p2"], ratings.match_outcome(m)) for m in matches])
    for b in bots:
        elo, low, high = sparse[b]
        assert elo == pytest.approx(dense[b], abs=1e-9)
        assert low < elo < high  # every bot has a non-degenerate interval around its fit
    assert ratings.bradley_terry_intervals(bots, matches, 200, np.random.default_rng(1)) == sparse  # seeded


def test_a_league_resumed_after_interruptions_ends_as_one_run_straight_through(tmp_path):
    straight = tmp_path / "straight.json"
    league.run_league(BOTS, 3, straight, **QUICK)

    resumed = tmp_path / "resumed.json"

    def stop_after_first(results):
        if results["rounds_played"] == 1:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        league.run_league(BOTS, 3, resumed, on_round=stop_after_first, **QUICK)
    saved = resumed.read_bytes()
    assert json.loads(saved)["rounds_played"] == 1

    # interrupted again in the middle of round 2: the saved round is untouched
    original = league.MatchRunner.play

    def interrupted(self, jobs, progress=lambda n: None):
        original(self, jobs[:1], progress)
        raise KeyboardInterrupt

    league.MatchRunner.play = interrupted
    try:
        with pytest.raises(KeyboardInterrupt):
            league.run_league(BOTS, 3, resumed, **QUICK)
    finally:
        league.MatchRunner.play = original
    assert resumed.read_bytes() == saved

    results = league.run_league(BOTS, 3, resumed, **QUICK)
    assert resumed.read_bytes() == straight.read_bytes()
    assert results == json.loads(straight.read_text())
    table = results["table"]
    assert [row["bot"] for row in table][-1] in ("idle", "random")  # the weakest rank last
    assert all(row["elo_low"] <= row["elo"] <= row["elo_high"] for row in table)
    assert sum(row["byes"] for row in table) == 3


def test_a_finished_league_goes_on_to_more_rounds(tmp_path):
    four = tmp_path / "four.json"
    league.run_league(BOTS[:4], 4, four, **QUICK)
    extended = tmp_path / "extended.json"
    league.run_league(BOTS[:4], 2, extended, **QUICK)
    league.run_league(BOTS[:4], 4, extended, **QUICK)
    assert extended.read_bytes() == four.read_bytes()


def test_a_results_file_of_another_league_is_refused_untouched(tmp_path):
    path = tmp_path / "league.json"
    league.run_league(BOTS[:4], 2, path, **QUICK)
    before = path.read_bytes()
    with pytest.raises(league.LeagueFileError, match="its seed is 1, this run's is 2"):
        league.run_league(BOTS[:4], 3, path, **{**QUICK, "seed": 2})
    with pytest.raises(league.LeagueFileError, match="its pairing is 'swiss'"):
        league.run_league(BOTS[:4], 3, path, **{**QUICK, "pairing": "sampled"})
    with pytest.raises(league.LeagueFileError, match="already holds 2 rounds"):
        league.run_league(BOTS[:4], 1, path, **QUICK)
    data = json.loads(before)
    data["rounds"][1]["pairs"][0].reverse()  # edited by hand
    tampered = tmp_path / "tampered.json"
    tampered.write_text(json.dumps(data))
    with pytest.raises(league.LeagueFileError, match="round 2 is not the round"):
        league.run_league(BOTS[:4], 3, tampered, **QUICK)
    replay_like = tmp_path / "other.json"
    replay_like.write_text('{"format": "spacewar-replay"}')
    with pytest.raises(Exception, match="replay|not a league"):
        league.run_league(BOTS[:4], 3, replay_like, **QUICK)
    assert path.read_bytes() == before


@pytest.mark.parametrize("bad, message", [
    (dict(rounds=0), "rounds must be an int >= 1"),
    (dict(pairing="knockout"), "pairing must be one of swiss, sampled"),
    (dict(bootstrap=-1), "bootstrap must be an int >= 0"),
    (dict(bots=["chaser"]), "at least two bots"),
    (dict(bots=["chaser", "chaser"]), "each bot may enter once"),
])
def test_bad_league_settings_are_refused_before_anything_is_written(tmp_path, bad, message):
    args = dict(bots=BOTS, rounds=2, out=tmp_path / "x.json", **QUICK)
    args.update(bad)
    with pytest.raises(ValueError, match=message):
        league.run_league(**args)
    assert not (tmp_path / "x.json").exists()


def test_a_directory_of_submissions_is_read_without_running_any_of_it(tmp_path):
    marker = tmp_path / "ran"
    (tmp_path / "good.py").write_text(
        f"open({str(marker)!r}, 'w').write('x')\n"
        "class Helper:\n    pass\n"
        "class Hunter:\n    def act(self, obs):\n        return None\n"
        "class Farm:\n    act_batch = None\n")
    (tmp_path / "nothing.py").write_text("x = 1\n")
    (tmp_path / "cookie.py").write_bytes(b"# -*- coding: no-such-codec -*-\nclass A:\n  def act(s, o): pass\n")
    (tmp_path / "notes.txt").write_text("class Fake:\n    def act(self, obs): pass\n")
    os.mkfifo(tmp_path / "pipe.py")
    specs, skipped = bots_in(tmp_path)
    assert specs == [f"{tmp_path / 'good.py'}:Hunter", f"{tmp_path / 'good.py'}:Farm"]
    assert set(skipped) == {str(tmp_path / n) for n in ("nothing.py", "cookie.py", "pipe.py")}
    assert not marker.exists()


def test_the_league_command_plays_a_directory_of_bots_hostile_ones_included(tmp_path, capsys):
    from spacewar.cli import main

    bots_dir = tmp_path / "bots"
    bots_dir.mkdir()
    (bots_dir / "a_gcs.py").write_text(
        "import gc\nfrom spacewar import NOOP\n\n\nclass GcKiller:\n"
        "    def act(self, obs):\n        for o in gc.get_objects():\n"
        "            if type(o).__name__ == 'Game':\n"
        "                o.ship_counters[:, 1 - obs.seat, 7] = 0\n        return NOOP\n")
    (bots_dir / "b_exits.py").write_text(
        "import sys\n\n\nclass ExitInAct:\n    def act(self, obs):\n        sys.exit(3)\n")
    (bots_dir / "README.md").write_text("not a bot")
    out = tmp_path / "league.json"
    args = ["league", "--bots", str(bots_dir), "--rounds", "1", "--out", str(out),
            "--games", "1", "--match-rounds", "1", "--workers", "1", "--no-progress",
            "--bootstrap", "10"]
    assert main(args) == 0
    assert "League: 2 bots, 1 swiss rounds, 2 matches" in capsys.readouterr().out
    assert main(args[:4] + ["2"] + args[5:]) == 0  # resumed and extended
    results = json.loads(out.read_text())
    assert results["rounds_played"] == 2
    rows = {Path(row["bot"]).name: row for row in results["table"]}
    # neither bot reached the game: the exiting bot forfeits, the other wins every match
    assert rows["b_exits.py:ExitInAct"]["forfeits"] + rows["b_exits.py:ExitInAct"]["faults"] > 0
    assert rows["a_gcs.py:GcKiller"]["wins"] == 4
    assert main(args[:6] + [str(out / "x")] + args[7:]) == 2  # a bad path, found first
