"""Running the report's work: compiling first, then every section's untimed runs on the
workers, then the timed work in this process; and the results as JSON."""
import math
import os
import platform
import time

import numpy as np

import engine

from .. import work_precision
from ..jobs import run_jobs
from ..problems import kepler, make_sim
from ..reference import rebound_version
from .registry import PHASES, SECTIONS, chosen


def warm_up():
    """Compile (or load from numba's on-disk cache) everything the runs call, in this process,
    before the workers start: the workers then only read the cache, never write it at the same
    time (numba's cache files are not safe against two processes compiling into them at once).
    """
    p = kepler(0.5)
    for name in engine.integrators.GENERAL:
        sim = make_sim(p, name, 0.01)
        sim.step(2)
        sim.integrate(0.05)
    sim.energy()
    sim.momentum()
    sim.angular_momentum()
    sim.center_of_mass()
    engine.analytic.kepler(p.pos[0], p.vel[0], 1.0, 1.0)
    engine.analytic.kepler(p.pos[0], p.vel[0], 1.0, np.array([1.0, 2.0]))


def collect(level, workers=2, progress=True, sections=SECTIONS, scheduler=None):
    """Run the report's work; the untimed runs on ``workers`` processes, or on the Dask
    cluster at ``scheduler`` (``engine.cluster.scheduler_address``: an address, ``"local"``,
    or the ``DASK_SCHEDULER_ADDRESS`` variable); the timed sweeps always here, one at a time.

    The results are gathered section by section in the report's order, those timed alone
    last (after everything else, in this process)."""
    from engine.cluster import scheduler_address

    scheduler = scheduler_address(scheduler)
    t_start = time.perf_counter()
    warm_up()
    modules = chosen(sections)
    jobs = [job for module in modules for job in module.jobs(level)]
    t_a = time.perf_counter()
    results, _ = run_jobs(jobs, workers=workers, desc="untimed runs", disable=not progress,
                          scheduler=scheduler)
    spent = dict.fromkeys(PHASES, 0.0)
    spent["untimed"] = time.perf_counter() - t_a

    out = {"meta": meta(level, workers, scheduler)}
    for module in sorted(modules, key=lambda m: m.PHASE == "alone"):
        start = time.perf_counter()
        out[module.NAME] = module.gather(level, results, progress)
        if module.PHASE != "untimed":
            spent[module.PHASE] += time.perf_counter() - start
    out["timings"] = {"wall_s": time.perf_counter() - t_start,
                      **{key: spent[phase] for phase, key in PHASES.items()}}
    return out


def meta(level, workers, scheduler=None):
    import numba
    return {
        "level": level.name, "engine_version": engine.__version__,
        "rebound_version": rebound_version(), "numpy_version": np.__version__,
        "numba_version": numba.__version__, "python_version": platform.python_version(),
        "machine": platform.machine(), "cpu_count": os.cpu_count(), "workers": workers,
        "scheduler": scheduler,
        "integrators": list(engine.integrators.GENERAL),
        "work_precision_methods": {m.key: m.description for m in work_precision.METHODS.values()},
        "force_evaluations_per_step": dict(engine.integrators.FORCE_EVALUATIONS),
    }


def jsonable(x):
    if isinstance(x, dict):
        return {str(k): jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        return jsonable(x.tolist())
    if isinstance(x, (np.floating, float)):
        x = float(x)
        return x if math.isfinite(x) else ("inf" if x > 0 else "-inf" if x < 0 else "nan")
    if isinstance(x, (np.integer,)):
        return int(x)
    if isinstance(x, np.bool_):
        return bool(x)
    return x
