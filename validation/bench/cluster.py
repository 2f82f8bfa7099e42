"""The cluster section of ``python -m validation bench``: tournaments and a validation sweep on
Dask (``engine.cluster``) against local processes, measured side by side in one run.

- matches per second of one 4-bot tournament played by local worker processes, and by a
  ``distributed.LocalCluster`` of 1 and of 2 single-threaded worker processes (started and
  warmed before the clock starts), with a check that the three gave the same JSON;
- the scheduling cost of a task: 1000 empty tasks submitted with ``pure=False`` and gathered
  on the 2-worker cluster, their wall time per task; and the bytes a tournament task moves
  (its arguments and its result, pickled as Dask sends them);
- the wall time of the validation report's untimed runs on local processes and on the
  2-worker cluster.
"""
import json
import os
import pickle
import time

NAME = "cluster"
KEYS = ("cluster",)
NEEDS = ()

BOTS = ["chaser", "sniper", "dodger", "random"]


def run(quick):
    return {"cluster": bench_cluster(quick)}


def _noop(i):
    return i


def _tournament(games, rounds, **where):
    from spacewar.arena.tournament import run_tournament

    start = time.perf_counter()
    report, _ = run_tournament(BOTS, games=games, rounds=rounds, progress=False, **where)
    return report, time.perf_counter() - start


def _per_task_seconds(client, tasks=1000):
    import distributed

    client.gather([client.submit(_noop, i, pure=False) for i in range(20)])  # warm the path
    start = time.perf_counter()
    futures = [client.submit(_noop, i, pure=False) for i in range(tasks)]
    for _ in distributed.as_completed(futures):
        pass
    return (time.perf_counter() - start) / tasks


def _task_bytes(games, rounds):
    """Pickled sizes of one tournament task's arguments and result, and the task's matches."""
    from engine import cluster
    from spacewar.arena import cluster as cluster_play
    from spacewar.rules import Rules
    from spacewar.sandbox.limits import Limits
    from spacewar.arena.tournament import make_jobs, schedule

    jobs = make_jobs(schedule(BOTS, games, 1), rounds, Rules(), Limits(), 25, "auto", frozenset())
    chunk = cluster.chunk(jobs, 2)[0]
    args = ((chunk, {}), cluster.code_fingerprint())
    result = cluster_play.play_chunk(*args)
    return {"matches": sum(len(job[0]) for job in chunk),
            "argument_bytes": len(pickle.dumps(args, protocol=5)),
            "result_bytes": len(pickle.dumps(result, protocol=5))}


def _sweep_seconds(level, **where):
    from validation import report

    start = time.perf_counter()
    out = report.collect(level, progress=False,
                         sections=("crosscheck", "two_body", "energy_drift", "hard_cases"),
                         **where)
    body = {k: v for k, v in report.jsonable(out).items() if k not in ("meta", "timings")}
    return json.dumps(body, sort_keys=True), time.perf_counter() - start


def bench_cluster(quick=False):
    try:
        import distributed
    except ImportError:
        return {"skipped": "the [cluster] extra is not installed: pip install -e '.[cluster]'"}
    from engine import cluster
    from spacewar.arena.tournament import warm_up_game
    from validation.settings import LEVELS

    games, rounds = (9, 1) if quick else (34, 1)
    level = LEVELS["smoke" if quick else "quick"]
    cluster.warm_up(["spacewar.arena.jobs:warm_up_game", "validation.report:warm_up"])
    warm_up_game()
    local, local_s = _tournament(games, rounds, workers=os.cpu_count() or 1)
    one_process, one_process_s = _tournament(games, rounds, workers=1)
    out = {"bots": BOTS, "games": games, "match_rounds": rounds,
           "matches": len(local["matches"]),
           "local_processes": {"workers": os.cpu_count() or 1, "seconds": local_s},
           "one_process": {"seconds": one_process_s}}
    same = [json.dumps(one_process, sort_keys=True) == json.dumps(local, sort_keys=True)]
    sweep_json, out_sweep_local = _sweep_seconds(level, workers=os.cpu_count() or 1)
    out["sweep"] = {"level": level.name, "local_seconds": out_sweep_local}
    for workers in (1, 2):
        start = time.perf_counter()
        with distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                      dashboard_address=":0") as local_cluster:
            startup = time.perf_counter() - start
            address = local_cluster.scheduler_address
            _tournament(1, 1, scheduler=address)  # workers joined and warmed
            report, seconds = _tournament(games, rounds, scheduler=address)
            same.append(json.dumps(report, sort_keys=True) == json.dumps(local, sort_keys=True))
            out[f"local_cluster_{workers}"] = {"startup_seconds": startup, "seconds": seconds}
            if workers == 2:
                with distributed.Client(address) as client:
                    out["per_task_seconds"] = _per_task_seconds(client)
                swept, out["sweep"]["cluster_seconds"] = _sweep_seconds(level, scheduler=address)
                out["sweep"]["identical"] = swept == sweep_json
    out["identical_json"] = all(same)
    for key in ("local_processes", "one_process", "local_cluster_1", "local_cluster_2"):
        out[key]["matches_per_second"] = out["matches"] / out[key]["seconds"]
    out["task"] = _task_bytes(games, rounds)
    return out


