"""Where a tournament's or a league's matches are played: ``MatchRunner`` (this process, a
pool of local worker processes, or a Dask cluster: the same outcomes in the same order), and
the progress bar they report to."""
import concurrent.futures
import multiprocessing

from spacewar.arena.jobs import play_job, warm_up, worker_start


class MatchRunner:
    """Where matches are played, kept open across calls (a league plays round after round):
    in this process (``workers=1``), in a pool of ``workers`` local processes, or on the Dask
    cluster at ``scheduler`` (an address, or ``"local"``; default: ``DASK_SCHEDULER_ADDRESS``,
    else local). ``play(jobs, progress)`` gives every job's outcomes in job order whichever it
    is, so the results are the same; ``play(jobs, progress, record=True)`` brings each match's
replay back too (``jobs.play_job``), from the worker processes or the cluster."""

    def __init__(self, bots, rules, workers, scheduler=None):
        from engine.cluster import scheduler_address

        self.address = scheduler_address(scheduler)
        self.bots, self.rules, self.workers = list(bots), rules, workers
        self._pool = self._connection = None

    def play(self, jobs, progress=lambda matches: None, record=False):
        if self.address is not None:
            return self._play_on_cluster(jobs, progress, record)
        if self.workers == 1:
            outcomes = []
            for job in jobs:
                outcomes.extend(play_job(job, record))
                progress(len(job[0]))
            return outcomes
        if self._pool is None:
            warm_up(self.rules)
            ctx = multiprocessing.get_context("spawn")
            self._pool = concurrent.futures.ProcessPoolExecutor(
                max_workers=self.workers, mp_context=ctx, initializer=worker_start)
        futures = {self._pool.submit(play_job, job, record): len(job[0]) for job in jobs}
        for future in concurrent.futures.as_completed(futures):
            future.result()  # surface worker errors early
            progress(futures[future])
        return [outcome for f in futures for outcome in f.result()]

    def _play_on_cluster(self, jobs, progress, record):
        from spacewar.arena import cluster as cluster_play

        if self._connection is None:
            self._connection = cluster_play.connect(self.address, self.bots)
        return cluster_play.play_jobs(self._connection, jobs, progress, record)

    def close(self):
        if self._pool is not None:
            self._pool.shutdown(cancel_futures=True)
            self._pool = None
        if self._connection is not None:
            self._connection.close()
            self._connection = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


class NoBar:
    """A progress bar that shows nothing."""

    def update(self, n):
        pass

    def close(self):
        pass


def progress_bar(total, enabled, what="tournament"):
    if not enabled:
        return NoBar()
    try:
        from tqdm import tqdm
    except ImportError:
        return NoBar()
    return tqdm(total=total, unit="match", desc=what, leave=False)
