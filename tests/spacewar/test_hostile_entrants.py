"""Entrants are who they are: twins (the same file name and
bytes in two folders) stay two entrants at home and on a cluster; a worker plays the bytes the
client sent and nothing another local user planted, and leaves no copy behind; the same file
under two spellings enters once; a submission's file name reaches the terminal escaped."""
import hashlib
import json
import os
import subprocess
import sys
import tempfile

import pytest

from engine import cluster
from spacewar.bots import BotLoadError
from spacewar.cli import main
from spacewar.arena.league import run_league
from spacewar.arena.tournament import run_tournament

#: the twins' bot: turns, thrusts and fires, which beats a bot that does nothing
TWIN = b'''from spacewar import Action


class Bot:
    def act(self, obs):
        return Action(turn=1, thrust=True, fire=True)
'''

#: what a local attacker plants where a worker used to look for a shipped bot: it would forfeit
PLANTED = b'''class Bot:
    def act(self, obs):
        raise RuntimeError("the planted bot played")
'''

ESCAPE = "\x1b[2J"  # clears the organizer's terminal if printed raw
QUICK = dict(games=1, rounds=1, progress=False)


def _json(data):
    return json.dumps(data, sort_keys=True)


def _twins(tmp_path):
    """``alice/bot.py:Bot`` and ``bob/bot.py:Bot``: the same file name and the same bytes."""
    specs = []
    for who in ("alice", "bob"):
        folder = tmp_path / who
        folder.mkdir()
        (folder / "bot.py").write_bytes(TWIN)
        specs.append(f"{folder / 'bot.py'}:Bot")
    return specs


# -- a cluster whose workers keep their temporary files where the test can see them ----------
@pytest.fixture(scope="module")
def worker_tmp(tmp_path_factory):
    return tmp_path_factory.mktemp("worker-tmp")


@pytest.fixture(scope="module")
def dask_cluster(worker_tmp, optional):
    distributed = optional("distributed")
    cluster.warm_up(["spacewar.arena.jobs:warm_up_game"])  # the workers then only load
    saved = os.environ.get("TMPDIR")
    os.environ["TMPDIR"] = str(worker_tmp)  # the workers' tempfile.gettempdir()
    try:
        local = distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1,
                                         dashboard_address=":0")
    finally:
        if saved is None:
            del os.environ["TMPDIR"]
        else:
            os.environ["TMPDIR"] = saved
    with local:
        yield local


def _bot_copies(folder, data):
    """Files under ``folder`` holding exactly ``data``."""
    found = []
    for root, _, names in os.walk(folder):
        for name in names:
            path = os.path.join(root, name)
            try:
                with open(path, "rb") as f:
                    if f.read(len(data) + 1) == data:
                        found.append(path)
            except OSError:
                pass
    return found


# -- twins ---------------------------------------------------------------------------------------
def test_twins_stay_two_entrants_at_home_and_on_the_cluster(tmp_path, dask_cluster):
    alice, bob = _twins(tmp_path)
    bots = [alice, bob, "idle"]
    local, _ = run_tournament(bots, workers=1, **QUICK)
    rows = {row["bot"]: row for row in local["table"]}
    assert rows[alice]["played"] == rows[bob]["played"] == 4
    assert rows["idle"]["losses"] == 4  # the twins each beat idle twice
    twin_matches = [m for m in local["matches"] if {m["p1"], m["p2"]} == {alice, bob}]
    assert [(m["p1"], m["p2"]) for m in twin_matches] == [(alice, bob), (bob, alice)]
    remote, _ = run_tournament(bots, scheduler=dask_cluster.scheduler_address, **QUICK)
    assert _json(remote) == _json(local)


def test_twins_in_a_league_on_the_cluster_are_the_local_league(tmp_path, dask_cluster):
    twins = _twins(tmp_path)
    quick = dict(games=1, match_rounds=1, progress=False, bootstrap=5)
    run_league(twins, 1, tmp_path / "local.json", workers=1, **quick)
    run_league(twins, 1, tmp_path / "cluster.json", scheduler=dask_cluster.scheduler_address,
               **quick)
    stored = json.loads((tmp_path / "local.json").read_text())
    assert sorted((m["p1"], m["p2"]) for m in stored["rounds"][0]["matches"]) == [
        tuple(twins), tuple(reversed(twins))]
    assert (tmp_path / "cluster.json").read_bytes() == (tmp_path / "local.json").read_bytes()


