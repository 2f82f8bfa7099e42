"""A Dask worker plugin for tests/spacewar/test_cluster.py: the first tournament task to start on
any worker says so and is held until released, so that the test kills a worker that is
certainly running a task (no timed poll of the scheduler).

Its ``setup`` runs in each worker process (a restarted one too) and wraps
``spacewar.arena.cluster.play_chunk``, which the client's tasks name by reference. The first call
across the cluster claims ``claimed`` (an exclusive create), writes ``started`` (its process id
and the task's fingerprint) and waits for ``release``; every call that returns appends its
fingerprint and process id to ``done``."""
import hashlib
import os
import pickle
import time

try:
    from distributed.diagnostics.plugin import WorkerPlugin
except ImportError:  # pragma: no cover - the test needs distributed, this module only its name
    WorkerPlugin = object

STARTED, RELEASE, CLAIMED, DONE = "started", "release", "claimed", "done"


def task_fingerprint(task):
    return hashlib.sha256(pickle.dumps(task)).hexdigest()[:16]


def wait_for(path, timeout):
    """Wait until ``path`` exists; False after ``timeout`` seconds (a failure guard only)."""
    deadline = time.monotonic() + timeout
    while not os.path.exists(path):
        if time.monotonic() > deadline:
            return False
        time.sleep(0.01)
    return True


def _write_whole(path, text):
    """Write ``text`` to ``path`` so that a reader never sees it half written."""
    tmp = f"{path}.{os.getpid()}.tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)


class HoldFirstTask(WorkerPlugin):
    def __init__(self, directory, hold_limit=600.0):
        self.directory = str(directory)
        self.hold_limit = hold_limit

    def setup(self, worker):
        from spacewar.arena import cluster as cluster_play

        self.original = original = cluster_play.play_chunk
        directory, hold_limit = self.directory, self.hold_limit

        def play_chunk(task, fingerprint):
            key = task_fingerprint(task)
            try:
                os.close(os.open(os.path.join(directory, CLAIMED),
                                 os.O_CREAT | os.O_EXCL | os.O_WRONLY))
                first = True
            except FileExistsError:
                first = False
            if first:
                _write_whole(os.path.join(directory, STARTED), f"{os.getpid()} {key}")
                wait_for(os.path.join(directory, RELEASE), hold_limit)
            out = original(task, fingerprint)
            with open(os.path.join(directory, DONE), "a") as f:
                f.write(f"{key} {os.getpid()}\n")
            return out

        play_chunk.__wrapped__ = original
        cluster_play.play_chunk = play_chunk

    def teardown(self, worker):
        from spacewar.arena import cluster as cluster_play

        cluster_play.play_chunk = self.original
