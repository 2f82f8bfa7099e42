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
"""
import dataclasses
import json
import os

import numpy as np

from .match import DEFAULT_BUDGET, DEFAULT_MAX_FAULTS
from .rules import Rules
from .seats import Limits
from .tournament import MatchRunner, _progress, batch_files_of, make_jobs, match_record

FORMAT = "spacewar-league"
VERSION = 1
PAIRINGS = ("swiss", "sampled")
_SEED_TAG = 0x1EA6  # keeps a league's seeds apart from a tournament's of the same seed


class LeagueFileError(ValueError):
    """A results file that cannot be resumed (the message says why and which field)."""


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


# -- pairings ----------------------------------------------------------------------------------
def _rng(seed, *words):
    return np.random.default_rng(np.random.SeedSequence([int(seed), _SEED_TAG, *words]))


def pair_round(config, round_index, standings, met, byes):
    """``(pairs, bye)`` of round ``round_index`` (from 0): ``standings`` the bots best first,
    ``met[(a, b)]`` (a < b) how often two bots have met, ``byes[bot]`` its byes so far."""
    bots = config["bots"]
    if config["pairing"] == "sampled" or (config["pairing"] == "swiss" and round_index == 0):
        order = [bots[i] for i in _rng(config["seed"], 0, round_index).permutation(len(bots))]
    else:
        order = list(standings)
    bye = None
    if len(order) % 2:
        fewest = min(byes.get(b, 0) for b in order)
        bye = next(b for b in reversed(order) if byes.get(b, 0) == fewest)
        order.remove(bye)
    if config["pairing"] == "sampled":
        return [(order[i], order[i + 1]) for i in range(0, len(order), 2)], bye
    pairs, left = [], list(order)
    while left:
        first = left.pop(0)
        times = [met.get(tuple(sorted((first, other))), 0) for other in left]
        second = left.pop(times.index(min(times)))
        pairs.append((first, second))
    return pairs, bye


def round_schedule(config, round_index, pairs):
    """The matches (p1, p2, seed) of a round: each pairing ``games`` seeds, both seat orders
    with the same seed."""
    out = []
    for pair, (a, b) in enumerate(pairs):
        for g in range(config["games"]):
            seed = int(np.random.SeedSequence(
                [config["seed"], _SEED_TAG, 1, round_index, pair, g]).generate_state(1)[0])
            out += [(a, b, seed), (b, a, seed)]
    return out


# -- ratings -----------------------------------------------------------------------------------
def _outcome(match):
    """1, 0.5 or 0: the result for the match's p1."""
    if match["winner"] is None:
        return 0.5
    return 1.0 if match["winner"] == match["p1"] else 0.0


def openskill_ratings(bots, matches):
    """``{bot: (mu, sigma)}`` after openskill's Plackett-Luce updates, match by match."""
    from openskill.models import PlackettLuce

    model = PlackettLuce()
    ratings = {b: model.rating(name=b) for b in bots}
    for m in matches:
        outcome = _outcome(m)
        ranks = [0, 0] if outcome == 0.5 else ([0, 1] if outcome == 1.0 else [1, 0])
        [[r1], [r2]] = model.rate([[ratings[m["p1"]]], [ratings[m["p2"]]]], ranks=ranks)
        ratings[m["p1"]], ratings[m["p2"]] = r1, r2
    return {b: (float(r.mu), float(r.sigma)) for b, r in ratings.items()}


def bradley_terry_sparse(k, a, b, a_won, b_won, iterations=2000):
    """Elo-scale Bradley-Terry ratings of ``k`` bots from the pairs that met: ``a[e] < b[e]``
    with ``a_won[e]``, ``b_won[e]`` their wins over each other (a draw half each way). The
    tournament's MM iteration with its 1500 anchor (``tournament.bradley_terry_fit``), summed
    over the pairs that played instead of a k x k matrix: a league's few opponents a bot."""
    games = a_won + b_won
    won = np.bincount(a, a_won, k) + np.bincount(b, b_won, k) + 0.5
    strength = np.ones(k)
    for _ in range(iterations):
        share = games / (strength[a] + strength[b])
        new = won / (np.bincount(a, share, k) + np.bincount(b, share, k) + 1.0 / (strength + 1.0))
        if np.allclose(new, strength, rtol=1e-12, atol=0):
            strength = new
            break
        strength = new
    return 1500.0 + 400.0 * np.log10(strength)


