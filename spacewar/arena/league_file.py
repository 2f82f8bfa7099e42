"""A league's results file: JSON written atomically after every round and signed with this
user's key (``spacewar.replay.sign``); read within a bound set by the league's size, and checked
record by record (every field's type and range, the players and seeds the schedule gives, a
winner consistent with the score and the forfeits) before a resume uses any of it. The rules
are in ``spacewar.arena.league``'s text."""
import json
import reprlib

import numpy as np

from spacewar.rules import Rules
from spacewar.arena.pairings import pair_round, round_schedule, state_after
from spacewar.strangers_files import FileRefused, read_bounded


FORMAT = "spacewar-league"


VERSION = 1


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
    from spacewar.replay import ReplayError, signature_status

    try:
        return signature_status(data)
    except ReplayError as exc:  # this user's key cannot be read
        _fail(path, f"its signature cannot be checked: {exc}")
    except (TypeError, ValueError):  # content the league never writes (a lone surrogate...)
        return "forged"


def results_document(config, rounds, table, resumed_from):
    """The results file's content, signed with this user's key (``spacewar.replay.sign``);
    ``resumed_from`` (the resumes from unverified files) only when there was one."""
    from spacewar.replay import sign

    results = {"format": FORMAT, "version": VERSION, "config": config,
               "rounds_played": len(rounds), "table": table, "rounds": rounds}
    if resumed_from:
        results["resumed_from"] = resumed_from
    results["signature"] = sign(results)
    return results


def save_results(path, results):
    from engine.atomic import atomic_write

    atomic_write(path, json.dumps(results, sort_keys=True, indent=1) + "\n")


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
        pairs, bye = pair_round(config, index, *state_after(config, rounds[:index]))
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
