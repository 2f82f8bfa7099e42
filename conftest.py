"""The test suite run on every core: pytest-xdist's workers, prepared by the controller.

``pytest`` (the README's test command) runs the tests in one pytest-xdist worker process per
core (``pytest_cmdline_main`` below: ``-n auto`` unless ``-n`` is given; ``-n 0`` or
``-p no:xdist`` runs them in one process). docs/testing.md describes the run; here is how:

- **The compiled code made once, first.** Before any worker starts, the controlling process
  fills numba's cache with the tasks of ``python -m engine compile`` and ``spacewar compile``
  (``engine.compile_ahead``: one process per core; milliseconds when the cache is warm),
  holding a lock file in the cache's directory, so that two workers, or two pytest sessions
  sharing the cache, never compile the same kernels into it at the same time.
- **One numba thread per worker**, so that the workers do not take each other's cores. numba's
  thread count stays at its maximum (``NUMBA_NUM_THREADS``, a core each): a test that compares
  one thread with two raises the count itself (``numba.set_num_threads``).
- **Tests that must have the machine to themselves** (``@pytest.mark.serial``: wall-clock
  budgets, hang detection, tests that start a process per core) run after all the others, on
  one worker, while no other test runs; before them each worker is given a test module at a
  time, whole, the long ones first (``ModulesThenSerial``).
- **The browser fixtures** (``chromium``, ``open_page``: tests/browser.py) loaded as a plugin,
  so that any test module can use them; each worker launches a browser of its own.

This file is the repository's, not the suite's rules (tests/conftest.py, which
tests/test_skip_policy.py runs in scratch directories of its own, without this file).
"""
import json
import os
import tempfile
import time

import pytest

#: the fixtures of the tests run in a headless Chromium (tests/browser.py)
pytest_plugins = ("tests.browser",)

#: the marker of the tests that run alone (pyproject.toml registers it)
SERIAL = "serial"

#: the worker input naming the directory where each worker lists its serial tests
_SERIAL_DIR = "nbody_serial_dir"


def _is_worker(config):
    return hasattr(config, "workerinput")


def _xdist_on(config):
    """Does this (controlling) process hand the tests out to pytest-xdist workers?"""
    return config.pluginmanager.hasplugin("xdist") and \
        config.getoption("dist", "no") != "no" and bool(config.getoption("tx", None))


# -- the number of workers ------------------------------------------------------------------------
@pytest.hookimpl(tryfirst=True)
def pytest_cmdline_main(config):
    """``-n auto`` unless ``-n`` was given (before pytest-xdist reads it). Not an ``addopts``
    entry: with pytest-xdist left out (``-p no:xdist``) ``-n`` would be an unknown option.
    Never in a worker: pytest-xdist runs this hook there too, with no ``-n``, and a worker
    given ``-n auto`` would start workers of its own, and they theirs."""
    if _is_worker(config) or os.environ.get("PYTEST_XDIST_WORKER"):
        return
    if config.pluginmanager.hasplugin("xdist") and config.getoption("numprocesses") is None:
        config.option.numprocesses = "auto"


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_auto_num_workers(config):
    """One worker per core this process may run on (``-n auto``), as ``engine.compile_ahead``
    counts them; ``PYTEST_XDIST_AUTO_NUM_WORKERS`` in the environment overrides it."""
    if os.environ.get("PYTEST_XDIST_AUTO_NUM_WORKERS"):
        return None  # pytest-xdist's own hook reads it
    from engine.compile_ahead import default_jobs

    return default_jobs()