def bradley_terry_intervals(bots, matches, samples, seed, level=0.95):
    """``{bot: (elo, low, high)}``: the Bradley-Terry fit of all matches, and the
    ``level`` percentile interval of the fits of ``samples`` bootstrap resamples."""
    index = {b: i for i, b in enumerate(bots)}
    k, n = len(bots), len(matches)
    i = np.array([index[m["p1"]] for m in matches], dtype=np.int64)
    j = np.array([index[m["p2"]] for m in matches], dtype=np.int64)
    p1_won = np.array([_outcome(m) for m in matches])
    low_first = i < j
    pair_key = np.where(low_first, i * k + j, j * k + i)
    keys, pair = np.unique(pair_key, return_inverse=True)
    a, b = keys // k, keys % k
    a_share = np.where(low_first, p1_won, 1.0 - p1_won)  # each match's result for the pair's a

    def fit(weight):
        a_won = np.bincount(pair, weight * a_share, len(keys))
        b_won = np.bincount(pair, weight * (1.0 - a_share), len(keys))
        return bradley_terry_sparse(k, a, b, a_won, b_won)

    elo = fit(np.ones(n))
    if samples and n:
        rng = _rng(seed, 2)
        draws = np.array([fit(np.bincount(rng.integers(0, n, n), minlength=n).astype(float))
                          for _ in range(samples)])
        tail = 100.0 * (1.0 - level) / 2.0
        low, high = np.percentile(draws, [tail, 100.0 - tail], axis=0)
    else:
        low = high = elo
    return {bot: (float(elo[index[bot]]), float(low[index[bot]]), float(high[index[bot]]))
            for bot in bots}


def standings(bots, matches, byes, bootstrap, seed):
    """The league table: per bot its record, openskill mu, sigma and ordinal (mu - 3 sigma,
    the rank used), the Bradley-Terry Elo and its bootstrap interval; best first."""
    rows = {b: {"bot": b, "played": 0, "wins": 0, "draws": 0, "losses": 0, "points_for": 0,
                "points_against": 0, "faults": 0, "forfeits": 0, "byes": byes.get(b, 0)}
            for b in bots}
    for m in matches:
        outcome = _outcome(m)
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
    bt = bradley_terry_intervals(bots, matches, bootstrap, seed)
    for b in bots:
        mu, sigma = skill[b]
        elo, low, high = bt[b]
        rows[b].update(mu=round(mu, 6), sigma=round(sigma, 6), ordinal=round(mu - 3 * sigma, 6),
                       elo=round(elo, 1), elo_low=round(low, 1), elo_high=round(high, 1))
    return sorted(rows.values(), key=lambda row: (-row["ordinal"], row["bot"]))


# -- the results file --------------------------------------------------------------------------
def load_results(path, config):
    """The completed rounds stored at ``path`` for a league of ``config`` (``[]`` if there is
    no file, or it is empty). Raises LeagueFileError for a file of anything else, or of a
    league with another configuration (naming the first field that differs)."""
    if not os.path.exists(path) or os.path.getsize(path) == 0:
        return []
    try:
        with open(path, encoding="utf-8") as f:
            data = json.load(f)
    except (OSError, ValueError, RecursionError) as exc:
        raise LeagueFileError(f"cannot resume the league from {path!r}: not readable JSON "
                              f"({exc})") from None
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise LeagueFileError(f"cannot resume the league from {path!r}: it is not a league "
                              f"results file (format {FORMAT!r})")
    if data.get("version") != VERSION:
        raise LeagueFileError(f"cannot resume the league from {path!r}: version "
                              f"{data.get('version')!r}, this program writes {VERSION}")
    stored = data.get("config")
    if not isinstance(stored, dict):
        raise LeagueFileError(f"cannot resume the league from {path!r}: no config")
    for key, value in config.items():
        if stored.get(key) != value:
            raise LeagueFileError(
                f"cannot resume the league from {path!r}: its {key} is {stored.get(key)!r}, "
                f"this run's is {value!r}; use the same settings, or another results file")
    rounds = data.get("rounds")
    if not isinstance(rounds, list):
        raise LeagueFileError(f"cannot resume the league from {path!r}: no list of rounds")
    return rounds


def _results(config, rounds, table):
    return {"format": FORMAT, "version": VERSION, "config": config,
            "rounds_played": len(rounds), "table": table, "rounds": rounds}


def _save(path, results):
    from engine.atomic import atomic_write

    atomic_write(path, json.dumps(results, sort_keys=True, indent=1) + "\n")


