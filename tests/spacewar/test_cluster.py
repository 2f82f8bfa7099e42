"""Tournaments on a Dask cluster (``spacewar.arena.cluster``, ``engine.cluster``): the same JSON
as local processes, bots from files (hostile ones included) sent as bytes, a worker killed
mid-run changing nothing, a worker with other code refused; a league and a validation sweep on
the cluster giving the local results."""
import json
import os
import signal
import threading
from pathlib import Path

import pytest

from engine import cluster
from spacewar.arena import cluster as cluster_play
from spacewar.bots import BotLoadError
from spacewar.arena.tournament import run_tournament

from . import held_task

HOSTILE = str(Path(__file__).with_name("hostile_bots.py"))


@pytest.fixture(scope="module")
def distributed(optional):
    return optional("distributed")


@pytest.fixture(scope="module")
def dask_cluster(distributed):
    cluster.warm_up(["spacewar.arena.jobs:warm_up_game"])  # the workers then only load
    with distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1,
                                  dashboard_address=":0") as local:
        yield local


def _json(report):
    return json.dumps(report, sort_keys=True)


def test_a_tournament_on_the_cluster_is_the_local_one_byte_for_byte(dask_cluster):
    bots = ["chaser", "sniper", f"{HOSTILE}:ReducePayload", f"{HOSTILE}:ExitInAct"]
    local, _ = run_tournament(bots, games=1, rounds=1, workers=1, progress=False)
    remote, _ = run_tournament(bots, games=1, rounds=1, progress=False,
                               scheduler=dask_cluster.scheduler_address)
    assert _json(remote) == _json(local)
    # the hostile bots played, lost their turns or forfeited, and were reported
    rows = {row["bot"]: row for row in remote["table"]}
    assert rows[f"{HOSTILE}:ExitInAct"]["forfeits"] + rows[f"{HOSTILE}:ExitInAct"]["faults"] > 0
    assert rows[f"{HOSTILE}:ReducePayload"]["faults"] > 0


def test_the_scheduler_variable_is_read(dask_cluster, monkeypatch):
    monkeypatch.setenv(cluster.SCHEDULER_VARIABLE, dask_cluster.scheduler_address)
    assert cluster.scheduler_address(None) == dask_cluster.scheduler_address
    assert cluster.scheduler_address("tcp://elsewhere:8786") == "tcp://elsewhere:8786"
    monkeypatch.delenv(cluster.SCHEDULER_VARIABLE)
    assert cluster.scheduler_address(None) is None


def test_a_worker_killed_mid_run_changes_nothing(dask_cluster, distributed, tmp_path):
    """The first task to start is held (tests/spacewar/held_task.py) until its worker is
    killed: the kill certainly interrupts a running task, which Dask then runs again on
    another worker process, and the report is the local one."""
    bots = ["chaser", "sniper", "dodger", "random"]
    local, _ = run_tournament(bots, games=3, rounds=1, workers=1, progress=False)
    pids = {nanny.process.process.pid for nanny in dask_cluster.workers.values()}
    # registered (and removed below) by a client of its own, before and after the run: the
    # run's client runs on its own thread
    with distributed.Client(dask_cluster.scheduler_address) as client:
        client.register_plugin(held_task.HoldFirstTask(tmp_path), name="hold-first-task")
    out = {}

    def run():
        try:
            out["report"], _ = run_tournament(bots, games=3, rounds=1, progress=False,
                                              scheduler=dask_cluster.scheduler_address)
        except BaseException as exc:  # reported below, with the test's failure
            out["error"] = repr(exc)

    thread = threading.Thread(target=run)
    thread.start()
    try:
        started = tmp_path / held_task.STARTED
        assert held_task.wait_for(started, 300), "no task started on the cluster"
        pid, key = started.read_text().split()
        assert int(pid) in pids  # a worker process, held inside its task
        os.kill(int(pid), signal.SIGKILL)
    finally:
        (tmp_path / held_task.RELEASE).touch()
        thread.join(600)
        with distributed.Client(dask_cluster.scheduler_address) as client:
            client.unregister_worker_plugin("hold-first-task")
    assert not thread.is_alive()
    assert "error" not in out, out["error"]
    assert _json(out["report"]) == _json(local)
    # the held task never finished where it was killed: it was run again by another process
    done = [line.split() for line in (tmp_path / held_task.DONE).read_text().splitlines()]
    assert [p for k, p in done if k == key] and all(p != pid for k, p in done if k == key)


