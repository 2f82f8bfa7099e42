"""Round-robin tournaments: every pair of bots, both seat orders, games in worker processes.

Each pair plays ``games`` seeds in both seat orders (the same seeds each way, so neither bot
gets the luckier seat). Match seeds derive from the tournament seed and the match's place in
the schedule, and results are gathered in schedule order, so the same seed gives the same
table whatever the number of workers.

No bot's code runs in the tournament's processes: specifications are checked without
importing them, and each non-built-in bot is loaded only in its own confined process. A bot
that cannot start forfeits its matches; the table is printed all the same.

Ratings are Elo-scale Bradley-Terry strengths fitted to all results at once (a draw counts
half a win each way), which unlike sequential Elo updates does not depend on game order:
P(i beats j) = 1 / (1 + 10^((R_j - R_i) / 400)). Each bot also plays one virtual draw
against a 1500-rated anchor, so a perfect record gives a finite rating (Hunter 2004, MM
algorithm; the virtual draw is a standard prior).
"""
import concurrent.futures
import itertools
import math
import multiprocessing
import os

import numpy as np

from .match import DEFAULT_BUDGET, DEFAULT_MAX_FAULTS, play_match
from .rules import Rules
from .seats import Limits, printable


def schedule(bots, games, seed):
    """The list of (p1, p2, match_seed) in a fixed order."""
    out = []
    for pair, (a, b) in enumerate(itertools.combinations(range(len(bots)), 2)):
        for g in range(games):
            match_seed = int(np.random.SeedSequence([int(seed), pair, g]).generate_state(1)[0])
            out.append((bots[a], bots[b], match_seed))
            out.append((bots[b], bots[a], match_seed))
    return out


def _play(job):
    """A job's outcomes ``[(result, timing), ...]``: one match, or every match of a pairing
    with a batch bot, played together (``spacewar.batch_match``)."""
    matches, together, rounds, rules_dict, limits, max_faults, isolation, batch_files = job
    rules = Rules.from_dict(rules_dict)
    if together:
        from .batch_match import play_matches

        return play_matches(matches, rounds=rounds, rules=rules, limits=limits,
                            max_faults=max_faults, batch_files=batch_files)
    (p1, p2, match_seed), = matches
    result, _, timing = play_match(p1, p2, seed=match_seed, rounds=rounds, rules=rules,
                                   limits=limits, max_faults=max_faults, isolation=isolation)
    return [(result, timing)]


def batch_files_of(bots):
    """The bots from files among ``bots`` that play as batch bots (their class defines
    ``act_batch``: ``spacewar.bots.declares_act_batch``), read once for the whole run."""
    from .bots import declares_act_batch

    return frozenset(spec for spec in bots if declares_act_batch(spec))


def group_jobs(schedule_, isolation, batch_files=frozenset()):
    """The schedule cut into jobs ``(matches, together)``: each match alone, except that a
    pairing with a batch bot (a policy file, or a bot from a file in ``batch_files``) and a
    bot that can share its game (``batch_match.can_play_together``) is one job, all its
    matches in one game, the batch bot answering for all of them at once (at most
    ``wire.MAX_ROWS`` matches a job). Under ``isolation="process"`` every match plays alone."""
    from .batch_match import can_play_together, is_batch_spec
    from .wire import MAX_ROWS

    jobs = []
    for p1, p2, seed in schedule_:
        together = (isolation != "process"
                    and (is_batch_spec(p1, batch_files) or is_batch_spec(p2, batch_files))
                    and can_play_together(p1, batch_files)
                    and can_play_together(p2, batch_files))
        if together and jobs and jobs[-1][0] and {p1, p2} == jobs[-1][2] \
                and len(jobs[-1][1]) < MAX_ROWS // 2:
            jobs[-1][1].append((p1, p2, seed))
        else:
            jobs.append((together, [(p1, p2, seed)], {p1, p2}))
    return [(matches, together) for together, matches, _ in jobs]


def _worker_start():
    """A worker dies with the tournament's process (and its bots with it), instead of waiting
    forever on a queue nobody feeds."""
    from .confinement import die_with_parent

    die_with_parent()


def warm_up_game():
    """A cluster worker's warm-up (``engine.cluster.WarmWorker``): the game's kernels."""
    _warm_up(Rules())


