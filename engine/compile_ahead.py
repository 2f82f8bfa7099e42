"""Compile ahead: fill the compiled-code cache for a command's kernels, on every core at once.

numba compiles on one core, and a first run of the tour compiles a dozen integrators one after
another. Here the work is cut into *tasks* (a function run once for its compiles: one
integrator's first steps, one game frame) spread over worker processes; each writes its
compiled code to the shared cache (``engine.cache``), and the command that follows loads it.

A task that ran records, in the cache's ``ahead/`` directory, the compiled functions it entered
from Python and the dependency stamp of each (``engine.cache.dependency_stamp``). It is still
*fresh* while every stamp is the same; a stale or unknown task runs again. Checking costs a
file read and the stamps (the project's sources hashed once): a warm start pays milliseconds.
The check only decides what to compile ahead: a task wrongly taken as fresh is compiled by the
command itself, in its own process, as without this module. ``NBODY_COMPILE_AHEAD=0`` in the
environment switches compiling ahead off (everything is then compiled where it is used).

    python -m engine compile               # the tour, every force kernel, Batch's executors
    python -m engine compile --jobs 2 --list

A task is ``Task(name, "module:function", args)``; other packages list their own (the game:
``spacewar compile``) and run them with ``run``.
"""
import argparse
import concurrent.futures
import concurrent.futures.process
import importlib
import json
import multiprocessing
import os
import sys
import time
from collections import namedtuple

from . import cache
from .atomic import atomic_write

Task = namedtuple("Task", "name target args")

#: the tour's integrators as tasks, those that share compiled code together (the five
#: splitting methods share one executor, whfast and saba their kernels), the slowest first so
#: that no worker is left with a long one at the end
TOUR = (
    Task("tour-ias15", "engine.__main__:first_runs", ("ias15",)),
    Task("tour-wisdom-holman", "engine.__main__:first_runs", ("whfast", "saba")),
    Task("tour-janus", "engine.__main__:first_runs", ("janus",)),
    Task("tour-rk45", "engine.__main__:first_runs", ("rk45",)),
    Task("tour-rk4", "engine.__main__:first_runs", ("rk4",)),
    Task("tour-splitting", "engine.__main__:first_runs",
         ("symplectic_euler", "leapfrog", "verlet", "yoshida4", "pefrl")),
    Task("tour-euler", "engine.__main__:first_runs", ("euler",)),
)

#: the rest of what the engine's users (and its tests) compile first: every force term's
#: kernels, and ``engine.Batch``'s executors
ENGINE = TOUR + (
    Task("engine-batch", "engine.compile_ahead:batch_steps", ()),
    Task("engine-forces", "engine.compile_ahead:force_kernels", ()),
)


def force_kernels():
    """Every force term's kernels (``engine.forces.dispatch.kernel_addresses``)."""
    from .forces import dispatch, registry

    for entry in registry.entries():
        dispatch.kernel_addresses(entry.kind)


def batch_steps():
    """A step of a small ``engine.Batch`` with each family of its integrators."""
    from . import Batch, forces

    for name in ("leapfrog", "euler", "rk4", "rk45"):
        batch = Batch(systems=2, dim=2, integrator=name, dt=0.01)
        batch.add_many(mass=1.0, pos=[[1.0, 0.0]], vel=[[0.0, 1.0]])
        batch.add_force(forces.PointMass(mu=1.0))
        batch.step(2)


def _ahead_dir():
    return os.path.join(cache.cache_dir(), "ahead")


def record_path(task):
    return os.path.join(_ahead_dir(), f"{task.name}.json")


def _dispatcher(name):
    """The compiled function ``module:qualname`` names, or None if there is none now."""
    module_name, _, qualname = name.partition(":")
    try:
        obj = importlib.import_module(module_name)
        for part in qualname.split("."):
            obj = getattr(obj, part)
    except (ImportError, AttributeError):
        return None
    return obj if hasattr(obj, "py_func") else None


def fresh(task):
    """Has ``task`` run with the current sources (its record's stamps all current)?"""
    try:
        with open(record_path(task), encoding="utf-8") as f:
            record = json.load(f)
    except (OSError, ValueError):
        return False
    if not isinstance(record, dict) or record.get("args") != list(task.args) \
            or not isinstance(record.get("entered"), dict) or not record["entered"]:
        return False
    for name, stamp in record["entered"].items():
        dispatcher = _dispatcher(name)
        if dispatcher is None or cache.dependency_stamp(dispatcher.py_func) != stamp:
            return False
    return True