def test_a_worker_with_other_code_is_refused(dask_cluster):
    with cluster.Connection(dask_cluster.scheduler_address) as connection:
        jobs = [([("chaser", "sniper", 1)], False, 1, {}, None, 1, "auto", frozenset())]
        with pytest.raises(cluster.CodeMismatch, match="install the client's version"):
            cluster.run_chunks(connection, cluster_play.play_chunk, [(jobs, {})],
                               common=("0" * 64,))


def test_module_bots_cannot_travel_and_forged_bytes_are_refused(tmp_path):
    with pytest.raises(BotLoadError, match="is a module"):
        cluster_play.bot_files(["chaser", "spacewar.bots.chaser:Chaser"])
    with pytest.raises(ValueError, match="do not match its sha256"):
        with cluster_play.private_copies({"bot.py:Bot": ("bot.py", b"print('other code')",
                                                         "0" * 64)}):
            pass


def test_a_task_carries_only_the_files_of_its_own_bots():
    files = {f"{HOSTILE}:ExitInAct": ("h.py", b"x", "1"), f"{HOSTILE}:GcKiller": ("h.py", b"x", "1"),
             "p.npz": ("p.npz", b"y", "2")}
    jobs = [([("chaser", f"{HOSTILE}:ExitInAct", 5)], False)]
    assert cluster_play._task(jobs, files) == (jobs, {f"{HOSTILE}:ExitInAct": files[f"{HOSTILE}:ExitInAct"]})


def test_chunks_keep_the_order_and_bound_their_size():
    items = list(range(1000))
    chunks = cluster.chunk(items, workers=2)
    assert [x for c in chunks for x in c] == items
    assert max(len(c) for c in chunks) <= 64 and len(chunks) >= 8
    assert cluster.chunk([], 4) == []


def test_a_league_on_the_cluster_writes_the_local_file_byte_for_byte(dask_cluster, tmp_path):
    from spacewar.arena.league import run_league

    bots = ["chaser", "sniper", "dodger", "random", f"{HOSTILE}:ExitInAct"]
    quick = dict(games=1, match_rounds=1, progress=False, bootstrap=20)
    run_league(bots, 2, tmp_path / "local.json", workers=1, **quick)
    run_league(bots, 2, tmp_path / "cluster.json", scheduler=dask_cluster.scheduler_address,
               **quick)
    assert (tmp_path / "cluster.json").read_bytes() == (tmp_path / "local.json").read_bytes()


def test_a_validation_sweep_on_the_cluster_is_the_local_one(dask_cluster, optional):
    optional("rebound")
    from validation import report
    from validation.settings import LEVELS

    untimed = ("crosscheck", "two_body", "energy_drift", "hard_cases")

    def results(**where):
        out = report.jsonable(report.collect(LEVELS["smoke"], progress=False, sections=untimed,
                                             **where))
        assert set(out) == {"meta", "timings", *untimed}
        return json.dumps({k: v for k, v in out.items() if k not in ("meta", "timings")},
                          sort_keys=True)

    assert results(scheduler=dask_cluster.scheduler_address) == results(workers=1)


def test_an_unreachable_scheduler_is_a_clear_error(capsys, distributed):
    import dask

    from spacewar.cli import main

    with dask.config.set({"distributed.comm.timeouts.connect": "2s"}):
        assert main(["tournament", "--bots", "chaser,sniper", "--games", "1", "--rounds", "1",
                     "--scheduler", "tcp://127.0.0.1:9", "--no-progress"]) == 2
    assert "no Dask scheduler answered at 'tcp://127.0.0.1:9'" in capsys.readouterr().err


def test_a_scheduler_without_workers_is_a_clear_error(monkeypatch, distributed):
    monkeypatch.setattr(cluster, "WORKER_WAIT", 2)
    with distributed.LocalCluster(n_workers=0, dashboard_address=":0") as empty:
        with pytest.raises(cluster.SchedulerUnreachable, match="has had no worker for 2 s"):
            run_tournament(["chaser", "sniper"], games=1, rounds=1, progress=False,
                           scheduler=empty.scheduler_address)