def _warm_up(rules):
    """Compile (or load) the game's code here, once, before the workers start: workers then
    only read numba's cache instead of all compiling and writing it at the same time."""
    from .game import Game

    Game(rules, seeds=[0], rounds=1).step()


def bradley_terry_elo(names, results, iterations=2000):
    """Elo-scale ratings from (p1, p2, outcome) with outcome 1, 0.5 or 0 for p1."""
    k = len(names)
    index = {n: i for i, n in enumerate(names)}
    wins = np.zeros((k, k))
    for p1, p2, outcome in results:
        i, j = index[p1], index[p2]
        wins[i, j] += outcome
        wins[j, i] += 1.0 - outcome
    elo = bradley_terry_fit(wins, iterations)
    return {n: float(elo[index[n]]) for n in names}


def bradley_terry_fit(wins, iterations=2000):
    """Elo-scale Bradley-Terry ratings (an array) from ``wins[i, j]``, the games i won against
    j (a draw half each way): Hunter's (2004) MM iteration, each bot also drawing once with
    an anchor of strength 1 (1500)."""
    games = wins + wins.T
    strength = np.ones(wins.shape[0])
    won = wins.sum(axis=1) + 0.5
    for _ in range(iterations):
        denom = (games / (strength[:, None] + strength[None, :])).sum(axis=1) + 1.0 / (strength + 1.0)
        new = won / denom
        if np.allclose(new, strength, rtol=1e-12, atol=0):
            strength = new
            break
        strength = new
    return 1500.0 + 400.0 * np.log10(strength)


def run_tournament(bots, games=10, seed=1, rounds=3, rules=None, workers=None, progress=True,
                   budget=DEFAULT_BUDGET, max_faults=DEFAULT_MAX_FAULTS, isolation="auto",
                   limits=None, scheduler=None):
    """Play the round robin; return ``(report, stats)``: the table and every match result
    (plain data), and the frames played and match seconds. ``limits`` (a
    ``spacewar.seats.Limits``) sets every budget of the bots; ``budget`` alone the per-action
    one. ``scheduler``: a Dask scheduler's address, or ``"local"`` for a LocalCluster of this
    machine (default: the ``DASK_SCHEDULER_ADDRESS`` variable, else local processes); the
    report is the same either way (``spacewar.cluster_play``)."""
    bots = list(bots)
    if len(bots) < 2:
        raise ValueError(f"a tournament needs at least two bots, got {bots!r}")
    if len(set(bots)) != len(bots):
        raise ValueError(f"each bot may enter once, got {bots!r}")
    if isinstance(games, bool) or not isinstance(games, int) or games < 1:
        raise ValueError(f"games must be an int >= 1, got {games!r}")
    from .bots import check_one_spelling_each, locate

    for spec in bots:
        locate(spec)  # unknown names and missing files fail here; no bot code runs here
    check_one_spelling_each(bots)  # a.py:X and ./a.py:X would be one bot entered twice
    rules = Rules() if rules is None else rules
    workers = (os.cpu_count() or 1) if workers is None else workers
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ValueError(f"workers must be an int >= 1, got {workers!r}")
    limits = Limits(budget=budget) if limits is None else limits
    jobs = make_jobs(schedule(bots, games, seed), rounds, rules, limits, max_faults, isolation,
                     batch_files_of(bots))
    bar = _progress(sum(len(job[0]) for job in jobs), progress)
    try:
        with MatchRunner(bots, rules, workers, scheduler) as runner:
            outcomes = runner.play(jobs, bar.update)
    finally:
        bar.close()
    return _report(bots, games, seed, rounds, rules, outcomes)


def make_jobs(schedule_, rounds, rules, limits, max_faults, isolation, batch_files):
    """The work of a schedule: ``group_jobs``' matches with everything a worker needs to
    play them."""
    return [(matches, together, rounds, rules.to_dict(), limits, max_faults, isolation,
             batch_files)
            for matches, together in group_jobs(schedule_, isolation, batch_files)]