def _state_after(config, rounds):
    """``(standings, met, byes)`` after ``rounds``: the pairing's inputs for the next round."""
    met, byes = {}, {}
    for r in rounds:
        for a, b in r["pairs"]:
            key = tuple(sorted((a, b)))
            met[key] = met.get(key, 0) + 1
        if r["bye"] is not None:
            byes[r["bye"]] = byes.get(r["bye"], 0) + 1
    matches = [m for r in rounds for m in r["matches"]]
    skill = openskill_ratings(config["bots"], matches)
    order = sorted(config["bots"], key=lambda b: (-(skill[b][0] - 3 * skill[b][1]), b))
    return order, met, byes


def _check_stored(path, config, rounds):
    """Each stored round's pairings are the ones this seed gives (a file edited by hand, or
    written by other code, would otherwise be silently continued)."""
    for index, r in enumerate(rounds):
        if not isinstance(r, dict) or not isinstance(r.get("matches"), list):
            raise LeagueFileError(f"cannot resume the league from {path!r}: round {index + 1} "
                                  "is not a round record")
        pairs, bye = pair_round(config, index, *_state_after(config, rounds[:index]))
        if [list(p) for p in pairs] != r.get("pairs") or bye != r.get("bye") \
                or len(r["matches"]) != 2 * config["games"] * len(pairs):
            raise LeagueFileError(f"cannot resume the league from {path!r}: round {index + 1} "
                                  "is not the round this league's settings give")


def run_league(bots, rounds, out, games=2, pairing="swiss", seed=1, match_rounds=3, rules=None,
               workers=None, progress=True, budget=DEFAULT_BUDGET, max_faults=DEFAULT_MAX_FAULTS,
               isolation="auto", limits=None, scheduler=None, bootstrap=200, on_round=None):
    """Play a league to ``rounds`` rounds, saving to the JSON file ``out`` after each; resume
    from ``out`` when it holds completed rounds of the same league. Returns the results (the
    file's content). ``on_round(results)`` is called after each round is saved. Matches run as
    a tournament's do (local processes, or a Dask cluster with ``scheduler``)."""
    from engine.atomic import check_output_path

    from .bots import locate

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
    rules = Rules() if rules is None else rules
    limits = Limits(budget=budget) if limits is None else limits
    config = league_config(bots, games, pairing, seed, match_rounds, rules, limits, max_faults,
                           isolation)
    out = check_output_path(out, "json")
    done = load_results(out, config)
    if len(done) > rounds:
        raise LeagueFileError(f"{out!r} already holds {len(done)} rounds of this league, more "
                              f"than rounds={rounds}: ask for at least {len(done)}")
    _check_stored(out, config, done)
    batch_files = batch_files_of(bots)
    per_round = 2 * games * (len(bots) // 2)
    bar = _progress(per_round * (rounds - len(done)), progress, "league")
    try:
        with MatchRunner(bots, rules, workers, scheduler) as runner:
            while len(done) < rounds:
                index = len(done)
                pairs, bye = pair_round(config, index, *_state_after(config, done))
                jobs = make_jobs(round_schedule(config, index, pairs), match_rounds, rules,
                                 limits, max_faults, isolation, batch_files)
                outcomes = runner.play(jobs, bar.update)
                done = done + [{"round": index + 1, "pairs": [list(p) for p in pairs],
                                "bye": bye, "matches": [match_record(r) for r, _ in outcomes]}]
                results = _results(config, done, _table(config, done, 0))
                _save(out, results)
                if on_round is not None:
                    on_round(results)
    finally:
        bar.close()
    results = _results(config, done, _table(config, done, bootstrap))
    _save(out, results)
    return results


def _table(config, rounds, bootstrap):
    byes = {}
    for r in rounds:
        if r["bye"] is not None:
            byes[r["bye"]] = byes.get(r["bye"], 0) + 1
    return standings(config["bots"], [m for r in rounds for m in r["matches"]], byes, bootstrap,
                     config["seed"])


def format_table(results):
    """The league table as fixed-width text."""
    lines = [f"{'bot':<28}{'played':>7}{'W-D-L':>12}{'faults':>8}{'mu':>8}{'sigma':>7}"
             f"{'ordinal':>9}{'elo':>7}  {'95% interval':<13}"]
    for row in results["table"]:
        record = f"{row['wins']}-{row['draws']}-{row['losses']}"
        lines.append(f"{row['bot'][-28:]:<28}{row['played']:>7}{record:>12}{row['faults']:>8}"
                     f"{row['mu']:>8.2f}{row['sigma']:>7.2f}{row['ordinal']:>9.2f}"
                     f"{row['elo']:>7.0f}  {row['elo_low']:.0f}-{row['elo_high']:.0f}")
    return "\n".join(lines)
