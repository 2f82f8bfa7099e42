"""Leagues: many bots, a few rounds of pairings each instead of the full round robin.

A round robin of k bots is k(k-1)/2 pairings: 44850 for 300 bots. A league plays ``rounds``
rounds instead, each bot meeting one opponent a round (k/2 pairings), every pairing playing
``games`` seeds in both seat orders as in a tournament. Pairings:

- ``"swiss"``: bots ranked by their rating so far (openskill's ordinal, mu - 3 sigma; the
  first round in a seeded random order), each in turn paired with the highest-ranked
  unpaired bot it has met least often, so that after a few rounds bots meet bots of their
  own strength and the ranking sharpens where it is uncertain (the Swiss system of chess
  tournaments, with ratings in place of scores);
- ``"sampled"``: a seeded random perfect matching each round.

With an odd number of bots, one sits out each round (a bye): the lowest-ranked of those with
the fewest byes so far.

Ratings with their uncertainty, two ways:

- openskill's Plackett-Luce model (Weng & Lin 2011, "A Bayesian Approximation Method for
  Online Ranking"), ``mu`` and ``sigma`` per bot, updated match after match in the order the
  matches were scheduled (so the same results give the same ratings);
- the tournament's Bradley-Terry fit (Elo scale; ``bradley_terry_sparse``) with a 95%
  interval from a bootstrap over matches (Efron 1979: the fit repeated on ``bootstrap``
  resamples of the matches, drawn with replacement from a seeded generator; the 2.5th and
  97.5th percentiles).

The results file is JSON, written atomically after every round. Run the league again with the
same file and it resumes after the last completed round (with more ``rounds`` it goes on):
the configuration must match the file's, each stored round's pairings are checked against
the ones the seed gives, and the ratings are recomputed from all stored matches, so a league
interrupted and resumed ends with the same file as one run straight through. An interruption
loses at most the matches of the round that was being played.

``replays``: a directory where each match's replay is kept (``spacewar.arena.kept_replays``:
brought back from the worker processes or the cluster, saved after its round under a name of
the round, the match's place in it and its seed, before the results file); the results are the
same with or without, and a resume keeps the replays of the rounds it plays.

The file is signed with this user's key (``spacewar.replay.sign``: an HMAC-SHA256 with the
replay-signing key), and checked record by record before a resume uses any of it (every
field's type and range, the players and seeds the schedule gives, a winner consistent with
the score and the forfeits). A file that is unsigned (written before files were signed),
signed with another key (another organizer's) or forged (its signature does not match) is
refused unless ``trust_results`` is given; the results then say so (``resumed_from``).
"""
import dataclasses
import os


from spacewar.arena.match import DEFAULT_BUDGET, DEFAULT_MAX_FAULTS
from spacewar.arena.league_file import (LeagueFileError, TRUST_OPTION, load_results,  # noqa: F401
                                       results_document, save_results)
from spacewar.arena.pairings import PAIRINGS, league_rng, pair_round, round_schedule, state_after
from spacewar.rules import Rules
from spacewar.faults import printable
from spacewar.sandbox.limits import Limits
from spacewar.arena.jobs import batch_files_of, make_jobs, match_record
from spacewar.arena.ratings import bradley_terry_intervals, match_outcome, openskill_ratings
from spacewar.arena.runner import MatchRunner, progress_bar
from spacewar.arena import kept_replays


def _positive_int(name, value):
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise ValueError(f"{name} must be an int >= 1, got {value!r}")
    return value


def league_config(bots, games, pairing, seed, match_rounds, rules, limits, max_faults,
                  isolation):
    """What a league's results depend on (besides its number of rounds), as plain data."""
    return {"bots": list(bots), "games": games, "pairing": pairing, "seed": int(seed),
            "match_rounds": match_rounds, "rules": rules.to_dict(),
            "limits": dataclasses.asdict(limits), "max_faults": max_faults,
            "isolation": isolation}


def standings(bots, matches, byes, bootstrap, seed):
    """The league table: per bot its record, openskill mu, sigma and ordinal (mu - 3 sigma,
    the rank used), the Bradley-Terry Elo and its bootstrap interval; best first."""
    rows = {b: {"bot": b, "played": 0, "wins": 0, "draws": 0, "losses": 0, "points_for": 0,
                "points_against": 0, "faults": 0, "forfeits": 0, "byes": byes.get(b, 0)}
            for b in bots}
    for m in matches:
        outcome = match_outcome(m)
        for seat, me in enumerate((m["p1"], m["p2"])):
            row = rows[me]
            row["played"] += 1
            row["points_for"] += m["score"][seat]
            row["points_against"] += m["score"][1 - seat]
            row["faults"] += m["faults"][seat]
            row["forfeits"] += int(m["forfeits"][seat])
            mine = outcome if seat == 0 else 1.0 - outcome
            row["wins" if mine == 1.0 else "losses" if mine == 0.0 else "draws"] += 1
    skill = openskill_ratings(bots, matches)
    bt = bradley_terry_intervals(bots, matches, bootstrap, league_rng(seed, 2))
    for b in bots:
        mu, sigma = skill[b]
        elo, low, high = bt[b]
        rows[b].update(mu=round(mu, 6), sigma=round(sigma, 6), ordinal=round(mu - 3 * sigma, 6),
                       elo=round(elo, 1), elo_low=round(low, 1), elo_high=round(high, 1))
    return sorted(rows.values(), key=lambda row: (-row["ordinal"], row["bot"]))