# -- the compiled code, made once before the workers start -----------------------------------------
def warm_up(write=print):
    """Run ``python -m engine compile`` and ``spacewar compile``'s tasks that are not fresh
    (``engine.compile_ahead.run``), holding ``warm-up.lock`` in the cache's directory: a second
    session waits for the first, then finds the tasks fresh. Returns the seconds it took."""
    from engine import cache, compile_ahead
    from spacewar.cli.compile_tasks import TASKS

    start = time.perf_counter()
    base = cache.cache_base()
    os.makedirs(base, exist_ok=True)
    with open(os.path.join(base, "warm-up.lock"), "a") as lock:
        try:
            import fcntl
        except ImportError:  # not POSIX: no lock (the tasks are still run once, here)
            fcntl = None
        if fcntl is not None:
            fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            done = {}
            for tasks in (compile_ahead.ENGINE, TASKS):  # as CI's two commands, in that order
                done.update(compile_ahead.run(tasks))
        finally:
            if fcntl is not None:
                fcntl.flock(lock, fcntl.LOCK_UN)
    seconds = time.perf_counter() - start
    if done:
        write(f"compiled code made ahead: {len(done)} tasks ({', '.join(sorted(done))}) in "
              f"{seconds:.0f} s into {cache.cache_dir()}")
    return seconds


@pytest.hookimpl(tryfirst=True)
def pytest_sessionstart(session):
    """In the controlling process (or the only one), before pytest-xdist starts its workers
    (its own ``pytest_sessionstart`` runs last): the compiled code made ahead."""
    config = session.config
    if _is_worker(config) or config.getoption("collectonly"):
        return
    reporter = config.pluginmanager.getplugin("terminalreporter")
    warm_up(reporter.write_line if reporter is not None else print)


# -- one numba thread per worker --------------------------------------------------------------------
def pytest_configure(config):
    if _is_worker(config):
        import numba

        numba.set_num_threads(1)


# -- the serial tests -------------------------------------------------------------------------------
@pytest.hookimpl(optionalhook=True)
def pytest_configure_node(node):
    """The controller gives each worker a directory to list its serial tests in."""
    config = node.config
    if getattr(config, "_nbody_serial_dir", None) is None:
        config._nbody_serial_dir = tempfile.mkdtemp(prefix="pytest-serial-")
    node.workerinput[_SERIAL_DIR] = config._nbody_serial_dir


def pytest_unconfigure(config):
    path = getattr(config, "_nbody_serial_dir", None)
    if path is not None:
        import shutil

        shutil.rmtree(path, ignore_errors=True)


@pytest.hookimpl(trylast=True)
def pytest_collection_modifyitems(config, items):
    """A worker writes down which of its tests are serial (before it reports its collection to
    the controller, which reads the list when it schedules)."""
    if not _is_worker(config) or _SERIAL_DIR not in config.workerinput:
        return
    serial = [item.nodeid for item in items if item.get_closest_marker(SERIAL) is not None]
    path = os.path.join(config.workerinput[_SERIAL_DIR], config.workerinput["workerid"] + ".json")
    with open(path + ".part", "w", encoding="utf-8") as f:
        json.dump(serial, f)
    os.replace(path + ".part", path)


def _serial_ids(directory):
    ids = set()
    for name in os.listdir(directory):
        if name.endswith(".json"):
            with open(os.path.join(directory, name), encoding="utf-8") as f:
                ids.update(json.load(f))
    return ids


#: the test modules that take longest (each from about a minute to five of a worker's time
#: when the cache is cold, measured on the 2-core machine), handed out first, longest first, so
#: that none of them starts near the end while the other workers run out of tests; a module not
#: listed starts in its turn (a stale list costs time, never a test)
LONG_MODULES = (
    "tests/engine/test_tree.py",
    "tests/spacewar/test_train.py",
    "tests/engine/test_collisions.py",
    "tests/engine/test_galaxies_demo.py",
    "tests/spacewar/test_cluster.py",
    "tests/spacewar/test_untrusted_batch_bots.py",
    "tests/validation/test_validation.py",
    "tests/spacewar/test_hostile_entrants.py",
    "tests/spacewar/test_untrusted_bots.py",
    "tests/spacewar/test_league.py",
)


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    """``--dist load`` (the default with ``-n``) becomes ``ModulesThenSerial``."""
    if config.getoption("dist") != "load":
        return None
    return _scheduler_class()(config, log)


