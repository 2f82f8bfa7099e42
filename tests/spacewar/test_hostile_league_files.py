"""Hostile league results files (``spacewar.arena.league``): a resume checks every stored round and
match before it uses any of them, and trusts only a file signed with this user's key. Every
forgery is a LeagueFileError naming the file, the round, the match and the field, never a
traceback; a file that is not verified resumes only when asked to, and then says so."""
import copy
import json
import os
import subprocess
import sys
import textwrap

import pytest

from spacewar import replay
from spacewar.arena import league, league_file

BOTS = ["idle", "random"]
ROUNDS = 2
QUICK = dict(games=1, match_rounds=1, workers=1, progress=False, bootstrap=10)


@pytest.fixture(scope="module")
def legit(tmp_path_factory):
    """The bytes of a finished league of two rounds, signed with the test run's key (the one
    conftest's ``replay_key`` points at, set here too: this fixture outlives a test's)."""
    key = tmp_path_factory.getbasetemp() / "replay-key"
    path = tmp_path_factory.mktemp("league") / "league.json"
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("SPACEWAR_REPLAY_KEY_FILE", str(key))
        league.run_league(BOTS, ROUNDS, path, **QUICK)
    return path.read_bytes()


def _write(tmp_path, data):
    path = tmp_path / "league.json"
    path.write_text(json.dumps(data))
    return path


def _refused(tmp_path, data, message, **options):
    """Resuming ``data`` raises LeagueFileError matching ``message``; the file is untouched."""
    path = _write(tmp_path, data)
    before = path.read_bytes()
    with pytest.raises(league.LeagueFileError, match=message) as caught:
        league.run_league(BOTS, ROUNDS, path, **QUICK, **options)
    assert path.read_bytes() == before
    return str(caught.value)


def _a_won_match(data):
    """The first stored match with a winner and no forfeit."""
    return next(m for r in data["rounds"] for m in r["matches"]
                if m["winner"] is not None and not any(m["forfeits"]))


def _set(path, value):
    """An edit of one field of the first round's matches."""
    def edit(data):
        *where, last = path
        record = data["rounds"][0]["matches"]
        for key in where:
            record = record[key]
        record[last] = value
    return edit


def _drop(match, field):
    def edit(data):
        del data["rounds"][0]["matches"][match][field]
    return edit


def _winner_who_did_not_play(data):
    _a_won_match(data)["winner"] = "dodger"


def _bare_number(data):
    data["rounds"][0]["matches"][0] = 7


def _round_that_is_a_list(data):
    data["rounds"][1] = []


def _forfeit_without_its_name(data):
    match = data["rounds"][0]["matches"][0]
    match["forfeits"], match["forfeit"] = [True, False], None


FORGERIES = {
    "a winner who did not play": (_winner_who_did_not_play,
                                  r"round 1, match \d: winner is 'dodger', who did not play"),
    "faults of 1e30": (_set((0, "faults", 0), 1e30),
                       r"round 1, match 1: faults\[0\] must be an int from 0 to 25, got 1e\+30"),
    "a score of strings": (_set((0, "score"), ["1", "0"]),
                           r"round 1, match 1: score\[0\] must be an int from 0 to 6, got '1'"),
    "a score of bools": (_set((0, "score"), [True, False]),
                         r"round 1, match 1: score\[0\] must be an int .*got True"),
    "a score beyond the match": (_set((0, "score"), [7, 0]),
                                 r"round 1, match 1: score\[0\] must be an int from 0 to 6"),
    "negative steps": (_set((1, "steps"), -1), r"round 1, match 2: steps must be an int"),
    "an unknown player": (_set((0, "p1"), "nobody"),
                          r"round 1, match 1: p1 is 'nobody', the schedule gives '"),
    "another seed": (_set((1, "seed"), 12345),
                     r"round 1, match 2: seed is 12345, the schedule gives \d+"),
    "a match record that is a bare number": (
        _bare_number, r"round 1, match 1 must be a match record \(a dict\), got 7"),
    "a match record lacking a field": (_drop(1, "forfeits"),
                                       r"round 1, match 2 lacks the field 'forfeits'"),
    "a match record with a field of its own": (_set((0, "bonus"), 1),
                                               r"round 1, match 1 has an unknown field 'bonus'"),
    "a forfeit the forfeits do not give": (
        _forfeit_without_its_name, r"round 1, match 1: forfeit is None, its forfeits"),
    "a round that is a list": (_round_that_is_a_list,
                               r"round 2 must be a round record \(a dict\), got \[\]"),
}


