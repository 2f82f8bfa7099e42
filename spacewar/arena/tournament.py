"""Round-robin tournaments: every pair of bots, both seat orders, games in worker processes.

Each pair plays ``games`` seeds in both seat orders (the same seeds each way, so neither bot
gets the luckier seat). Match seeds derive from the tournament seed and the match's place in
the schedule, and results are gathered in schedule order, so the same seed gives the same
table whatever the number of workers.

No bot's code runs in the tournament's processes: specifications are checked without
importing them, and each non-built-in bot is loaded only in its own confined process. A bot
that cannot start forfeits its matches; the table is printed all the same.

Ratings: the Bradley-Terry fit of ``spacewar.arena.ratings`` (Elo scale, every result at once,
so the order of games does not matter).
"""
import itertools
import os

import numpy as np

from spacewar.faults import printable
# the jobs' names, public here too (a tournament's work is cut by them)
from spacewar.arena.jobs import (batch_files_of, group_jobs, make_jobs, match_record, warm_up_game)  # noqa: F401
from spacewar.arena.match import DEFAULT_BUDGET, DEFAULT_MAX_FAULTS
from spacewar.rules import Rules
from spacewar.arena.ratings import bradley_terry_elo
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


def run_tournament(bots, games=10, seed=1, rounds=3, rules=None, workers=None, progress=True,
                   budget=DEFAULT_BUDGET, max_faults=DEFAULT_MAX_FAULTS, isolation="auto",
                   limits=None, scheduler=None):
    """Play the round robin; return ``(report, stats)``: the table and every match result
    (plain data), and the frames played and match seconds. ``limits`` (a
    ``spacewar.sandbox.limits.Limits``) sets every budget of the bots; ``budget`` alone the per-action
    one. ``scheduler``: a Dask scheduler's address, or ``"local"`` for a LocalCluster of this
    machine (default: the ``DASK_SCHEDULER_ADDRESS`` variable, else local processes); the
    report is the same either way (``spacewar.arena.cluster``)."""
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
    jobs = make_jobs(schedule(bots, games, seed), rounds, rules, limits, max_faults, isolation,
                     batch_files_of(bots))
    bar = progress_bar(sum(len(job[0]) for job in jobs), progress)
    try:
        with MatchRunner(bots, rules, workers, scheduler) as runner:
            outcomes = runner.play(jobs, bar.update)
    finally:
        bar.close()
    return _report(bots, games, seed, rounds, rules, outcomes)


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