# -- the cluster's copies -----------------------------------------------------------------------
def test_a_bot_planted_where_a_worker_looked_never_plays_and_no_copy_is_left(
        tmp_path, dask_cluster, worker_tmp):
    alice, bob = _twins(tmp_path)
    digest = hashlib.sha256(TWIN).hexdigest()
    planted = worker_tmp / "nbody-spacewar-bots" / digest / "bot.py"
    planted.parent.mkdir(parents=True, exist_ok=True)
    planted.write_bytes(PLANTED)
    bots = [alice, bob, "idle"]
    local, _ = run_tournament(bots, workers=1, **QUICK)
    remote, _ = run_tournament(bots, scheduler=dask_cluster.scheduler_address, **QUICK)
    assert _json(remote) == _json(local)
    assert all(row["faults"] == row["forfeits"] == 0 for row in remote["table"])
    assert planted.read_bytes() == PLANTED  # left alone, and never played
    # every copy of the twins' bytes the workers made is gone once the run is over
    assert _bot_copies(worker_tmp, TWIN) == []
    assert not [name for name in os.listdir(worker_tmp) if name.startswith("nbody-spacewar-bot-")]


def test_a_tasks_copies_are_private_and_removed_even_on_error(tmp_path):
    from spacewar.arena import cluster as cluster_play

    twins = _twins(tmp_path)
    files = cluster_play.bot_files(twins)
    seen = {}
    with pytest.raises(RuntimeError, match="the task failed"):
        with cluster_play.private_copies(files) as local:
            seen.update(local)
            assert len(set(local.values())) == 2  # each twin has its own copy
            for spec, there in local.items():
                path = there.rsplit(":", 1)[0]
                with open(path, "rb") as f:
                    assert f.read() == TWIN
                home = os.path.dirname(os.path.dirname(path))
                assert os.stat(home).st_mode & 0o077 == 0  # the worker's user's alone
            raise RuntimeError("the task failed")
    assert seen and not any(os.path.exists(there.rsplit(":", 1)[0]) for there in seen.values())


def test_bytes_that_do_not_match_their_hash_are_refused(tmp_path):
    from spacewar.arena import cluster as cluster_play

    files = {"x/bot.py:Bot": ("bot.py", b"print('other code')", "0" * 64)}
    with pytest.raises(ValueError, match="do not match its sha256"):
        with cluster_play.private_copies(files):
            pass


# -- one entrant, one spelling --------------------------------------------------------------------
def _spellings(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "a.py").write_bytes(TWIN)
    os.symlink("a.py", tmp_path / "link.py")
    os.link(tmp_path / "a.py", tmp_path / "hard.py")
    return ["a.py:Bot", "./a.py:Bot", f"{tmp_path / 'a.py'}:Bot", "link.py:Bot", "hard.py:Bot"]


@pytest.mark.parametrize("second", range(1, 5))
def test_a_second_spelling_of_the_same_bot_is_refused_naming_both(tmp_path, monkeypatch, second):
    spellings = _spellings(tmp_path, monkeypatch)
    first, other = spellings[0], spellings[second]
    for run in (lambda bots: run_tournament(bots, workers=1, **QUICK),
                lambda bots: run_league(bots, 1, tmp_path / "league.json", games=1,
                                        match_rounds=1, progress=False, workers=1)):
        with pytest.raises(BotLoadError) as caught:
            run([first, "idle", other])
        assert repr(first) in str(caught.value) and repr(other) in str(caught.value)
    assert not (tmp_path / "league.json").exists()


def test_another_class_of_the_same_file_and_a_twin_are_two_entrants(tmp_path, monkeypatch):
    from spacewar.bots import check_one_spelling_each

    _spellings(tmp_path, monkeypatch)
    (tmp_path / "twin.py").write_bytes(TWIN)
    check_one_spelling_each(["a.py:Bot", "a.py:Other", "twin.py:Bot", "idle", "chaser"])
    with pytest.raises(BotLoadError, match="'chaser'.*'spacewar.bots.chaser:Chaser'"):
        check_one_spelling_each(["chaser", "spacewar.bots.chaser:Chaser"])


def test_a_league_of_a_folder_refuses_a_symlinked_second_entry(tmp_path, capsys):
    folder = tmp_path / "submissions"
    folder.mkdir()
    (folder / "a.py").write_bytes(TWIN)
    os.symlink("a.py", folder / "b.py")
    (folder / "c.py").write_bytes(TWIN)  # a twin: enters
    code = main(["league", "--bots", str(folder), "--rounds", "1", "--out",
                 str(tmp_path / "league.json"), "--no-progress"])
    err = capsys.readouterr().err
    assert code == 2
    assert f"{folder / 'a.py'}:Bot" in err and f"{folder / 'b.py'}:Bot" in err
    assert f"{folder / 'c.py'}" not in err


