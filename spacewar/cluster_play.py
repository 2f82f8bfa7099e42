"""Tournament and league matches on a Dask cluster (``engine.cluster``).

The matches of a run are cut into tasks of many matches each; a task plays its matches on the
worker exactly as a local worker process would (``spacewar.tournament._play``: every bot that
is not built in in its own confined process, with the same limits), so the results are the
same, and they are put back in schedule order.

A bot from a file travels as its bytes with their sha256, never as a pickled class: the worker
checks the hash, writes the file once into a directory named by the hash (atomically), and
plays it from there, each match loading it in a fresh confined process as at home. Module bots
(``package.module:Class``) are refused: their code is a package that would have to be
installed on every worker; give such a bot as a file.
"""
import hashlib
import os
import tempfile

from engine import cluster

from .bots import BotLoadError, _is_file_spec, _split, is_builtin, is_policy_file

#: the largest bot file sent to a cluster (a policy file included)
MAX_BOT_BYTES = 64 << 20


def bot_files(bots):
    """``{spec: (file name, bytes, sha256)}`` for the bots that come from files; built-in
    bots travel by name. Raises BotLoadError for a module bot."""
    files = {}
    for spec in bots:
        if is_policy_file(spec):
            path = spec
        elif is_builtin(spec):
            continue
        else:
            where, _ = _split(spec)
            if not _is_file_spec(where):
                raise BotLoadError(
                    f"bot {spec!r} is a module: on a cluster only built-in bots and bots from "
                    "files can play (a module would have to be installed on every worker); "
                    "give it as path/to/file.py:Class")
            path = where
        size = os.path.getsize(path)
        if size > MAX_BOT_BYTES:
            raise BotLoadError(f"bot file {path!r} is {size} bytes, more than the "
                               f"{MAX_BOT_BYTES} a cluster run sends")
        with open(path, "rb") as f:
            data = f.read()
        files[spec] = (os.path.basename(path), data, hashlib.sha256(data).hexdigest())
    return files


def _materialise(name, data, digest):
    """The path of the bot file on this worker: ``<tmp>/nbody-spacewar-bots/<sha256>/<name>``,
    written once (atomically) after its bytes are checked against the hash."""
    if hashlib.sha256(data).hexdigest() != digest:
        raise ValueError(f"bot file {name!r} arrived with bytes that do not match its sha256")
    folder = os.path.join(tempfile.gettempdir(), "nbody-spacewar-bots", digest)
    path = os.path.join(folder, os.path.basename(name))
    if not os.path.isfile(path):
        os.makedirs(folder, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=folder, prefix=".arriving-")
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        os.chmod(tmp, 0o444)
        os.replace(tmp, path)
    return path


def _local_specs(files):
    """``{client spec: spec on this worker}`` for the bots from files."""
    local = {}
    for spec, (name, data, digest) in files.items():
        path = _materialise(name, data, digest)
        local[spec] = path if is_policy_file(spec) else f"{path}:{spec.rsplit(':', 1)[1]}"
    return local


def play_chunk(task, fingerprint):
    """A task: the outcomes of each job of ``task = (jobs, files)`` (``tournament._play``),
    with the client's bot names; ``files`` holds the bots from files those jobs play."""
    cluster.check_code(fingerprint)
    from .tournament import _play

    jobs, files = task
    local = _local_specs(files)
    back = {v: k for k, v in local.items()}
    out = []
    for matches, together, *rest in jobs:
        rest = list(rest)
        rest[-1] = frozenset(local.get(s, s) for s in rest[-1])  # batch_files
        mine = [(local.get(p1, p1), local.get(p2, p2), seed) for p1, p2, seed in matches]
        outcomes = _play((mine, together, *rest))
        for result, _ in outcomes:
            result["bots"] = [back.get(b, b) for b in result["bots"]]
            for key in ("winner", "forfeit"):  # the fields that name a bot
                if result.get(key) is not None:
                    result[key] = back.get(result[key], result[key])
        out.append(outcomes)
    return out


def _task(jobs, files):
    """A task's payload: its jobs and the files of just the bots they play (a league's task
    carries a few bots' files, not every entrant's)."""
    playing = {spec for job in jobs for match in job[0] for spec in match[:2]}
    return jobs, {spec: f for spec, f in files.items() if spec in playing}


class _GameConnection:
    """A cluster connection with the run's bot files, ready to play jobs."""

    def __init__(self, address, bots):
        self.files = bot_files(bots)
        self.connection = cluster.Connection(address, warm=("spacewar.tournament:warm_up_game",))

    def close(self):
        self.connection.close()


def connect(address, bots):
    """A connection to the cluster at ``address`` for matches among ``bots`` (their files
    read and hashed once); ``close()`` it when done."""
    return _GameConnection(address, bots)


def play_jobs(connection, jobs, progress):
    """Every job's outcomes, in job order, played on the cluster of ``connection``
    (``connect``); ``progress(matches)`` as tasks complete."""
    tasks = [_task(c, connection.files) for c in cluster.chunk(jobs, connection.connection.workers())]
    results = cluster.run_chunks(
        connection.connection, play_chunk, tasks, common=(cluster.code_fingerprint(),),
        progress=lambda task: progress(sum(len(job[0]) for job in task[0])))
    return [outcome for chunk in results for outcomes in chunk for outcome in outcomes]
