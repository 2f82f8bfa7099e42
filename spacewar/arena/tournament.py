"""Round-robin tournaments: every pair of bots, both seat orders, games in worker processes.

Each pair plays ``games`` seeds in both seat orders (the same seeds each way, so neither bot
gets the luckier seat). Match seeds derive from the tournament seed and the match's place in
the schedule, and results are gathered in schedule order, so the same seed gives the same
table whatever the number of workers.

No bot's code runs in the tournament's processes: specifications are checked without
importing them, and each non-built-in bot is loaded only in its own confined process. A bot
that cannot start forfeits its matches; the table is printed all the same.

Ratings: the Bradley-Terry fit of ``spacewar.arena.ratings`` (Elo scale, every result at once,
so the order of games does not matter), with the league's 95% interval
(``ratings.bradley_terry_intervals``): the fit repeated on ``bootstrap`` resamples of the
matches (default 200, as a league's), drawn with replacement by a generator seeded with the
tournament's seed (``bootstrap_rng``), so the same seed gives the same intervals. The table's
``elo`` stays the full-matrix fit (``bradley_terry_elo``) and its order is by it; the
interval's ends are ``elo_low`` and ``elo_high``.

``replays``: a directory where each match's replay is kept (``spacewar.arena.kept_replays``:
brought back from the worker processes or the cluster, saved under a name of its place in the
schedule and its seed); the report is the same with or without.
"""
import itertools
import os

import numpy as np

from spacewar.faults import printable
from spacewar.arena import kept_replays
# the jobs' names, public here too (a tournament's work is cut by them)
from spacewar.arena.jobs import (batch_files_of, group_jobs, make_jobs, match_record, warm_up_game)  # noqa: F401
from spacewar.arena.match import DEFAULT_BUDGET, DEFAULT_MAX_FAULTS
from spacewar.rules import Rules
from spacewar.arena.ratings import bradley_terry_elo, bradley_terry_intervals
from spacewar.arena.runner import MatchRunner, progress_bar
from spacewar.sandbox.limits import Limits


def schedule(bots, games, seed):
    """The list of (p1, p2, match_seed) in a fixed order."""
    out = []
    for pair, (a, b) in enumerate(itertools.combinations(range(len(bots)), 2)):
        for g in range(games):
            match_seed = int(np.random.SeedSequence([int(seed), pair, g]).generate_state(1)[0])
            out.append((bots[a], bots[b], match_seed))
            out.append((bots[b], bots[a], match_seed))
    return out


#: bootstrap resamples for a tournament's rating intervals (as a league's ``--bootstrap``)
DEFAULT_BOOTSTRAP = 200

#: keeps a tournament's bootstrap draws apart from its match seeds
BOOTSTRAP_TAG = 0xB007


def bootstrap_rng(seed):
    """The generator of a tournament's bootstrap resamples: from its seed alone."""
    return np.random.default_rng(np.random.SeedSequence([int(seed), BOOTSTRAP_TAG]))


def run_tournament(bots, games=10, seed=1, rounds=3, rules=None, workers=None, progress=True,
                   budget=DEFAULT_BUDGET, max_faults=DEFAULT_MAX_FAULTS, isolation="auto",
                   limits=None, scheduler=None, bootstrap=DEFAULT_BOOTSTRAP, replays=None):
    """Play the round robin; return ``(report, stats)``: the table and every match result
    (plain data), and the frames played and match seconds. ``limits`` (a
    ``spacewar.sandbox.limits.Limits``) sets every budget of the bots; ``budget`` alone the per-action
    one. ``scheduler``: a Dask scheduler's address, or ``"local"`` for a LocalCluster of this
    machine (default: the ``DASK_SCHEDULER_ADDRESS`` variable, else local processes); the
    report is the same either way (``spacewar.arena.cluster``). ``bootstrap``: resamples for
    the ratings' 95% intervals (0: none, the interval is the rating). ``replays``: a
    directory to keep every match's replay in (``spacewar.arena.kept_replays``; checked and
    made before any match is played); the report is the same with or without."""
    bots = list(bots)
    if len(bots) < 2:
        raise ValueError(f"a tournament needs at least two bots, got {bots!r}")
    if len(set(bots)) != len(bots):
        raise ValueError(f"each bot may enter once, got {bots!r}")
    if isinstance(games, bool) or not isinstance(games, int) or games < 1:
        raise ValueError(f"games must be an int >= 1, got {games!r}")
    from spacewar.bots import check_one_spelling_each, locate

    for spec in bots:
        locate(spec)  # unknown names and missing files fail here; no bot code runs here
    check_one_spelling_each(bots)  # a.py:X and ./a.py:X would be one bot entered twice
    rules = Rules() if rules is None else rules
    workers = (os.cpu_count() or 1) if workers is None else workers
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ValueError(f"workers must be an int >= 1, got {workers!r}")
    limits = Limits(budget=budget) if limits is None else limits
    if isinstance(bootstrap, bool) or not isinstance(bootstrap, int) or bootstrap < 0:
        raise ValueError(f"bootstrap must be an int >= 0, got {bootstrap!r}")
    planned = schedule(bots, games, seed)
    names = kept_replays.tournament_names(planned)
    if replays is not None:
        replays = kept_replays.prepare(replays)
        kept_replays.check_paths(replays, names)
    jobs = make_jobs(planned, rounds, rules, limits, max_faults, isolation, batch_files_of(bots))
    bar = progress_bar(sum(len(job[0]) for job in jobs), progress)
    try:
        with MatchRunner(bots, rules, workers, scheduler) as runner:
            outcomes = (runner.play(jobs, bar.update) if replays is None else
                        runner.play(jobs, bar.update, record=True))
    finally:
        bar.close()
    if replays is not None:
        kept_replays.save_all(replays, names, [replay for _, _, replay in outcomes])
    return _report(bots, games, seed, rounds, rules, outcomes, bootstrap)


def _report(bots, games, seed, rounds, rules, outcomes, bootstrap=DEFAULT_BOOTSTRAP):
    matches = [outcome[0] for outcome in outcomes]
    frames = sum(r["steps"] for r in matches)
    wall = sum(outcome[1]["wall_seconds"] for outcome in outcomes)
    records = [match_record(r) for r in matches]
    table = _table(bots, matches, records, bootstrap, seed)
    return {
        "bots": bots, "games_per_pairing": games, "seed": int(seed), "rounds": int(rounds),
        "rules": rules.to_dict(), "bootstrap": int(bootstrap), "table": table,
        "matches": records,
    }, {"frames": frames, "match_seconds": wall}


def _table(bots, matches, records, bootstrap, seed):
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
    intervals = bradley_terry_intervals(bots, records, bootstrap, bootstrap_rng(seed))
    for b in bots:
        _, low, high = intervals[b]
        rows[b].update(elo=round(elo[b], 1), elo_low=round(low, 1), elo_high=round(high, 1))
    return sorted(rows.values(), key=lambda row: (-row["elo"], row["bot"]))


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
