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

The file is signed with this user's key (``spacewar.replay.sign``: an HMAC-SHA256 with the
replay-signing key), and checked record by record before a resume uses any of it (every
field's type and range, the players and seeds the schedule gives, a winner consistent with
the score and the forfeits). A file that is unsigned (written before files were signed),
signed with another key (another organizer's) or forged (its signature does not match) is
refused unless ``trust_results`` is given; the results then say so (``resumed_from``).
"""
import dataclasses
import json
import os
import reprlib

import numpy as np

from .match import DEFAULT_BUDGET, DEFAULT_MAX_FAULTS
from .rules import Rules
from .faults import printable
from .seats import Limits
from .strangers_files import FileRefused, read_bounded
from .jobs import batch_files_of, make_jobs, match_record
from .runner import MatchRunner, progress_bar

FORMAT = "spacewar-league"
VERSION = 1
PAIRINGS = ("swiss", "sampled")
_SEED_TAG = 0x1EA6  # keeps a league's seeds apart from a tournament's of the same seed
MAX_FILE_BYTES = 64 * 1024 * 1024  # ten times the 16,000 matches of a 1000-bot league
MIB = 1024 * 1024
TRUST_OPTION = "--trust-results"  # the command's option that resumes an unverified file
#: what a results file's signature can be, other than verified
UNVERIFIED = {"unsigned": "unsigned (written before results files were signed, or its "
                          "signature removed)",
              "other key": "signed with another key (another organizer's, or another "
                           "account's)",
              "forged": "forged: its signature does not match its content under this "
                        "user's key (edited after it was written)"}
_TOP_FIELDS = {"format", "version", "config", "rounds_played", "table", "rounds"}
_OPTIONAL_TOP_FIELDS = {"signature", "resumed_from"}
_ROUND_FIELDS = ("round", "pairs", "bye", "matches")
_MATCH_FIELDS = ("p1", "p2", "seed", "winner", "score", "steps", "forfeit", "forfeits",
                 "faults")
_SHOWN = reprlib.Repr()  # a stored value in an error message: escaped, and short
_SHOWN.maxstring = _SHOWN.maxother = _SHOWN.maxlong = 60


class LeagueFileError(ValueError):
    """A results file that cannot be resumed (the message says why and which field)."""


def _shown(value):
    """``value`` as an error message shows it: its repr (control characters escaped), cut
    short."""
    return _SHOWN.repr(value)


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
def load_results(path, config, trust_results=False, rounds=None):
    """``(rounds, resumed_from)``: the completed rounds stored at ``path`` for a league of
    ``config`` (``[]`` if there is no file, or it is empty) and the file's record of earlier
    resumes from unverified files, with this resume's added when ``trust_results`` let one
    through. The file is read only if it is no larger than ``rounds`` rounds of this league
    can make it (``max_file_bytes``; None: ``MAX_FILE_BYTES``). Every stored round and match
    is checked first (``_check_stored``), then the signature. Raises LeagueFileError, naming
    the file, the round, the match and the field, for a file of anything else, of a league
    with another configuration, of a record the league could not have written, or (unless
    ``trust_results``) one that is not verified."""
    raw = _read_bounded(path, MAX_FILE_BYTES if rounds is None else
                        max_file_bytes(config, rounds), rounds)
    if not raw:
        return [], []
    data = _parse(path, raw)
    _check_header(path, data, config)
    rounds = data["rounds"]
    _check_stored(path, config, rounds)
    resumed_from = _check_resumed_from(path, data.get("resumed_from", []), len(rounds))
    status = _signature(path, data)
    if status == "verified":
        return rounds, resumed_from
    if not trust_results:
        raise LeagueFileError(  # never resumed silently: the table would follow a forgery
            f"cannot resume the league from {path!r}: the file is {UNVERIFIED[status]}; its "
            f"{len(rounds)} rounds were checked one by one but cannot be verified. To resume "
            f"it anyway, give {TRUST_OPTION} (run_league(trust_results=True)): the results "
            "and the table will say so")
    return rounds, resumed_from + [{"signature": status, "rounds": len(rounds)}]


def _fail(path, message):
    raise LeagueFileError(f"cannot resume the league from {path!r}: {message}")


def max_file_bytes(config, rounds):
    """The most bytes a results file of ``rounds`` rounds of the league of ``config`` is read
    with: twice the most the league can write (every name at its JSON length, every number
    at its widest, generously) and a MiB more, at most ``MAX_FILE_BYTES``. Parsed JSON can
    take 25 bytes of memory a byte of file (a file of nothing but empty lists), so the bound
    keeps a hostile file's cost in proportion to the league it claims to be."""
    name = max(len(json.dumps(bot)) for bot in config["bots"])
    match = 1000 + 3 * name + 2 * len(str(config["max_faults"]))
    pair = 400 + 2 * name + 2 * config["games"] * match
    per_round = 200 + name + len(config["bots"]) // 2 * pair
    fixed = 4 * len(json.dumps(config, indent=1)) + len(config["bots"]) * (2000 + name) \
        + 64 * 1024  # the signature and the record of earlier resumes
    return min(MAX_FILE_BYTES, MIB + 2 * (fixed + rounds * per_round))


def _read_bounded(path, limit, rounds):
    """The bytes of the results file at ``path`` (``b""`` when there is none): a regular file
    (never a FIFO or device, which could block or never end), opened without blocking, of at
    most ``limit`` bytes (what ``rounds`` rounds can take), read from the descriptor that was
    checked (``strangers_files.read_bounded``)."""
    too_big = (f"over the {limit} a results file may have" if rounds is None else
               f"over the {limit} that {rounds} rounds of this league can take (if it holds "
               "more rounds, ask for as many)")
    try:
        return read_bounded(path, limit)
    except FileNotFoundError:
        return b""
    except FileRefused as exc:
        _fail(path, {"not regular": "it is not a regular file",
                     "too large": f"it has {exc.size} bytes, {too_big}",
                     "grew": f"it grew while it was read, {too_big}"}[exc.reason])
    except OSError as exc:
        _fail(path, f"cannot read it: {exc.strerror or exc}")


def _finite_float(text):
    value = float(text)
    if not np.isfinite(value):
        raise ValueError(f"number {_shown(text)} is out of range")
    return value


def _no_constant(name):
    raise ValueError(f"non-standard JSON constant {name}")


def _parse(path, raw):
    """The JSON content of a results file: plain data, finite numbers (NaN, Infinity and
    1e999 refused, so the content can be signed and rated)."""
    try:
        return json.loads(raw, parse_float=_finite_float, parse_constant=_no_constant)
    except RecursionError:
        _fail(path, "not readable JSON (nested too deeply)")
    except (ValueError, TypeError) as exc:  # JSONDecodeError, bad UTF-8, an int's digit limit
        _fail(path, f"not readable JSON ({exc})")


def _check_header(path, data, config):
    """The file is a league results file of this version, its fields the known ones, and its
    configuration this run's (the first field that differs is named)."""
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        _fail(path, f"it is not a league results file (format {FORMAT!r})")
    if data.get("version") != VERSION:
        _fail(path, f"version {_shown(data.get('version'))}, this program writes {VERSION}")
    missing = sorted(_TOP_FIELDS - set(data))
    unknown = sorted(set(data) - _TOP_FIELDS - _OPTIONAL_TOP_FIELDS)
    if missing or unknown:
        _fail(path, f"it lacks the field {missing[0]!r}" if missing
              else f"unknown field {_shown(unknown[0])}")
    stored = data["config"]
    if not isinstance(stored, dict):
        _fail(path, f"config must be a dict, got {_shown(stored)}")
    for key, value in config.items():
        if key not in stored or not _same_data(stored[key], value):
            _fail(path, f"its {key} is {_shown(stored.get(key))}, this run's is "
                        f"{_shown(value)}; use the same settings, or another results file")
    if not isinstance(data["rounds"], list):
        _fail(path, f"rounds must be a list of rounds, got {_shown(data['rounds'])}")
    played = data["rounds_played"]
    if not _is_int(played) or played != len(data["rounds"]):
        _fail(path, f"rounds_played is {_shown(played)}, the file holds "
                    f"{len(data['rounds'])} rounds")


def _same_data(a, b):
    """JSON data ``a`` is ``b``, types included (``==`` alone takes true for 1 and 1.0 for 1)."""
    return json.dumps(a, sort_keys=True) == json.dumps(b, sort_keys=True)


def _is_int(value):
    return isinstance(value, int) and not isinstance(value, bool)


def _check_resumed_from(path, entries, rounds):
    """The file's record of earlier resumes from unverified files, checked: a list of
    ``{"signature": one of UNVERIFIED, "rounds": 0..rounds}``."""
    if not isinstance(entries, list):
        _fail(path, f"resumed_from must be a list, got {_shown(entries)}")
    for i, entry in enumerate(entries):
        if not isinstance(entry, dict) or set(entry) != {"signature", "rounds"} \
                or entry["signature"] not in UNVERIFIED or not _is_int(entry["rounds"]) \
                or not 0 <= entry["rounds"] <= rounds:
            _fail(path, f"resumed_from[{i}] must be {{'signature': one of "
                        f"{', '.join(map(repr, UNVERIFIED))}, 'rounds': 0 to {rounds}}}, got "
                        f"{_shown(entry)}")
    return entries


def _signature(path, data):
    """The file's ``spacewar.replay.signature_status``."""
    from .replay import ReplayError, signature_status

    try:
        return signature_status(data)
    except ReplayError as exc:  # this user's key cannot be read
        _fail(path, f"its signature cannot be checked: {exc}")
    except (TypeError, ValueError):  # content the league never writes (a lone surrogate...)
        return "forged"


def _results(config, rounds, table, resumed_from):
    """The results file's content, signed with this user's key (``spacewar.replay.sign``);
    ``resumed_from`` (the resumes from unverified files) only when there was one."""
    from .replay import sign

    results = {"format": FORMAT, "version": VERSION, "config": config,
               "rounds_played": len(rounds), "table": table, "rounds": rounds}
    if resumed_from:
        results["resumed_from"] = resumed_from
    results["signature"] = sign(results)
    return results


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
    """Every stored round is the one this league's settings give after the rounds before it
    (its number, pairings and bye), and every match record is one the league could have
    written: the schedule's players and seed in the schedule's order, fields of the right
    types within the match's range, and a winner and forfeit consistent with the score and
    the forfeits. A file edited by hand, or written by other code, is refused naming the
    round, the match and the field, before any of it is used."""
    bounds = _match_bounds(config)
    for index, r in enumerate(rounds):
        where = f"round {index + 1}"
        if not isinstance(r, dict):
            _fail(path, f"{where} must be a round record (a dict), got {_shown(r)}")
        _check_fields(path, where, r, _ROUND_FIELDS)
        if not _is_int(r["round"]) or r["round"] != index + 1:
            _fail(path, f"{where}: round is {_shown(r['round'])}, its place gives {index + 1}")
        if not isinstance(r["matches"], list):
            _fail(path, f"{where}: matches must be a list, got {_shown(r['matches'])}")
        pairs, bye = pair_round(config, index, *_state_after(config, rounds[:index]))
        if r["pairs"] != [list(p) for p in pairs] or not _same_data(r["bye"], bye) \
                or len(r["matches"]) != 2 * config["games"] * len(pairs):
            _fail(path, f"{where} is not the round this league's settings give: its pairs "
                        f"are {_shown(r['pairs'])}, bye {_shown(r['bye'])} and "
                        f"{len(r['matches'])} matches; the seed gives {_shown(pairs)}, bye "
                        f"{_shown(bye)} and {2 * config['games'] * len(pairs)} matches")
        for number, (match, planned) in enumerate(
                zip(r["matches"], round_schedule(config, index, pairs)), 1):
            _check_match(path, f"{where}, match {number}", match, planned, bounds)


def _check_fields(path, where, record, fields):
    """``record`` (a dict) has exactly ``fields``."""
    missing = [f for f in fields if f not in record]
    if missing:
        _fail(path, f"{where} lacks the field {missing[0]!r}")
    unknown = sorted((f for f in record if f not in fields), key=str)
    if unknown:
        _fail(path, f"{where} has an unknown field {_shown(unknown[0])}")


def _match_bounds(config):
    """The most a match of this league can give: ``(score, steps, faults)`` a seat (the
    match's rounds and its extra rounds, each of at most ``max_round_frames`` and the
    ``post_round_delay``; a seat forfeits when its faults reach ``max_faults``)."""
    rules = Rules.from_dict(config["rules"])
    rounds = config["match_rounds"] + rules.max_extra_rounds
    return (rounds, rounds * (rules.max_round_frames + rules.post_round_delay),
            config["max_faults"])


def _check_match(path, where, match, planned, bounds):
    """One stored match record (``tournament.match_record``'s fields) against the match the
    schedule ``planned`` (p1, p2, seed), within ``bounds`` (``_match_bounds``)."""
    if not isinstance(match, dict):
        _fail(path, f"{where} must be a match record (a dict), got {_shown(match)}")
    _check_fields(path, where, match, _MATCH_FIELDS)
    for field, value in zip(("p1", "p2", "seed"), planned):
        if not _same_data(match[field], value):
            _fail(path, f"{where}: {field} is {_shown(match[field])}, the schedule gives "
                        f"{_shown(value)}")
    most_points, most_steps, most_faults = bounds
    _check_count(path, where, "steps", match["steps"], most_steps)
    for seat in range(2):
        for field, high in (("score", most_points), ("faults", most_faults)):
            if not isinstance(match[field], list) or len(match[field]) != 2:
                _fail(path, f"{where}: {field} must be a list of two ints (one per seat), got "
                            f"{_shown(match[field])}")
            _check_count(path, where, f"{field}[{seat}]", match[field][seat], high)
    forfeits = match["forfeits"]
    if not isinstance(forfeits, list) or len(forfeits) != 2 \
            or not all(isinstance(f, bool) for f in forfeits):
        _fail(path, f"{where}: forfeits must be a list of two bools (one per seat), got "
                    f"{_shown(forfeits)}")
    _check_outcome(path, where, match)


def _check_count(path, where, field, value, high):
    if not _is_int(value) or not 0 <= value <= high:
        _fail(path, f"{where}: {field} must be an int from 0 to {high}, got {_shown(value)}")


def _check_outcome(path, where, match):
    """``forfeit`` and ``winner`` are what ``match.match_result`` gives for the record's score and
    forfeits: one forfeit names its seat's bot and the other bot wins; two forfeits, or
    none and an equal score, are a draw; otherwise the higher score wins, or nobody when the
    simulation stopped on a numerical error (which the record does not keep)."""
    names, score, forfeits = (match["p1"], match["p2"]), match["score"], match["forfeits"]
    forfeit, winners = None, [None]
    if forfeits.count(True) == 1:
        forfeit = names[forfeits.index(True)]
        winners = [names[forfeits.index(False)]]
    elif not any(forfeits) and score[0] != score[1]:
        winners = [names[0] if score[0] > score[1] else names[1], None]
    if not _same_data(match["forfeit"], forfeit):
        _fail(path, f"{where}: forfeit is {_shown(match['forfeit'])}, its forfeits "
                    f"{forfeits} give {_shown(forfeit)}")
    if not any(_same_data(match["winner"], w) for w in winners):
        played = match["winner"] is None or match["winner"] in names
        _fail(path, f"{where}: winner is {_shown(match['winner'])}"
                    f"{'' if played else ', who did not play this match'}; its score {score} "
                    f"and forfeits {forfeits} give {' or '.join(map(_shown, winners))}")


def run_league(bots, rounds, out, games=2, pairing="swiss", seed=1, match_rounds=3, rules=None,
               workers=None, progress=True, budget=DEFAULT_BUDGET, max_faults=DEFAULT_MAX_FAULTS,
               isolation="auto", limits=None, scheduler=None, bootstrap=200, on_round=None,
               trust_results=False):
    """Play a league to ``rounds`` rounds, saving to the JSON file ``out`` after each; resume
    from ``out`` when it holds completed rounds of the same league. Returns the results (the
    file's content). ``on_round(results)`` is called after each round is saved. Matches run as
    a tournament's do (local processes, or a Dask cluster with ``scheduler``).

    The file is signed with this user's key; a file to resume must be verified, unless
    ``trust_results``: then an unsigned one, one signed with another key or a forged one is
    resumed all the same (after its record-by-record checks, which always hold), and the
    results' ``resumed_from`` and the table say so (``load_results``)."""
    from engine.atomic import check_output_path

    from .bots import check_one_spelling_each, locate

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
                pairs, bye = pair_round(config, index, *_state_after(config, done))
                jobs = make_jobs(round_schedule(config, index, pairs), match_rounds, rules,
                                 limits, max_faults, isolation, batch_files)
                outcomes = runner.play(jobs, bar.update)
                done = done + [{"round": index + 1, "pairs": [list(p) for p in pairs],
                                "bye": bye, "matches": [match_record(r) for r, _ in outcomes]}]
                results = _results(config, done, _table(config, done, 0), resumed_from)
                _save(out, results)
                if on_round is not None:
                    on_round(results)
    finally:
        bar.close()
    results = _results(config, done, _table(config, done, bootstrap), resumed_from)
    _save(out, results)
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
    lines += [_resumed_note(entry) for entry in results.get("resumed_from", [])]
    return "\n".join(lines)


def _resumed_note(entry):
    """The line under the table for a resume from an unverified file."""
    kind = {"unsigned": "an unsigned", "other key": "another key's",
            "forged": "a forged (signature not matching)"}[entry["signature"]]
    return (f"NOTE: resumed with {TRUST_OPTION} from {kind} results file: its first "
            f"{entry['rounds']} rounds are not verified")