def _module_order(collection, indices):
    """``indices`` of ``collection`` (node ids) in groups, one per test module: the modules of
    ``LONG_MODULES`` first, in its order, then the others in collection order."""
    groups = {}
    for i in indices:
        groups.setdefault(collection[i].split("::", 1)[0], []).append(i)
    rank = {name: k for k, name in enumerate(LONG_MODULES)}
    names = sorted(groups, key=lambda name: rank.get(name, len(rank)))  # a stable sort
    return [groups[name] for name in names]


def _scheduler_class():
    from xdist.scheduler import LoadScheduling

    class ModulesThenSerial(LoadScheduling):
        """A test module at a time to each worker, whole (its compiled code is compiled or
        loaded by one worker, and its module-scoped fixtures made once), the long modules
        first; then, once no module is left to hand out and every other worker has finished
        its tests, the serial tests, all on one worker (the first to run out of work), one
        after another.

        (A worker runs a test once it has been given the next one, or told to stop: a worker
        is given its next module while it still has one test to run, and the worker chosen
        for the serial tests holds its last test until they come.)"""

        def __init__(self, config, log=None):
            super().__init__(config, log)
            self.groups = []  # modules not yet handed out: lists of indices (not serial)
            self.serial = []  # indices of the serial tests not yet handed out
            self.serial_all = frozenset()
            self.serial_node = None

        def _sync(self):
            self.pending[:] = [i for group in self.groups for i in group]

        @property
        def tests_finished(self):
            return not self.serial and super().tests_finished

        @property
        def has_pending(self):
            return bool(self.serial) or super().has_pending

        def schedule(self):
            assert self.collection_is_completed
            if self.collection is not None:  # a worker added later (one replaced a crashed one)
                for node in self.nodes:
                    self.check_schedule(node)
                return
            if not self._check_nodes_have_same_collection():
                self.log("**Different tests collected, aborting run**")
                return
            self.collection = next(iter(self.node2collection.values()))
            directory = getattr(self.config, "_nbody_serial_dir", None)
            ids = _serial_ids(directory) if directory else set()
            self.serial = [i for i, nodeid in enumerate(self.collection) if nodeid in ids]
            self.serial_all = frozenset(self.serial)
            self.groups = _module_order(self.collection, [
                i for i in range(len(self.collection)) if i not in self.serial_all])
            self._sync()
            for node in self.nodes:
                self.check_schedule(node)

        def _send(self, node, indices):
            self.node2pending[node].extend(indices)
            node.send_runtest_some(indices)

        def check_schedule(self, node, duration=0):
            if node.shutting_down:
                return
            if self.groups:
                if len(self.node2pending[node]) < 2:
                    self._send(node, self.groups.pop(0))
                    self._sync()
                return
            if not self.serial:
                node.shutdown()
                return
            if self.serial_node is None:
                self.serial_node = node
            if node is not self.serial_node:
                node.shutdown()
                return
            if any(pending for other, pending in self.node2pending.items() if other is not node):
                return  # the other workers' last tests still run
            serial, self.serial = self.serial, []
            self._send(node, serial)
            node.shutdown()

        def mark_test_complete(self, node, item_index, duration=0):
            self.node2pending[node].remove(item_index)
            self.check_schedule(node, duration=duration)
            if self.serial_node is not None and node is not self.serial_node:
                self.check_schedule(self.serial_node)

        def mark_test_pending(self, item):
            assert self.collection is not None
            self.groups.insert(0, [self.collection.index(item)])
            self._sync()
            for node in self.nodes:
                self.check_schedule(node)

        def remove_node(self, node):
            pending = self.node2pending.pop(node)
            if node is self.serial_node:
                self.serial_node = None
            crashitem = None
            if pending:  # the worker crashed: the others take its tests
                assert self.collection is not None
                crashitem = self.collection[pending.pop(0)]
                self.serial[:0] = [i for i in pending if i in self.serial_all]
                rest = [i for i in pending if i not in self.serial_all]
                if rest:
                    self.groups.insert(0, rest)
                    self._sync()
            for other in self.nodes:
                self.check_schedule(other)
            return crashitem

    return ModulesThenSerial
