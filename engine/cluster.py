"""Running independent work on a Dask cluster: the pieces the tournament, the league and the
validation report share.

Without a scheduler everything runs in local processes as before; with one
(``--scheduler ADDRESS``, or the ``DASK_SCHEDULER_ADDRESS`` variable; ``local`` starts a
``distributed.LocalCluster`` on this machine) the work is cut into tasks of many units each
(a task costs about a millisecond of scheduling, so one match or one sweep point per task would
spend the cluster on bookkeeping), submitted with ``pure=False`` and their explicit seeds, and
gathered as they complete; results are put back in submission order, so the output is the
same as a local run's, byte for byte.

What a worker needs: this project installed at the same code (``code_fingerprint``: a hash of
every source file of ``engine``, ``spacewar`` and ``validation``, not only the version string,
which does not change between commits). Every task carries the client's fingerprint and a
worker with other code refuses it (``CodeMismatch``), so a stale worker fails the run with the
reason instead of playing by other rules. ``WarmWorker``, registered as a worker plugin, checks
the same when the worker joins and compiles or loads the compiled kernels before the first
task, one worker per machine at a time (a file lock), so no task pays the compile and no two
processes write numba's cache at once.

``dask[distributed]`` is the ``[cluster]`` extra, imported only here and only when a scheduler
is asked for.
"""
import fcntl
import functools
import hashlib
import os
import tempfile
from pathlib import Path

#: the environment variable read when no ``--scheduler`` is given (Dask's own name)
SCHEDULER_VARIABLE = "DASK_SCHEDULER_ADDRESS"
#: seconds a run waits for a scheduler's first worker before giving up
WORKER_WAIT = 120
_PACKAGES = ("engine", "spacewar", "validation")
_FINGERPRINT = None


class CodeMismatch(RuntimeError):
    """A worker runs other code than the client: the run cannot give the client's results."""


class SchedulerUnreachable(ConnectionError):
    """No Dask scheduler answered at the address given, or it has no worker."""



def code_fingerprint():
    """sha256 of the project's version and every ``.py`` file of its packages (relative path
    and bytes, in sorted order), computed once per process."""
    global _FINGERPRINT
    if _FINGERPRINT is None:
        from . import __version__

        root = Path(__file__).resolve().parent.parent
        digest = hashlib.sha256(__version__.encode())
        for package in _PACKAGES:
            for path in sorted((root / package).rglob("*.py")):
                digest.update(str(path.relative_to(root)).encode())
                digest.update(b"\0")
                digest.update(path.read_bytes())
        _FINGERPRINT = digest.hexdigest()
    return _FINGERPRINT


def check_code(expected):
    """Raise ``CodeMismatch`` unless this process runs the code ``expected`` names."""
    from . import __version__

    mine = code_fingerprint()
    if mine != expected:
        import socket

        raise CodeMismatch(
            f"worker on {socket.gethostname()} runs nbody-spacewar {__version__} with code "
            f"{mine[:12]}, the client code {expected[:12]}: install the client's version of the "
            "project on every worker (pip install -e '.[cluster]' from the same commit)")


def scheduler_address(requested):
    """The scheduler to use: ``requested`` (an address or ``"local"``), else the
    ``DASK_SCHEDULER_ADDRESS`` variable, else None (local processes)."""
    if requested:
        return requested
    return os.environ.get(SCHEDULER_VARIABLE) or None


def _import_distributed():
    try:
        import distributed
    except ImportError as exc:
        raise ImportError("running on a Dask cluster needs the [cluster] extra: "
                          "pip install -e '.[cluster]'") from exc
    return distributed