def run_league(bots, rounds, out, games=2, pairing="swiss", seed=1, match_rounds=3, rules=None,
               workers=None, progress=True, budget=DEFAULT_BUDGET, max_faults=DEFAULT_MAX_FAULTS,
               isolation="auto", limits=None, scheduler=None, bootstrap=200, on_round=None,
               trust_results=False, replays=None):
    """Play a league to ``rounds`` rounds, saving to the JSON file ``out`` after each; resume
    from ``out`` when it holds completed rounds of the same league. Returns the results (the
    file's content). ``on_round(results)`` is called after each round is saved. Matches run as
    a tournament's do (local processes, or a Dask cluster with ``scheduler``).

    The file is signed with this user's key; a file to resume must be verified, unless
    ``trust_results``: then an unsigned one, one signed with another key or a forged one is
    resumed all the same (after its record-by-record checks, which always hold), and the
    results' ``resumed_from`` and the table say so (``load_results``).

    ``replays``: a directory to keep the replay of every match this run plays
    (``spacewar.arena.kept_replays``; the directory is checked and made before any match,
    each round's file names before its matches); the results are the same with or without."""
    from engine.atomic import check_output_path

    from spacewar.bots import check_one_spelling_each, locate

    bots = list(bots)
    if len(bots) < 2:
        raise ValueError(f"a league needs at least two bots, got {bots!r}")
    if len(set(bots)) != len(bots):
        raise ValueError(f"each bot may enter once, got {bots!r}")
    rounds, games = _positive_int("rounds", rounds), _positive_int("games", games)
    match_rounds = _positive_int("match_rounds", match_rounds)
    if pairing not in PAIRINGS:
        raise ValueError(f"pairing must be one of {', '.join(PAIRINGS)}, got {pairing!r}")
    if isinstance(bootstrap, bool) or not isinstance(bootstrap, int) or bootstrap < 0:
        raise ValueError(f"bootstrap must be an int >= 0, got {bootstrap!r}")
    workers = (os.cpu_count() or 1) if workers is None else workers
    _positive_int("workers", workers)
    for spec in bots:
        locate(spec)  # unknown names and missing files fail here; no bot code runs here
    check_one_spelling_each(bots)  # a.py:X and ./a.py:X would be one bot entered twice
    rules = Rules() if rules is None else rules
    limits = Limits(budget=budget) if limits is None else limits
    config = league_config(bots, games, pairing, seed, match_rounds, rules, limits, max_faults,
                           isolation)
    # the path's kind is not sniffed (that parses up to 64 MiB of JSON, whatever the league):
    # an existing file must be this league's, read within its league's bound by load_results
    out = check_output_path(out)
    done, resumed_from = load_results(out, config, trust_results, rounds)
    if replays is not None:
        replays = kept_replays.prepare(replays)
    if len(done) > rounds:
        raise LeagueFileError(f"{out!r} already holds {len(done)} rounds of this league, more "
                              f"than rounds={rounds}: ask for at least {len(done)}")
    batch_files = batch_files_of(bots)
    per_round = 2 * games * (len(bots) // 2)
    bar = progress_bar(per_round * (rounds - len(done)), progress, "league")
    try:
        with MatchRunner(bots, rules, workers, scheduler) as runner:
            while len(done) < rounds:
                index = len(done)
                pairs, bye = pair_round(config, index, *state_after(config, done))
                planned = round_schedule(config, index, pairs)
                names = kept_replays.league_round_names(index + 1, planned)
                if replays is not None:
                    kept_replays.check_paths(replays, names)
                jobs = make_jobs(planned, match_rounds, rules, limits, max_faults, isolation,
                                 batch_files)
                outcomes = (runner.play(jobs, bar.update) if replays is None else
                            runner.play(jobs, bar.update, record=True))
                if replays is not None:
                    kept_replays.save_all(replays, names, [o[2] for o in outcomes])
                done = done + [{"round": index + 1, "pairs": [list(p) for p in pairs],
                                "bye": bye, "matches": [match_record(o[0]) for o in outcomes]}]
                results = results_document(config, done, _table(config, done, 0), resumed_from)
                save_results(out, results)
                if on_round is not None:
                    on_round(results)
    finally:
        bar.close()
    results = results_document(config, done, _table(config, done, bootstrap), resumed_from)
    save_results(out, results)
    return results


def _table(config, rounds, bootstrap):
    byes = {}
    for r in rounds:
        if r["bye"] is not None:
            byes[r["bye"]] = byes.get(r["bye"], 0) + 1
    return standings(config["bots"], [m for r in rounds for m in r["matches"]], byes, bootstrap,
                     config["seed"])


def format_standings(results):
    """The league table as fixed-width text; a bot's name (a submission's file name) shown
    escaped (``seats.printable``), then cut to its last 28 characters."""
    lines = [f"{'bot':<28}{'played':>7}{'W-D-L':>12}{'faults':>8}{'mu':>8}{'sigma':>7}"
             f"{'ordinal':>9}{'elo':>7}  {'95% interval':<13}"]
    for row in results["table"]:
        record = f"{row['wins']}-{row['draws']}-{row['losses']}"
        lines.append(f"{printable(row['bot'])[-28:]:<28}{row['played']:>7}{record:>12}"
                     f"{row['faults']:>8}"
                     f"{row['mu']:>8.2f}{row['sigma']:>7.2f}{row['ordinal']:>9.2f}"
                     f"{row['elo']:>7.0f}  {row['elo_low']:.0f}-{row['elo_high']:.0f}")
    lines += [resumed_note(entry) for entry in results.get("resumed_from", [])]
    return "\n".join(lines)


def resumed_note(entry):
    """The line under the table (and on the league's pages) for a resume from an unverified
    file."""
    kind = {"unsigned": "an unsigned", "other key": "another key's",
            "forged": "a forged (signature not matching)"}[entry["signature"]]
    return (f"NOTE: resumed with {TRUST_OPTION} from {kind} results file: its first "
            f"{entry['rounds']} rounds are not verified")