# -- names reach the terminal escaped -------------------------------------------------------------
@pytest.fixture
def escaped_bot(tmp_path):
    path = tmp_path / f"evil{ESCAPE}.py"
    path.write_bytes(TWIN)
    return f"{path}:Bot", f"{tmp_path}/evil\\x1b[2J.py:Bot"


def _no_raw_escape(text):
    assert "\x1b" not in text
    return text


def test_a_file_name_with_escapes_is_shown_escaped_in_a_tournament_table(escaped_bot, capsys):
    spec, _ = escaped_bot
    assert main(["tournament", "--bots", f"{spec},idle", "--games", "1", "--rounds", "1",
                 "--workers", "1", "--no-progress"]) == 0
    out, err = capsys.readouterr()
    _no_raw_escape(out + err)
    assert "evil\\x1b[2J" in out
    assert main(["tournament", "--bots", f"{spec},idle", "--games", "1", "--rounds", "1",
                 "--workers", "1", "--json"]) == 0
    report = json.loads(_no_raw_escape(capsys.readouterr().out))
    assert spec in report["bots"]  # JSON keeps the name exactly, escaped by json.dumps


def test_a_file_name_with_escapes_is_shown_escaped_in_a_league_and_its_errors(
        escaped_bot, tmp_path, capsys):
    spec, _ = escaped_bot
    assert main(["league", "--bots", f"{spec},idle", "--rounds", "1", "--games", "1",
                 "--match-rounds", "1", "--workers", "1", "--out", str(tmp_path / "l.json"),
                 "--no-progress", "--bootstrap", "0"]) == 0
    out, err = capsys.readouterr()
    _no_raw_escape(out + err)
    assert "evil\\x1b[2J" in out
    # a second spelling of it: the error names both, escaped
    other = "./" + os.path.relpath(spec.rsplit(":", 1)[0]) + ":Bot"
    assert main(["tournament", "--bots", f"{spec},{other}", "--no-progress"]) == 2
    assert "evil\\x1b[2J" in _no_raw_escape(capsys.readouterr().err)
    # a file of a submissions folder that holds no bot: skipped, its name escaped
    folder = tmp_path / "submissions"
    folder.mkdir()
    (folder / f"nobot{ESCAPE}.py").write_text("x = 1\n")
    (folder / "a.py").write_bytes(TWIN)
    (folder / "b.py").write_bytes(TWIN)
    assert main(["league", "--bots", str(folder), "--rounds", "1", "--games", "1",
                 "--match-rounds", "1", "--workers", "1", "--out", str(tmp_path / "f.json"),
                 "--no-progress", "--bootstrap", "0"]) == 0
    err = _no_raw_escape(capsys.readouterr().err)
    assert "nobot\\x1b[2J.py" in err


def test_a_file_name_with_escapes_is_shown_escaped_by_match_and_check(escaped_bot, capsys):
    spec, shown = escaped_bot
    assert main(["match", "--p1", spec, "--p2", "idle", "--rounds", "1"]) == 0
    out, err = capsys.readouterr()
    assert shown in _no_raw_escape(out + err)
    main(["check", spec, "--opponents", "idle"])
    out, err = capsys.readouterr()
    assert "evil\\x1b[2J" in _no_raw_escape(out) and "evil" in out
    _no_raw_escape(err)


def test_an_error_quoting_a_name_raw_is_shown_escaped(monkeypatch, capsys):
    from spacewar import cli

    def fails(args):  # any error message that would quote a submission's words unescaped
        raise BotLoadError(f"bot file evil{ESCAPE}.py cannot be played")

    monkeypatch.setitem(cli.COMMANDS, "bots", fails)
    assert main(["bots"]) == 2
    assert "evil\\x1b[2J.py cannot be played" in _no_raw_escape(capsys.readouterr().err)


def test_directories_left_by_a_killed_process_are_swept_and_a_live_ones_kept(tmp_path,
                                                                             monkeypatch):
    """A seat's and a cluster task's directories are named after their process: one whose
    process is gone (killed by SIGKILL, it cleaned nothing up) is removed by the next one,
    a live process's is kept."""
    from spacewar.sandbox.provision import sweep_stale_directories

    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    gone = subprocess.Popen([sys.executable, "-c", "pass"])
    gone.wait()
    live = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        for pid in (gone.pid, live.pid, os.getpid()):
            (tmp_path / f"some-prefix-{pid}-x1").mkdir()
        (tmp_path / f"other-prefix-{gone.pid}-x1").mkdir()
        sweep_stale_directories("some-prefix-")
        assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
            [f"some-prefix-{live.pid}-x1", f"some-prefix-{os.getpid()}-x1",
             f"other-prefix-{gone.pid}-x1"])
    finally:
        live.kill()
        live.wait()