class MatchRunner:
    """Where matches are played, kept open across calls (a league plays round after round):
    in this process (``workers=1``), in a pool of ``workers`` local processes, or on the Dask
    cluster at ``scheduler`` (an address, or ``"local"``; default: ``DASK_SCHEDULER_ADDRESS``,
    else local). ``play(jobs, progress)`` gives every job's outcomes in job order whichever it
    is, so the results are the same."""

    def __init__(self, bots, rules, workers, scheduler=None):
        from engine.cluster import scheduler_address

        self.address = scheduler_address(scheduler)
        self.bots, self.rules, self.workers = list(bots), rules, workers
        self._pool = self._connection = None

    def play(self, jobs, progress=lambda matches: None):
        if self.address is not None:
            return self._play_on_cluster(jobs, progress)
        if self.workers == 1:
            outcomes = []
            for job in jobs:
                outcomes.extend(_play(job))
                progress(len(job[0]))
            return outcomes
        if self._pool is None:
            _warm_up(self.rules)
            ctx = multiprocessing.get_context("spawn")
            self._pool = concurrent.futures.ProcessPoolExecutor(
                max_workers=self.workers, mp_context=ctx, initializer=_worker_start)
        futures = {self._pool.submit(_play, job): len(job[0]) for job in jobs}
        for future in concurrent.futures.as_completed(futures):
            future.result()  # surface worker errors early
            progress(futures[future])
        return [outcome for f in futures for outcome in f.result()]

    def _play_on_cluster(self, jobs, progress):
        from . import cluster_play

        if self._connection is None:
            self._connection = cluster_play.connect(self.address, self.bots)
        return cluster_play.play_jobs(self._connection, jobs, progress)

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


def _report(bots, games, seed, rounds, rules, outcomes):
    matches = [r for r, _ in outcomes]
    frames = sum(r["steps"] for r in matches)
    wall = sum(t["wall_seconds"] for _, t in outcomes)
    table = _table(bots, matches)
    return {
        "bots": bots, "games_per_pairing": games, "seed": int(seed), "rounds": int(rounds),
        "rules": rules.to_dict(), "table": table,
        "matches": [match_record(r) for r in matches],
    }, {"frames": frames, "match_seconds": wall}


def match_record(result):
    """A match's line in a tournament's or a league's results: a match result cut to plain
    data (fault totals, no wall-clock figure)."""
    return {"p1": result["bots"][0], "p2": result["bots"][1], "seed": result["seed"],
            "winner": result["winner"], "score": result["score"], "steps": result["steps"],
            "forfeit": result["forfeit"], "forfeits": result["forfeits"],
            "faults": [result["faults"][0]["total"], result["faults"][1]["total"]]}


def _table(bots, matches):
    rows = {b: {"bot": b, "played": 0, "wins": 0, "draws": 0, "losses": 0, "points_for": 0,
                "points_against": 0, "faults": 0, "forfeits": 0} for b in bots}
    results = []
    for r in matches:
        p1, p2 = r["bots"]
        for seat, me in enumerate((p1, p2)):
            row = rows[me]
            row["played"] += 1
            row["points_for"] += r["score"][seat]
            row["points_against"] += r["score"][1 - seat]
            row["faults"] += r["faults"][seat]["total"]
            row["forfeits"] += int(r["forfeits"][seat])
            if r["winner_seat"] is None:
                row["draws"] += 1
            elif r["winner_seat"] == seat:
                row["wins"] += 1
            else:
                row["losses"] += 1
        outcome = 0.5 if r["winner_seat"] is None else (1.0 if r["winner_seat"] == 0 else 0.0)
        results.append((p1, p2, outcome))
    elo = bradley_terry_elo(bots, results)
    for b in bots:
        rows[b]["elo"] = round(elo[b], 1)
    return sorted(rows.values(), key=lambda row: (-row["elo"], row["bot"]))


class _NoBar:
    def update(self, n):
        pass

    def close(self):
        pass


def _progress(total, enabled, what="tournament"):
    if not enabled:
        return _NoBar()
    try:
        from tqdm import tqdm
    except ImportError:
        return _NoBar()
    return tqdm(total=total, unit="match", desc=what, leave=False)


def format_table(report):
    """The table as fixed-width text; a bot's name (a submission's file name) shown escaped
    (``seats.printable``): it cannot redraw the organizer's terminal."""
    lines = [f"{'bot':<24}{'played':>7}{'wins':>6}{'draws':>7}{'losses':>8}{'points':>9}"
             f"{'faults':>8}{'elo':>8}"]
    for row in report["table"]:
        lines.append(f"{printable(row['bot']):<24}{row['played']:>7}{row['wins']:>6}"
                     f"{row['draws']:>7}{row['losses']:>8}"
                     f"{row['points_for']:>5}-{row['points_against']:<3}"
                     f"{row['faults']:>8}{row['elo']:>8.0f}")
    return "\n".join(lines)