@pytest.mark.parametrize("forgery", FORGERIES)
def test_each_forged_record_is_refused_naming_its_round_match_and_field(tmp_path, legit,
                                                                         forgery):
    edit, message = FORGERIES[forgery]
    data = json.loads(legit)
    edit(data)
    # refused even when the user trusts the file: the record-by-record checks always hold
    _refused(tmp_path, data, "cannot resume the league from '.*league.json': " + message,
             trust_results=True)


def test_a_stored_value_is_shown_escaped_and_short(tmp_path, legit):
    data = json.loads(legit)
    data["rounds"][0]["matches"][0]["p2"] = "\x1b]0;owned\x07" + "x" * 5000
    text = _refused(tmp_path, data, r"round 1, match 1: p2 is '\\x1b\]0;owned\\x07xx")
    assert "\x1b" not in text and "\x07" not in text and len(text) < 400


def _flip_a_winner(data):
    """The forgery the checks cannot see: a won match's winner and score both flipped."""
    match = _a_won_match(data)
    match["winner"] = match["p2"] if match["winner"] == match["p1"] else match["p1"]
    match["score"].reverse()
    return match["winner"]


def _row(results, bot):
    return next(row for row in results["table"] if row["bot"] == bot)


def test_a_flipped_winner_and_score_is_refused_as_forged_and_resumes_only_when_trusted(
        tmp_path, legit):
    honest = json.loads(legit)
    data = copy.deepcopy(honest)
    new_winner = _flip_a_winner(data)
    text = _refused(tmp_path, data, "the file is forged")
    assert "--trust-results" in text and "trust_results=True" in text

    path = _write(tmp_path, data)
    results = league.run_league(BOTS, ROUNDS, path, **QUICK, trust_results=True)
    assert results["resumed_from"] == [{"signature": "forged", "rounds": ROUNDS}]
    assert _row(results, new_winner)["wins"] == _row(honest, new_winner)["wins"] + 1
    assert ("NOTE: resumed with --trust-results from a forged (signature not matching) results "
            "file: its first 2 rounds are not verified") in league.format_standings(results)
    # the file is now this user's, and keeps its mark when it is resumed again
    again = league.run_league(BOTS, ROUNDS + 1, path, **QUICK)
    assert again["resumed_from"] == [{"signature": "forged", "rounds": ROUNDS}]
    assert "NOTE: resumed with --trust-results" in league.format_standings(again)


def test_a_bad_signature_is_refused_as_forged(tmp_path, legit):
    data = json.loads(legit)
    data["signature"]["hmac_sha256"] = "0" * 64
    assert "the file is forged" in _refused(tmp_path, data, "--trust-results")


def test_an_unsigned_file_is_refused_and_resumes_marked_when_trusted(tmp_path, legit):
    data = json.loads(legit)
    del data["signature"]
    assert "the file is unsigned" in _refused(tmp_path, data, "--trust-results")
    results = league.run_league(BOTS, ROUNDS, _write(tmp_path, data), **QUICK,
                                trust_results=True)
    assert results["resumed_from"] == [{"signature": "unsigned", "rounds": ROUNDS}]
    assert results["table"] == json.loads(legit)["table"]  # the same matches, rated alike


