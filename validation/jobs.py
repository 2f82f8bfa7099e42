"""Running the report's work: independent jobs, in worker processes when nothing is timed.

A job is a module-level function and its keyword arguments (plain data), so it can run in a
``spawn`` worker. Untimed jobs (errors, energies, stability) run on ``workers`` processes;
timed jobs run one after another in the main process so that they do not compete for a core.
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


def run_jobs(jobs, workers=1, desc="jobs", disable=False):
    """Run ``jobs``; return ``({key: result}, {key: seconds})``."""
    results = {}
    seconds = {}
    jobs = sorted(jobs, key=lambda j: -j.cost)
    bar = tqdm(total=len(jobs), desc=desc, unit="job", disable=disable, dynamic_ncols=True)
    try:
        if workers <= 1 or len(jobs) <= 1:
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