def format_cluster(c):
    """Text lines of the section."""
    if "skipped" in c:
        return [f"  skipped: {c['skipped']}"]
    lines = [f"  tournament of {', '.join(c['bots'])}: {c['matches']} matches of "
             f"{c['match_rounds']} round(s); JSON identical everywhere: {c['identical_json']}"]
    for key, name in (("one_process", "one process"),
                      ("local_processes", f"{c['local_processes']['workers']} local processes"),
                      ("local_cluster_1", "LocalCluster, 1 worker"),
                      ("local_cluster_2", "LocalCluster, 2 workers")):
        row = c[key]
        lines.append(f"  {name:<26}{row['matches_per_second']:>8.1f} matches/s "
                     f"({row['seconds']:.1f} s)")
    t = c["task"]
    lines.append(f"  scheduling: {1e3 * c['per_task_seconds']:.2f} ms per empty task; a task of "
                 f"{t['matches']} matches sends {t['argument_bytes']} bytes and returns "
                 f"{t['result_bytes']}")
    s = c["sweep"]
    lines.append(f"  validation sweep (untimed runs, level {s['level']}): local "
                 f"{s['local_seconds']:.1f} s, LocalCluster of 2 {s['cluster_seconds']:.1f} s, "
                 f"identical: {s['identical']}")
    return lines


def markdown_cluster(c):
    """Markdown lines of the section."""
    if "skipped" in c:
        return [f"Skipped: {c['skipped']}."]
    lines = [f"One tournament of {', '.join(c['bots'])} ({c['matches']} matches of "
             f"{c['match_rounds']} round): the same JSON from every runner: "
             f"**{c['identical_json']}**.", "",
             "| runner | matches/s | wall s | cluster start-up s |", "|---|---|---|---|"]
    for key, name in (("one_process", "one process"),
                      ("local_processes", f"{c['local_processes']['workers']} local processes"),
                      ("local_cluster_1", "LocalCluster, 1 worker"),
                      ("local_cluster_2", "LocalCluster, 2 workers")):
        row = c[key]
        start = f"{row['startup_seconds']:.1f}" if "startup_seconds" in row else ""
        lines.append(f"| {name} | {row['matches_per_second']:.1f} | {row['seconds']:.1f} | "
                     f"{start} |")
    t, s = c["task"], c["sweep"]
    lines += ["", f"Scheduling cost: {1e3 * c['per_task_seconds']:.2f} ms per empty task "
              f"(1000 submitted with `pure=False` and gathered). A tournament task of "
              f"{t['matches']} matches sends {t['argument_bytes']} bytes and returns "
              f"{t['result_bytes']} bytes.", "",
              f"Validation report, untimed runs at level `{s['level']}`: "
              f"{s['local_seconds']:.1f} s on local processes, {s['cluster_seconds']:.1f} s on a "
              f"LocalCluster of 2 workers; identical results: **{s['identical']}**."]
    return lines


def text(r):
    return (["\n10. tournaments and sweeps on Dask (local processes against a LocalCluster)"]
            + format_cluster(r["cluster"]))


def markdown(r):
    return ["## 10. Tournaments and sweeps on Dask", ""] + markdown_cluster(r["cluster"]) + [""]


def targets(r):
    return []
