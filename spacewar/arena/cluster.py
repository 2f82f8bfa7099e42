"""Tournament and league matches on a Dask cluster (``engine.cluster``).

The matches of a run are cut into tasks of many matches each; a task plays its matches on the
worker exactly as a local worker process would (``spacewar.arena.jobs.play_job``: every bot that
is not built in in its own confined process, with the same limits), so the results are the
same, and they are put back in schedule order.

A bot from a file travels as its bytes with their sha256, never as a pickled class. For each
task the worker checks every hash first, then writes the bytes into a private directory of the
task's own (``private_copies``: an unpredictable name, the worker's user's alone, one
sub-directory per entrant so that twins stay apart), plays them from there, each match loading
its bot in a fresh confined process as at home, and removes the directory when the task ends,
also on error. Nothing another local user could have written is read: no path of the worker's
is reused from one task to the next. Module bots (``package.module:Class``) are refused: their
code is a package that would have to be installed on every worker; give such a bot as a file.

Entrants are named by the client's specifications: a task's jobs name them so, and a result
comes back with the client's names of its two seats (``_named_by_seat``), never mapped back
from a worker's path, so two entrants whose files have the same name and bytes stay two.
"""
import contextlib
import hashlib
import os
import shutil
import tempfile

from engine import cluster

from spacewar.sandbox import confinement
from spacewar.bots import BotLoadError, is_builtin, is_file_spec, is_policy_file, split_spec
from spacewar.sandbox.provision import sweep_stale_directories
from spacewar.strangers_files import FileRefused, read_bounded

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
            where, _ = split_spec(spec)
            if not is_file_spec(where):
                raise BotLoadError(
                    f"bot {spec!r} is a module: on a cluster only built-in bots and bots from "
                    "files can play (a module would have to be installed on every worker); "
                    "give it as path/to/file.py:Class")
            path = where
        data = _read_bot_file(path)
        files[spec] = (os.path.basename(path), data, hashlib.sha256(data).hexdigest())
    return files


def _read_bot_file(path):
    """The bytes of the bot file ``path``: a regular file (opened non-blocking, so a FIFO is
    refused, not waited on) of at most ``MAX_BOT_BYTES``, read no further than that."""
    try:
        return read_bounded(path, MAX_BOT_BYTES)
    except FileRefused as exc:
        raise BotLoadError(f"bot file {path!r} is not a regular file" if exc.reason ==
                           "not regular" else f"bot file {path!r} is more than the "
                           f"{MAX_BOT_BYTES} bytes a cluster run sends") from None


#: the start of the name of a task's private directory of bot copies (then the worker's pid)
COPIES_PREFIX = "nbody-spacewar-bot-copies-"


@contextlib.contextmanager
def private_copies(files):
    """``{client spec: spec on this worker}`` for the bots from files of one task
    (``files``: ``bot_files``' entries), while the task runs. Every hash is checked before
    anything is written; each bot's bytes are then written into a sub-directory of their own
    in a fresh private directory (``tempfile.mkdtemp``), which is removed on leaving, also on
    error."""
    for name, data, digest in files.values():
        if hashlib.sha256(data).hexdigest() != digest:
            raise ValueError(f"bot file {name!r} arrived with bytes that do not match its "
                             "sha256")
    if not files:  # built-in bots only: nothing to write
        yield {}
        return
    sweep_stale_directories(COPIES_PREFIX)  # left by workers that were killed
    home = tempfile.mkdtemp(prefix=f"{COPIES_PREFIX}{os.getpid()}-")
    try:
        _open_to_the_bots_user(home)
        local = {}
        for spec, (name, data, _) in files.items():
            path = _write_copy(home, name, data)
            local[spec] = path if is_policy_file(spec) else f"{path}:{spec.rsplit(':', 1)[1]}"
        yield local
    finally:
        shutil.rmtree(home, ignore_errors=True)


def _write_copy(home, name, data):
    """The path of ``data`` written as ``name`` in a new sub-directory of ``home``: each
    entrant's own, so that two files of the same name never meet."""
    from engine.atomic import atomic_write

    folder = tempfile.mkdtemp(dir=home)
    _open_to_the_bots_user(folder)
    path = atomic_write(os.path.join(folder, os.path.basename(name)), data, mode="wb")
    os.chmod(path, 0o444 if confinement.bot_uid() is not None else 0o400)
    return path


def _open_to_the_bots_user(folder):
    """Where bots run as another user (``nobody``, started by root), let it through
    ``folder`` without listing it (0o711): the names inside are unpredictable, so only the
    match, which was told them, finds the files; otherwise ``folder`` stays 0o700."""
    if confinement.bot_uid() is not None:
        os.chmod(folder, 0o711)


def _named_by_seat(result, pair):
    """``result`` with the client's names ``pair`` of its two seats: who won and who forfeited
    follow from the seats (the worker's names of the bots are paths of its own copies)."""
    result["bots"] = list(pair)
    if result.get("winner_seat") is not None:
        result["winner"] = pair[result["winner_seat"]]
    if result.get("forfeit") is not None:  # exactly one seat forfeited
        result["forfeit"] = pair[result["forfeits"].index(True)]
    return result


def play_chunk(task, fingerprint, record=False):
    """A task: the outcomes of each job of ``task = (jobs, files)`` (``jobs.play_job``, with
    each match's replay when ``record``), with the client's bot names; ``files`` holds the
    bots from files those jobs play."""
    cluster.check_code(fingerprint)
    from spacewar.arena.jobs import play_job

    jobs, files = task
    out = []
    with private_copies(files) as local:
        for matches, together, *rest in jobs:
            rest = list(rest)
            rest[-1] = frozenset(local.get(s, s) for s in rest[-1])  # batch_files
            mine = [(local.get(p1, p1), local.get(p2, p2), seed) for p1, p2, seed in matches]
            outcomes = play_job((mine, together, *rest), record)
            for outcome, (p1, p2, _) in zip(outcomes, matches, strict=True):
                _named_by_seat(outcome[0], (p1, p2))
                if record:  # the replay names its bots and holds its result as the client's
                    outcome[2]["bots"] = list(outcome[0]["bots"])
                    outcome[2]["result"] = outcome[0]
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
        self.connection = cluster.Connection(address, warm=("spacewar.arena.jobs:warm_up_game",))

    def close(self):
        self.connection.close()


def connect(address, bots):
    """A connection to the cluster at ``address`` for matches among ``bots`` (their files
    read and hashed once); ``close()`` it when done."""
    return _GameConnection(address, bots)


def play_jobs(connection, jobs, progress, record=False):
    """Every job's outcomes, in job order, played on the cluster of ``connection``
    (``connect``); ``progress(matches)`` as tasks complete. With ``record`` each outcome
    carries its match's replay too (``jobs.play_job``), brought back from the worker."""
    tasks = [_task(c, connection.files) for c in cluster.chunk(jobs, connection.connection.workers())]
    common = (cluster.code_fingerprint(),) + ((True,) if record else ())
    results = cluster.run_chunks(
        connection.connection, play_chunk, tasks, common=common,
        progress=lambda task: progress(sum(len(job[0]) for job in task[0])))
    return [outcome for chunk in results for outcomes in chunk for outcome in outcomes]