def test_a_file_signed_with_another_key_is_refused_and_resumes_marked_when_trusted(
        tmp_path, legit, monkeypatch):
    data = json.loads(legit)
    del data["signature"]
    ours = os.environ["SPACEWAR_REPLAY_KEY_FILE"]
    monkeypatch.setenv("SPACEWAR_REPLAY_KEY_FILE", str(tmp_path / "another-organizer's-key"))
    data["signature"] = replay.sign(data)
    monkeypatch.setenv("SPACEWAR_REPLAY_KEY_FILE", ours)
    assert "signed with another key" in _refused(tmp_path, data, "--trust-results")
    results = league.run_league(BOTS, ROUNDS, _write(tmp_path, data), **QUICK,
                                trust_results=True)
    assert results["resumed_from"] == [{"signature": "other key", "rounds": ROUNDS}]


def test_a_forged_record_of_resumes_is_refused(tmp_path, legit):
    data = json.loads(legit)
    data["resumed_from"] = [{"signature": "verified", "rounds": 1}]
    _refused(tmp_path, data, r"resumed_from\[0\] must be", trust_results=True)


def test_the_league_command_names_the_option_and_marks_the_table(tmp_path, legit, capsys):
    from spacewar.cli import main

    data = json.loads(legit)
    del data["signature"]
    path = _write(tmp_path, data)
    args = ["league", "--bots", ",".join(BOTS), "--rounds", str(ROUNDS), "--out", str(path),
            "--games", "1", "--match-rounds", "1", "--workers", "1", "--no-progress",
            "--bootstrap", "10"]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "spacewar league: error:" in err and "unsigned" in err and "--trust-results" in err
    assert "Traceback" not in err
    assert main(args + ["--trust-results"]) == 0
    out = capsys.readouterr().out
    assert ("NOTE: resumed with --trust-results from an unsigned results file: its first 2 "
            "rounds are not verified") in out


def test_an_interrupted_league_resumes_to_the_file_of_one_run_straight_through(tmp_path,
                                                                                legit):
    path = tmp_path / "league.json"

    def stop_after_first(results):
        if results["rounds_played"] == 1:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        league.run_league(BOTS, ROUNDS, path, on_round=stop_after_first, **QUICK)
    assert replay.signature_status(json.loads(path.read_text())) == "verified"
    results = league.run_league(BOTS, ROUNDS, path, **QUICK)
    assert path.read_bytes() == legit and "resumed_from" not in results


def test_a_fifo_is_refused_without_blocking(tmp_path, legit):
    fifo = tmp_path / "league.json"
    os.mkfifo(fifo)
    with pytest.raises(league.LeagueFileError, match="not a regular file"):
        league.load_results(fifo, json.loads(legit)["config"])


def test_a_file_larger_than_its_league_can_be_is_refused_unread(tmp_path, legit):
    """A results file of empty lists takes about 25 bytes of memory a byte once parsed: one of
    60 MiB, 1.5 GiB. It is refused by its size before it is read (the bound grows with the
    league: ``max_file_bytes``), in a child under an address-space limit, so that a regression
    fails here and never takes the machine down."""
    config = json.loads(legit)["config"]
    path = tmp_path / "league.json"
    with open(path, "w") as f:
        f.write('{"format": "spacewar-league", "version": 1, "rounds": [')
        f.write("[]," * (20 << 20))
        f.write("[]]}")
    assert league_file.max_file_bytes(config, ROUNDS) < os.path.getsize(path) // 20
    child = textwrap.dedent(f"""
        import json, resource, sys
        from spacewar.arena import league

        def status(field):
            return int(next(line.split()[1] for line in open("/proc/self/status")
                            if line.startswith(field)))

        limit = (status("VmSize") + 512 * 1024) * 1024  # what is mapped now, and 512 MiB
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
        try:
            league.run_league({BOTS!r}, {ROUNDS}, {str(path)!r}, games=1, match_rounds=1,
                              workers=1, progress=False, bootstrap=10)
            message = "resumed"
        except league.LeagueFileError as exc:
            message = str(exc)
        print(json.dumps({{"message": message, "peak_kib": status("VmHWM")}}))
    """)
    done = subprocess.run([sys.executable, "-c", child], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-2000:]
    report = json.loads(done.stdout)
    assert "that 2 rounds of this league can take" in report["message"]
    print(f"peak resident memory of the refusing process: {report['peak_kib'] // 1024} MiB")