def _entered(run):
    """Run ``run()`` and return the compiled functions it entered from Python (compiled or
    loaded there, not inside another's compilation), as ``module:qualname``."""
    from numba.core import event

    entered = set()
    depth = [0]

    class Listener(event.Listener):
        def on_start(self, ev):
            if depth[0] == 0:
                entered.add(ev.data["dispatcher"].py_func)
            depth[0] += 1

        def on_end(self, ev):
            depth[0] -= 1

    listener = Listener()
    loads = cache.record_loads()
    event.register("numba:compile", listener)
    try:
        run()
    finally:
        event.unregister("numba:compile", listener)
        loaded = loads.stop()
    names = {}
    for f in entered | loaded:
        if cache.is_project_function(f):
            names[f"{f.__module__}:{f.__qualname__}"] = cache.dependency_stamp(f)
    return names


def _work(task):
    """A worker's job: run ``task`` and record what it entered. Returns its seconds."""
    start = time.perf_counter()
    module_name, _, function = task.target.partition(":")
    target = getattr(importlib.import_module(module_name), function)
    entered = _entered(lambda: target(*task.args))
    os.makedirs(_ahead_dir(), exist_ok=True)
    atomic_write(record_path(task), json.dumps({"args": list(task.args), "entered": entered},
                                                sort_keys=True))
    return time.perf_counter() - start


def default_jobs():
    """One worker per core this process may run on."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not Linux
        return max(1, os.cpu_count() or 1)


def enabled():
    """False when the environment says ``NBODY_COMPILE_AHEAD=0`` (a profile of what one
    process compiles; a machine where a command must not start processes)."""
    return os.environ.get("NBODY_COMPILE_AHEAD", "1") != "0"


def run(tasks, jobs=None, report=None):
    """Run the tasks that are not fresh in ``jobs`` worker processes (default: one per core);
    ``report(task, seconds)`` after each. Returns ``{task name: seconds}`` of those run
    (nothing when ``enabled()`` is False)."""
    if not enabled():
        return {}
    stale = [task for task in tasks if not fresh(task)]
    jobs = min(jobs or default_jobs(), len(stale))
    done = {}
    if not stale:
        return done
    # a process per task, started afresh (spawn): a fork of a process that has compiled code
    # and threads is not safe, each task must import the sources as they are now, and its
    # record must list all it needs (in a process of its own, nothing is loaded before it)
    context = multiprocessing.get_context("spawn")
    try:
        with concurrent.futures.ProcessPoolExecutor(max_workers=jobs, mp_context=context,
                                                    max_tasks_per_child=1) as pool:
            futures = {pool.submit(_work, task): task for task in stale}
            for future in concurrent.futures.as_completed(futures):
                task = futures[future]
                done[task.name] = future.result()  # a task's own error is raised here
                if report is not None:
                    report(task, done[task.name])
    except (OSError, concurrent.futures.process.BrokenProcessPool):
        # no worker could start or one died (no process allowed, out of memory): what is not
        # compiled ahead is compiled by the command itself
        pass
    return done


def add_arguments(parser):
    parser.add_argument("--jobs", type=int, default=None,
                        help="worker processes (default: one per core)")
    parser.add_argument("--list", action="store_true",
                        help="list the tasks and whether each is fresh; compile nothing")


def main(args, tasks):
    """``python -m engine compile`` (and the game's ``spacewar compile``): run ``tasks``."""
    if args.jobs is not None and args.jobs < 1:
        raise SystemExit(f"--jobs must be at least 1, got {args.jobs}")
    if args.list:
        for task in tasks:
            print(f"{task.name:<28}{'fresh' if fresh(task) else 'to compile'}")
        return
    start = time.perf_counter()

    def report(task, seconds):
        print(f"{task.name:<28}{seconds:7.1f} s", flush=True)

    done = run(tasks, args.jobs, report)
    print(f"{len(done)} of {len(tasks)} tasks compiled in {time.perf_counter() - start:.1f} s "
          f"({len(tasks) - len(done)} fresh) into {cache.cache_dir()}")


def parser(prog="python -m engine compile", description=None):
    out = argparse.ArgumentParser(prog=prog, description=description or __doc__.split("\n\n")[0])
    add_arguments(out)
    return out


if __name__ == "__main__":  # pragma: no cover - the command is ``python -m engine compile``
    main(parser().parse_args(sys.argv[1:]), TOUR)