class Connection:
    """A client of ``address`` (``"local"``: a LocalCluster of this machine's cores, one
    single-threaded worker process each, closed with the connection), with ``WarmWorker``
    registered for ``warm`` (``"module:function"`` names of warm-up functions)."""

    def __init__(self, address, warm=()):
        distributed = _import_distributed()
        self.cluster = None
        if address == "local":
            self.cluster = distributed.LocalCluster(
                n_workers=os.cpu_count() or 1, threads_per_worker=1, processes=True,
                dashboard_address=":0")
            address = self.cluster.scheduler_address
        try:
            self.client = distributed.Client(address)  # waits distributed.comm.timeouts.connect
        except (OSError, TimeoutError) as exc:
            if self.cluster is not None:
                self.cluster.close()
            raise SchedulerUnreachable(
                f"no Dask scheduler answered at {address!r} ({exc}); start "
                "one with 'dask scheduler' (docs/cluster.md), or use --scheduler local") from None
        try:
            self.client.wait_for_workers(1, timeout=WORKER_WAIT)
        except (TimeoutError, OSError):
            self.close()
            raise SchedulerUnreachable(
                f"the Dask scheduler at {address!r} has had no worker for {WORKER_WAIT} s: start "
                f"some with 'dask worker {address}' (docs/cluster.md)") from None
        self.client.register_plugin(_warm_worker_class()(code_fingerprint(), tuple(warm)),
                                    name="nbody-spacewar-warm")

    def workers(self):
        return max(1, len(self.client.scheduler_info()["workers"]))

    def close(self):
        self.client.close()
        if self.cluster is not None:
            self.cluster.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def chunk(items, workers, per_worker=4, largest=64):
    """``items`` cut into consecutive chunks: about ``per_worker`` chunks a worker (so that a
    slow chunk does not leave the others idle at the end), each of at most ``largest``."""
    items = list(items)
    if not items:
        return []
    size = max(1, min(largest, -(-len(items) // (max(1, workers) * per_worker))))
    return [items[i:i + size] for i in range(0, len(items), size)]


def run_chunks(connection, function, chunks, common=(), progress=None):
    """``function(chunk, *common)`` for each chunk on the cluster, ``pure=False``; the results
    in chunk order. ``progress(chunk)`` is called as each completes. A task that raises (a
    ``CodeMismatch``, a fault of ours) fails the run with its exception; a worker that dies
    has its tasks run again elsewhere (Dask's ``allowed-failures``), which changes nothing,
    as a task's result depends only on its arguments."""
    distributed = _import_distributed()
    client = connection.client
    futures = [client.submit(function, c, *common, pure=False) for c in chunks]
    index = {f.key: i for i, f in enumerate(futures)}
    results = [None] * len(futures)
    try:
        for future in distributed.as_completed(futures):
            i = index[future.key]
            results[i] = future.result()
            if progress is not None:
                progress(chunks[i])
    except BaseException:
        client.cancel(futures)
        raise
    return results


# -- warm workers -----------------------------------------------------------------------------
def warm_engine():
    """Compile (or load) every integrator's kernel on a small gravitating scene."""
    import engine
    from engine import forces

    for integrator in engine.INTEGRATORS:
        sim = engine.Simulation(dim=3, integrator=integrator, dt=0.01)
        sim.add(mass=1.0, pos=(0.0, 0.0, 0.0))
        sim.add(mass=1e-3, pos=(1.0, 0.0, 0.0), vel=(0.0, 1.0, 0.0))
        sim.add_force(forces.NBodyGravity())
        sim.step(2)


def _resolve(name):
    import importlib

    module, function = name.split(":")
    return getattr(importlib.import_module(module), function)


def warm_lock_path():
    """One lock file per machine and code: the workers of one machine warm up one at a time."""
    return os.path.join(tempfile.gettempdir(), f"nbody-spacewar-warm-{code_fingerprint()[:16]}.lock")


def warm_up(names):
    """Call each ``"module:function"`` of ``names`` (each compiles or loads some kernels),
    holding this machine's warm-up lock: the first process compiles and writes numba's cache,
    the next ones wait, then only read it."""
    with open(warm_lock_path(), "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            for name in names:
                _resolve(name)()
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)


@functools.lru_cache(maxsize=None)
def _warm_worker_class():
    """``WarmWorker``, made on first use: its base class is Dask's ``WorkerPlugin``, and
    importing ``distributed`` takes 0.8 s, which every command that only names this module's
    exceptions (``spacewar``'s command line does) would pay at start-up."""
    try:
        from distributed.diagnostics.plugin import WorkerPlugin as base
    except ImportError:  # without the extra the class is never registered
        base = object

    class WarmWorker(base):
        """Worker plugin: refuse other code, then warm up (``warm_up``) before any task."""

        def __init__(self, fingerprint, names):
            self.fingerprint = fingerprint
            self.names = tuple(names)

        def setup(self, worker):
            check_code(self.fingerprint)
            warm_up(self.names)

    WarmWorker.__module__ = __name__
    WarmWorker.__qualname__ = "WarmWorker"  # pickled by reference: engine.cluster.WarmWorker
    return WarmWorker


def __getattr__(name):
    if name == "WarmWorker":
        return _warm_worker_class()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
