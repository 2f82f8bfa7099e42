"""Running the report's work: independent jobs, in worker processes when nothing is timed.

A job is a module-level function and its keyword arguments (plain data), so it can run in a
``spawn`` worker. Untimed jobs (errors, energies, stability) run on ``workers`` processes;
timed jobs run one after another in the main process so that they do not compete for a core.
With a Dask scheduler (``--scheduler``, ``engine.cluster``) the untimed jobs run on the cluster
instead, packed into about four tasks a worker of about equal cost; the results are the same
(each job's result depends only on its arguments).
"""
import concurrent.futures as cf
import importlib
import multiprocessing
import time
from dataclasses import dataclass, field

from tqdm import tqdm


@dataclass
class Job:
    key: tuple
    func: str            # "module:function" inside this package
    kwargs: dict = field(default_factory=dict)
    cost: float = 1.0    # rough relative cost, to start the longest jobs first


def _resolve(func):
    module, name = func.split(":")
    return getattr(importlib.import_module(f"validation.{module}"), name)


def _call(func, kwargs):
    t0 = time.perf_counter()
    out = _resolve(func)(**kwargs)
    return out, time.perf_counter() - t0


def run_chunk(chunk, fingerprint):
    """A cluster task: ``[(result, seconds), ...]`` of each ``(func, kwargs)`` of ``chunk``,
    run by a worker that has the client's code (``engine.cluster.check_code``)."""
    from engine.cluster import check_code

    check_code(fingerprint)
    return [_call(func, kwargs) for func, kwargs in chunk]


def pack_by_cost(jobs, bins):
    """``jobs`` (largest cost first) dealt into at most ``bins`` lists of about equal total
    cost: each job to the currently cheapest list (Graham's longest-processing-time rule)."""
    packed = [[] for _ in range(max(1, min(bins, len(jobs))))]
    load = [0.0] * len(packed)
    for job in sorted(jobs, key=lambda j: -j.cost):
        i = load.index(min(load))
        packed[i].append(job)
        load[i] += job.cost
    return [p for p in packed if p]


def _run_on_cluster(jobs, scheduler, bar, results, seconds):
    from engine import cluster

    with cluster.Connection(scheduler, warm=("validation.report:warm_up",)) as connection:
        chunks = pack_by_cost(jobs, 4 * connection.workers())
        done = cluster.run_chunks(
            connection, run_chunk, [[(j.func, j.kwargs) for j in c] for c in chunks],
            common=(cluster.code_fingerprint(),), progress=lambda c: bar.update(len(c)))
    for chunk, outcomes in zip(chunks, done):
        for job, (result, took) in zip(chunk, outcomes):
            results[job.key], seconds[job.key] = result, took


def run_jobs(jobs, workers=1, desc="jobs", disable=False, scheduler=None):
    """Run ``jobs``; return ``({key: result}, {key: seconds})``. ``scheduler``: a Dask
    scheduler's address or ``"local"`` (``engine.cluster``) to run them on a cluster."""
    results = {}
    seconds = {}
    jobs = sorted(jobs, key=lambda j: -j.cost)
    bar = tqdm(total=len(jobs), desc=desc, unit="job", disable=disable, dynamic_ncols=True)
    try:
        if scheduler is not None:
            _run_on_cluster(jobs, scheduler, bar, results, seconds)
        elif workers <= 1 or len(jobs) <= 1:
            for job in jobs:
                results[job.key], seconds[job.key] = _call(job.func, job.kwargs)
                bar.update()
        else:
            ctx = multiprocessing.get_context("spawn")
            with cf.ProcessPoolExecutor(max_workers=workers, mp_context=ctx) as pool:
                futures = {pool.submit(_call, job.func, job.kwargs): job for job in jobs}
                for fut in cf.as_completed(futures):
                    job = futures[fut]
                    results[job.key], seconds[job.key] = fut.result()
                    bar.update()
    finally:
        bar.close()
    return results, seconds
